#include "studies/figures.h"

#include <fmt/format.h>

namespace rths::studies {

CurveStyle ControllerStyle(const std::string& name, bool prominent, std::size_t index) {
  CurveStyle s;
  auto starts = [&](const char* prefix) { return name.rfind(prefix, 0) == 0; };
  auto has = [&](const char* part) { return name.find(part) != std::string::npos; };
  if (starts("None")) {
    s.color = "#666666", s.point_type = 1;
  } else if (starts("Numerical")) {
    s.color = "#666666", s.dash = 2, s.width = 2.0, s.point_type = 6;
  } else if (starts("3rd Poly")) {
    s.color = "#D55E00", s.point_type = 9;
  } else if (starts("Lead Comp")) {
    s.color = "#CC79A7", s.point_type = 13;
  } else if (starts("Bumpless")) {
    s.color = "#882255", s.point_type = 2;
  } else if (starts("G_FF") && has("+ LQG")) {
    s.color = "#000000", s.point_type = 5;
  } else if (starts("G_FF") && has("+ LP")) {
    s.color = "#009E73", s.point_type = 4;
  } else if (starts("G_FF")) {
    s.color = "#0072B2", s.point_type = 7;
  } else {
    const auto& colors = io::ReadableColors();
    s.color = colors[index % colors.size()];
  }
  if (prominent) {
    s.width *= 2.0;
    s.point_size = 1.6;
  }
  return s;
}

io::Series StyledSeries(const std::string& title, const CurveStyle& style, const std::string& with) {
  io::Series s = io::MakeSeries(title, style.color, style.dash);
  s.width = style.width;
  s.with = with == "linespoints" ? fmt::format("linespoints pt {} ps {:g}", style.point_type, style.point_size) : with;
  return s;
}

}  // namespace rths::studies
