#include "ident/damper_figure.h"

#include <filesystem>

#include <fmt/format.h>

namespace rths::ident {

std::string DamperFigureTitle(const FitStatus& status, const std::string& what) {
  const std::string mark = status.Mark();
  if (mark.empty()) return fmt::format("MR damper {}: measured (blue) and fitted model (vermillion)", what);
  return fmt::format("{} | MR damper {}: measured (blue), model (vermillion)", mark, what);
}

io::Figure DamperFitFigure(const DamperModelFit& fit, const std::vector<io::RigRecord>& training,
                           const std::vector<io::RigRecord>& held, const std::string& what) {
  const std::string measured_color = io::ReadableColors()[0], model_color = io::ReadableColors()[1];
  io::Figure fig;
  fig.name = "damper_fit";
  fig.title = DamperFigureTitle(fit.status(), what);
  fig.columns = 2;
  fig.width_px = 1000;
  fig.panel_height_px = 260;
  auto add = [&](const io::RigRecord& rec, bool fitted) {
    const double cutoff = fit.CutoffHz(rec);
    const auto F = fit.PredictForce(rec);
    const auto v = SmoothVelocity(rec.y_mm, rec.dt_s, cutoff);
    const double pct = ScoreForce(rec, F, cutoff).nrmse_f_pct;
    const std::string title = fmt::format("{} ({}, Eq. 31 on f {:.1f} %)",
                                          std::filesystem::path(rec.source).filename().string(),
                                          fitted ? "fitted" : "held out", pct);
    auto fv = io::MakePanel(title, "Velocity [mm/s]", "Force [kN]");
    auto fx = io::MakePanel(title, "Displacement [mm]", "Force [kN]");
    io::Series mv = io::MakeSeries("", measured_color), pv = io::MakeSeries("", model_color);
    io::Series mx = mv, px = pv;
    for (std::size_t k = rec.size() * 2 / 5; k < rec.size(); ++k) {
      mv.x.push_back(v[k]);
      mv.y.push_back(rec.f_kN[k]);
      pv.x.push_back(v[k]);
      pv.y.push_back(F[k]);
      mx.x.push_back(rec.y_mm[k]);
      mx.y.push_back(rec.f_kN[k]);
      px.x.push_back(rec.y_mm[k]);
      px.y.push_back(F[k]);
    }
    fv.series = {mv, pv};
    fx.series = {mx, px};
    fv.key = fx.key = "off";
    fig.panels.push_back(std::move(fv));
    fig.panels.push_back(std::move(fx));
  };
  for (const auto& r : training) add(r, true);
  for (const auto& r : held) add(r, false);
  return fig;
}

}  // namespace rths::ident
