#pragma once
/// @file The curves of a figure as io::Plot wrote them beside its PNG (<name>.dat, <name>.gp), for
/// tests that check what a figure shows: each curve's panel, legend entry and points, in drawing
/// order, and each panel's part of the script.
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace rths_test {

/// One curve of a figure: a data block of <name>.dat.
struct PlotCurve {
  int panel = 0;          ///< 1-based, as in the block's comment
  std::string title;      ///< its legend entry ("" = none)
  std::vector<double> x, y;
};

/// Every curve of `dat` (io::Plot's "# index N: panel P curve "T"" blocks), in file order, which
/// is the order the script draws them (a later curve is drawn over an earlier one).
inline std::vector<PlotCurve> ReadPlotData(const std::filesystem::path& dat) {
  std::ifstream in(dat);
  std::vector<PlotCurve> curves;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# index ", 0) == 0) {
      PlotCurve c;
      const std::size_t p = line.find(": panel ");
      const std::size_t q = line.find(" curve \"");
      if (p == std::string::npos || q == std::string::npos) continue;
      c.panel = std::stoi(line.substr(p + 8, q - p - 8));
      c.title = line.substr(q + 8, line.size() - q - 9);
      curves.push_back(c);
      continue;
    }
    if (line.empty() || line[0] == '#' || curves.empty()) continue;
    std::istringstream ss(line);
    double x = 0, y = 0;
    if (ss >> x >> y) {
      curves.back().x.push_back(x);
      curves.back().y.push_back(y);
    }
  }
  return curves;
}

/// The curves of panel `panel` (1-based), in drawing order.
inline std::vector<PlotCurve> PanelCurves(const std::vector<PlotCurve>& all, int panel) {
  std::vector<PlotCurve> out;
  for (const auto& c : all) {
    if (c.panel == panel) out.push_back(c);
  }
  return out;
}

/// Panel `panel`'s part of the script `gp` (from "# panel N" to the next panel or the end).
inline std::string PanelScript(const std::string& gp, int panel) {
  const std::string head = "\n# panel " + std::to_string(panel) + "\n";
  const std::size_t at = gp.find(head);
  if (at == std::string::npos) return "";
  const std::size_t next = gp.find("\n# panel ", at + head.size());
  return gp.substr(at, next == std::string::npos ? std::string::npos : next - at);
}

}  // namespace rths_test
