#include "io/bode_figure.h"

namespace rths::io {

namespace {

/// `style` with x = the curve's frequencies and y = `column`.
Series Drawn(Series style, const signal::BodeCurve& c, const std::vector<double>& column) {
  style.x = c.f_hz;
  style.y = column;
  return style;
}

}  // namespace

Figure BodeFigure(const BodeLayout& l, const std::vector<BodeTrace>& traces) {
  Panel mag = MakePanel(l.magnitude_title, l.x_label, l.magnitude_label);
  Panel ph = MakePanel(l.phase_title, l.x_label, l.phase_label);
  Panel lag = MakePanel(l.lag_title, l.x_label, l.lag_label);
  Panel coh = MakePanel(l.coherence_title, l.x_label, l.coherence_label);
  for (const auto& t : traces) {
    mag.series.push_back(Drawn(t.style, t.curve, t.curve.magnitude));
    Series p = t.style;
    if (!t.phase_title.empty()) p.title = t.phase_title;
    ph.series.push_back(Drawn(p, t.curve, t.curve.phase_deg));
    lag.series.push_back(Drawn(t.style, t.curve, t.curve.lag_ms));
    if (t.coherence_style) coh.series.push_back(Drawn(*t.coherence_style, t.curve, t.curve.coherence));
  }
  for (const auto& s : l.coherence_extra) coh.series.push_back(s);
  lag.y_range = l.lag_range_ms;
  coh.y_range = std::make_pair(0.0, 1.05);
  mag.key = l.magnitude_key;
  ph.key = lag.key = "off";
  coh.key = l.coherence_key;
  std::vector<Panel*> panels{&mag, &ph};
  if (l.lag_panel) panels.push_back(&lag);
  if (l.coherence_panel) panels.push_back(&coh);
  const int right = l.key_margin ? KeyMarginChars({&mag}) : -1;
  for (Panel* p : panels) {
    p->x_range = l.f_range_hz;
    p->shade_x = l.shade_hz;
    p->left_margin_chars = l.left_margin_chars;
    p->right_margin_chars = right;
  }
  Figure fig;
  for (Panel* p : panels) fig.panels.push_back(std::move(*p));
  return fig;
}

}  // namespace rths::io
