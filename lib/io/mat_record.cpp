// ReadMatRecord, IsMatFile, MatVariableNames of io/column_record.h: rig records from MATLAB
// .mat files through matio (v5 and, through its HDF5, v7.3).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>

#include <fmt/format.h>
#include <matio.h>

#include "core/error.h"
#include "io/column_record.h"
#include "io/matio_handles.h"

namespace rths::io {

namespace {

using MatFile = matio::File;
using MatVar = matio::Var;

MatFile Open(const std::string& path) {
  MatFile m(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  if (!m) throw Error(path, "cannot open as a MATLAB .mat file");
  return m;
}

/// The elements of a real numeric variable as doubles (column-major), or an error message.
template <typename T>
void Append(const matvar_t* v, std::size_t n, std::vector<double>* out) {
  const T* p = static_cast<const T*>(v->data);
  for (std::size_t k = 0; k < n; ++k) out->push_back(static_cast<double>(p[k]));
}

std::vector<double> Elements(const matvar_t* v, const std::string& what, const std::string& path) {
  if (v->isComplex) throw Error(path, fmt::format("{} is complex: a record needs real numbers", what));
  std::size_t n = 1;
  for (int d = 0; d < v->rank; ++d) n *= v->dims[d];
  if (n > 0 && v->data == nullptr) throw Error(path, fmt::format("{} holds no data matio can read", what));
  std::vector<double> out;
  out.reserve(n);
  switch (v->class_type) {
    case MAT_C_DOUBLE: Append<double>(v, n, &out); break;
    case MAT_C_SINGLE: Append<float>(v, n, &out); break;
    case MAT_C_INT8: Append<std::int8_t>(v, n, &out); break;
    case MAT_C_UINT8: Append<std::uint8_t>(v, n, &out); break;
    case MAT_C_INT16: Append<std::int16_t>(v, n, &out); break;
    case MAT_C_UINT16: Append<std::uint16_t>(v, n, &out); break;
    case MAT_C_INT32: Append<std::int32_t>(v, n, &out); break;
    case MAT_C_UINT32: Append<std::uint32_t>(v, n, &out); break;
    case MAT_C_INT64: Append<std::int64_t>(v, n, &out); break;
    case MAT_C_UINT64: Append<std::uint64_t>(v, n, &out); break;
    default: throw Error(path, fmt::format("{} is not a numeric array (a struct, cell, char or sparse)", what));
  }
  return out;
}

/// The values a SOURCE names (column_record.h): NAME, NAME.FIELD or NAME(:,K), as a vector;
/// `names`: the file's variables (MatVariableNames).
std::vector<double> ReadSource(mat_t* mat, const std::vector<std::string>& names, const std::string& source,
                               const std::string& path) {
  std::string name = source, field;
  long column = 0;  // 1-based, 0 = the variable is a vector
  if (const auto paren = source.find("(:,"); paren != std::string::npos && source.back() == ')') {
    name = source.substr(0, paren);
    const std::string k = source.substr(paren + 3, source.size() - paren - 4);
    char* end = nullptr;
    column = std::strtol(k.c_str(), &end, 10);
    if (k.empty() || *end != '\0' || column < 1)
      throw Error(path, fmt::format("\"{}\": NAME(:,K) needs a column K >= 1", source));
  } else if (const auto dot = source.find('.'); dot != std::string::npos) {
    name = source.substr(0, dot);
    field = source.substr(dot + 1);
  }
  if (std::find(names.begin(), names.end(), name) == names.end())
    throw Error(path, fmt::format("no variable \"{}\" (for {}); the file's variables: {}", name, source, JoinNames(names)));
  MatVar var(Mat_VarRead(mat, name.c_str()));
  if (!var) throw Error(path, fmt::format("cannot read the variable \"{}\"", name));
  const matvar_t* v = var.get();
  if (!field.empty()) {
    if (var->class_type != MAT_C_STRUCT) throw Error(path, fmt::format("\"{}\" is not a struct (for {})", name, source));
    v = Mat_VarGetStructFieldByName(var.get(), field.c_str(), 0);
    if (v == nullptr) {
      std::vector<std::string> fields;
      char* const* fn = Mat_VarGetStructFieldnames(var.get());
      for (unsigned i = 0; fn != nullptr && i < Mat_VarGetNumberOfFields(var.get()); ++i) fields.emplace_back(fn[i]);
      throw Error(path, fmt::format("struct \"{}\" has no field \"{}\"; its fields: {}", name, field, JoinNames(fields)));
    }
  }
  const auto all = Elements(v, "\"" + source + "\"", path);
  if (v->rank != 2) throw Error(path, fmt::format("\"{}\" has {} dimensions: a record needs vectors", source, v->rank));
  const std::size_t rows = v->dims[0], cols = v->dims[1];
  if (column > 0) {
    if (static_cast<std::size_t>(column) > cols)
      throw Error(path, fmt::format("\"{}\": the matrix has {} columns", source, cols));
    return {all.begin() + static_cast<std::ptrdiff_t>((column - 1) * rows),
            all.begin() + static_cast<std::ptrdiff_t>(column * rows)};
  }
  if (rows != 1 && cols != 1)
    throw Error(path, fmt::format("\"{}\" is a {} x {} matrix: name one column, {}(:,K)", source, rows, cols, source));
  return all;
}

/// The map of a .mat file in the rig record's own names (column_record.h), from the variables it has.
ColumnMap OwnNamesMap(mat_t* mat, const std::vector<std::string>& names, const std::string& path) {
  auto has = [&](const char* n) { return std::find(names.begin(), names.end(), n) != names.end(); };
  std::string text;
  for (const auto& [role, name] : {std::pair{'t', "t_s"}, {'u', "u_mm"}, {'y', "y_mm"}, {'f', "f_kN"}, {'i', "i_A"},
                                   {'v', "v_V"}, {'r', "r_mm"}})
    if (has(name)) text += fmt::format("{}{}={}", text.empty() ? "" : ",", role, name);
  if (!has("y_mm") || !has("f_kN") || (!has("t_s") && !has("dt_s")))
    throw Error(path, fmt::format("a .mat file without the rig record's variable names (t_s or dt_s, y_mm, f_kN; "
                                  "u_mm, i_A, v_V, r_mm): name its variables with --columns ROLE=VARIABLE[*SCALE][:UNIT]"
                                  ",... (e.g. --columns t=time,y=disp:cm,f=force:N,v=volt); its variables: {} "
                                  "(docs/rig_record.md \"Other formats\")",
                                  JoinNames(names)));
  if (!has("t_s")) {
    const auto dt = ReadSource(mat, names, "dt_s", path);
    if (dt.size() != 1) throw Error(path, "dt_s must be a scalar [s]");
    text += fmt::format(",dt={}", dt[0]);
  }
  return ParseColumnMap(text, path);
}

}  // namespace

bool IsMatFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[128] = {};
  in.read(head, sizeof head);
  const std::string h(head, static_cast<std::size_t>(in.gcount()));
  return h.rfind("MATLAB ", 0) == 0 && h.find("MAT-file") != std::string::npos;
}

std::vector<std::string> MatVariableNames(const std::string& path) {
  const MatFile mat = Open(path);
  std::vector<std::string> names;
  while (matvar_t* v = Mat_VarReadNextInfo(mat.get())) {
    if (v->name != nullptr) names.emplace_back(v->name);
    Mat_VarFree(v);
  }
  return names;
}

RigRecord ReadMatRecord(const std::string& path, const ColumnMap* map) {
  const auto names = MatVariableNames(path);
  const MatFile mat = Open(path);
  const ColumnMap own = map == nullptr ? OwnNamesMap(mat.get(), names, path) : ColumnMap{};
  const ColumnMap& m = map == nullptr ? own : *map;
  std::vector<std::vector<double>> values;
  for (const auto& c : m.columns) {
    values.push_back(ReadSource(mat.get(), names, c.source, path));
    for (double x : values.back())
      if (!std::isfinite(x)) throw Error(path, fmt::format("\"{}\" holds a value that is not finite", c.source));
  }
  return RecordFromColumns(m, path, std::move(values));
}

}  // namespace rths::io
