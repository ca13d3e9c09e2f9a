#include "models/marths_files.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models::marths {

namespace {

double MarthsNumber(const std::string& text, const std::string& where) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || text.find_first_not_of(" \t\r", used) != std::string::npos || !std::isfinite(v)) {
    throw Error(where, fmt::format("'{}' is not a finite number", text));
  }
  return v;
}

}  // namespace

Eigen::MatrixXd ReadMatrixCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot be read");
  std::vector<std::vector<std::string>> rows;
  std::vector<int> line_of;
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;  // a blank line (the last, say)
    std::vector<std::string> fields;
    std::size_t at = 0;
    for (std::size_t comma; (comma = line.find(',', at)) != std::string::npos; at = comma + 1) {
      fields.push_back(line.substr(at, comma - at));
    }
    fields.push_back(line.substr(at));
    rows.push_back(std::move(fields));
    line_of.push_back(line_no);
  }
  if (rows.empty() || rows[0].empty()) throw Error(path, "no rows");
  Eigen::MatrixXd m(rows.size(), rows[0].size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string where = fmt::format("{}:{}", path, line_of[i]);
    if (rows[i].size() != rows[0].size()) {
      throw Error(where, fmt::format("{} fields where the first row has {}", rows[i].size(), rows[0].size()));
    }
    for (std::size_t j = 0; j < rows[i].size(); ++j) m(i, j) = MarthsNumber(rows[i][j], where);
  }
  return m;
}

RodeacInitialParameters ReadRodeacParameters(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot be read");
  RodeacInitialParameters p;
  bool seen[4] = {false, false, false, false};
  const char* names[4] = {"theta0_1", "P0_1", "theta0_2", "P0_2"};
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    line = line.substr(0, line.find('#'));
    std::istringstream ss(line);
    std::string name;
    if (!(ss >> name)) continue;
    const std::string where = fmt::format("{}:{}", path, line_no);
    int which = -1;
    for (int i = 0; i < 4; ++i) which = name == names[i] ? i : which;
    if (which < 0) throw Error(where, fmt::format("unknown entry '{}' (theta0_1, P0_1, theta0_2, P0_2)", name));
    if (seen[which]) throw Error(where, fmt::format("{} given twice", name));
    seen[which] = true;
    std::vector<double> v;
    for (std::string tok; ss >> tok;) v.push_back(MarthsNumber(tok, where));
    const std::size_t want = which % 2 == 0 ? 4 : 16;
    if (v.size() != want) throw Error(where, fmt::format("{} needs {} numbers, found {}", name, want, v.size()));
    const int act = which / 2;
    if (which % 2 == 0) {
      for (int i = 0; i < 4; ++i) p.theta0[act](i) = v[i];
    } else {
      for (int i = 0; i < 16; ++i) p.P0[act](i / 4, i % 4) = v[i];
    }
  }
  for (int i = 0; i < 4; ++i) {
    if (!seen[i]) throw Error(path, fmt::format("{} is missing", names[i]));
  }
  return p;
}

bool MarthsFiles::operator==(const MarthsFiles& o) const {
  auto same = [](const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
    return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
  };
  for (int i = 0; i < 2; ++i) {
    if (rodeac.theta0[i] != o.rodeac.theta0[i] || rodeac.P0[i] != o.rodeac.P0[i]) return false;
  }
  return same(K_ref, o.K_ref) && same(M_ref, o.M_ref);
}

}  // namespace rths::models::marths
