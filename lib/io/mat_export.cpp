#include "io/mat_export.h"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <matio.h>

#include "core/error.h"
#include "io/csv.h"

#ifndef RTHS_VERSION_STRING
#define RTHS_VERSION_STRING "unknown"
#endif

namespace rths::io {

namespace fs = std::filesystem;

std::string RthsVersion() { return std::string("rths ") + RTHS_VERSION_STRING; }

std::string MatioVersion() {
  int major = 0, minor = 0, release = 0;
  Mat_GetLibraryVersion(&major, &minor, &release);
  return fmt::format("{}.{}.{}", major, minor, release);
}

namespace {

// --- matio's own messages: collected, so that an error can say what matio said -------------
std::string& MatioMessages() {
  static std::string messages;
  return messages;
}
void CollectMatioMessage(int /*log_level*/, char* message) {
  if (!message) return;
  std::string& m = MatioMessages();
  if (!m.empty()) m += "; ";
  m += message;
}
/// Routes matio's messages into MatioMessages() (instead of stderr) and clears them.
void ResetMatioMessages() {
  static const bool installed = [] {
    Mat_LogInitFunc("rths", CollectMatioMessage);
    return true;
  }();
  (void)installed;
  MatioMessages().clear();
}
std::string MatioSaid() { return MatioMessages().empty() ? "" : " (matio: " + MatioMessages() + ")"; }

// --- temporary file beside the target, renamed into place -----------------------------------
/// A writable, empty temporary file beside `path`; removed on destruction unless Commit()ed.
class TempBeside {
 public:
  explicit TempBeside(const fs::path& path) : path_(path) {
    tmp_ = path.parent_path() / fmt::format(".{}.tmp-{}", path.filename().string(), ::getpid());
    std::FILE* f = std::fopen(tmp_.c_str(), "wb");
    if (!f) throw Error(path.string(), fmt::format("cannot write the file: {}", std::strerror(errno)));
    std::fclose(f);
  }
  ~TempBeside() {
    if (!committed_) {
      std::error_code ec;
      fs::remove(tmp_, ec);
    }
  }
  TempBeside(const TempBeside&) = delete;
  TempBeside& operator=(const TempBeside&) = delete;
  const fs::path& tmp() const { return tmp_; }
  /// Renames the temporary file to the target.
  void Commit() {
    if (std::rename(tmp_.c_str(), path_.c_str()) != 0)
      throw Error(path_.string(), fmt::format("cannot rename {} to it: {}", tmp_.string(), std::strerror(errno)));
    committed_ = true;
  }

 private:
  fs::path path_, tmp_;
  bool committed_ = false;
};

// --- matio variables ------------------------------------------------------------------------
struct VarFree {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using Var = std::unique_ptr<matvar_t, VarFree>;

/// Throws if matio could not create a variable (out of memory); `name` may be null (a field).
Var Checked(matvar_t* v, const char* name) {
  if (!v) throw Error("matio", fmt::format("cannot create a variable {}{}", name ? name : "(field)", MatioSaid()));
  return Var(v);
}

/// UTF-8 -> UTF-16 code units (MATLAB's char); an invalid byte becomes U+FFFD.
std::vector<mat_uint16_t> Utf16(std::string_view s) {
  std::vector<mat_uint16_t> out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    char32_t cp = 0xFFFD;
    std::size_t len = 1;
    if (b < 0x80) {
      cp = b;
    } else if ((b >> 5) == 0x6 || (b >> 4) == 0xE || (b >> 3) == 0x1E) {
      len = (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : 4;
      cp = b & (len == 2 ? 0x1F : len == 3 ? 0x0F : 0x07);
      bool ok = i + len <= s.size();
      for (std::size_t j = 1; ok && j < len; ++j) {
        const auto c = static_cast<unsigned char>(s[i + j]);
        ok = (c >> 6) == 0x2;
        cp = (cp << 6) | (c & 0x3F);
      }
      if (!ok) {
        cp = 0xFFFD;
        len = 1;
      }
    }
    if (cp >= 0x10000) {
      cp -= 0x10000;
      out.push_back(static_cast<mat_uint16_t>(0xD800 + (cp >> 10)));
      out.push_back(static_cast<mat_uint16_t>(0xDC00 + (cp & 0x3FF)));
    } else {
      out.push_back(static_cast<mat_uint16_t>(cp));
    }
    i += len;
  }
  return out;
}

/// A 1 x n char row vector.
Var CharVar(const char* name, std::string_view text) {
  std::vector<mat_uint16_t> units = Utf16(text);
  size_t dims[2] = {1, units.size()};
  mat_uint16_t empty = 0;
  return Checked(Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, dims, units.empty() ? &empty : units.data(), 0),
                 name);
}

/// An n x 1 double column vector (n may be 0).
Var ColumnVar(const char* name, const std::vector<double>& values) {
  size_t dims[2] = {values.size(), 1};
  double empty = 0.0;
  return Checked(Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                               values.empty() ? &empty : const_cast<double*>(values.data()), 0),
                 name);
}

Var ScalarVar(const char* name, double v) { return ColumnVar(name, std::vector<double>{v}); }

Var Int64Var(const char* name, std::int64_t v) {
  size_t dims[2] = {1, 1};
  mat_int64_t x = v;
  return Checked(Mat_VarCreate(name, MAT_C_INT64, MAT_T_INT64, 2, dims, &x, 0), name);
}

/// A 1 x 1 struct with the given field names (in order), fields empty until Set().
Var StructVar(const char* name, const std::vector<std::string>& fields) {
  std::vector<const char*> names;
  for (const auto& f : fields) names.push_back(f.c_str());
  names.push_back(nullptr);
  size_t dims[2] = {1, 1};
  return Checked(Mat_VarCreateStruct2(name, 2, dims, names.data()), name);
}

/// Moves `value` into field `field` of the 1 x 1 struct `s` (the struct owns it from then on).
void Set(matvar_t* s, const std::string& field, Var value) {
  // Returns the field's previous value (none: every field is set once).
  Mat_VarFree(Mat_VarSetStructFieldByName(s, field.c_str(), 0, value.release()));
}

/// Throws unless `name` is a valid MATLAB field name.
void CheckFieldName(const fs::path& path, const std::string& name) {
  bool ok = !name.empty() && name.size() <= 63 && std::isalpha(static_cast<unsigned char>(name[0]));
  for (char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
  if (!ok)
    throw Error(path.string(), fmt::format("signal name '{}' is not a MATLAB field name (letters, digits and '_', "
                                           "starting with a letter, at most 63 characters)",
                                           name));
}

/// The whole `rths` struct.
Var BuildRthsVar(const fs::path& path, const RunSignals& s, const ExportMeta& meta) {
  std::vector<std::string> names;
  for (const auto& c : s.columns) {
    CheckFieldName(path, c.name);
    names.push_back(c.name);
  }
  Var signals = StructVar(nullptr, names), units = StructVar(nullptr, names),
      descriptions = StructVar(nullptr, names);
  for (const auto& c : s.columns) {
    Set(signals.get(), c.name, ColumnVar(nullptr, c.values));
    Set(units.get(), c.name, CharVar(nullptr, c.unit));
    Set(descriptions.get(), c.name, CharVar(nullptr, c.description));
  }
  const std::vector<std::string> meta_fields{"run_id",          "dt_s",       "steps",        "planned_steps",
                                             "complete",        "status",     "scenario",     "scenario_sha256",
                                             "source_log",      "rths_version", "matio_version"};
  Var m = StructVar(nullptr, meta_fields);
  Set(m.get(), "run_id", Int64Var(nullptr, meta.run_id));
  Set(m.get(), "dt_s", ScalarVar(nullptr, s.dt_s));
  Set(m.get(), "steps", ScalarVar(nullptr, static_cast<double>(s.steps())));
  Set(m.get(), "planned_steps", ScalarVar(nullptr, static_cast<double>(meta.planned_steps)));
  Set(m.get(), "complete", ScalarVar(nullptr, meta.complete ? 1.0 : 0.0));
  Set(m.get(), "status", CharVar(nullptr, meta.status));
  Set(m.get(), "scenario", CharVar(nullptr, meta.scenario_toml));
  Set(m.get(), "scenario_sha256", CharVar(nullptr, meta.scenario_sha256));
  Set(m.get(), "source_log", CharVar(nullptr, meta.source_log));
  Set(m.get(), "rths_version", CharVar(nullptr, RthsVersion()));
  Set(m.get(), "matio_version", CharVar(nullptr, MatioVersion()));

  Var top = StructVar("rths", {"signals", "units", "descriptions", "names", "meta"});
  Set(top.get(), "signals", std::move(signals));
  Set(top.get(), "units", std::move(units));
  Set(top.get(), "descriptions", std::move(descriptions));
  // A comma-separated string rather than a cell array: GNU Octave cannot read matio's v7.3 cells.
  std::string joined;
  for (const auto& n : names) joined += (joined.empty() ? "" : ",") + n;
  Set(top.get(), "names", CharVar(nullptr, joined));
  Set(top.get(), "meta", std::move(m));
  return top;
}

struct MatClose {
  void operator()(mat_t* m) const { Mat_Close(m); }
};

}  // namespace

void WriteMat(const fs::path& path, const RunSignals& signals, const ExportMeta& meta, MatVersion version) {
  Var rths_var = BuildRthsVar(path, signals, meta);
  TempBeside tmp(path);
  ResetMatioMessages();
  const std::string header =
      fmt::format("MATLAB {} MAT-file, written by {} (matio {}), run {}", version == MatVersion::kV73 ? "7.3" : "5.0",
                  RthsVersion(), MatioVersion(), meta.run_id)
          .substr(0, 116);
  mat_t* mat = Mat_CreateVer(tmp.tmp().c_str(), header.c_str(), version == MatVersion::kV73 ? MAT_FT_MAT73 : MAT_FT_MAT5);
  if (!mat) {
    if (version == MatVersion::kV73)
      throw Error(path.string(), fmt::format("matio {} cannot create a MATLAB v7.3 file (this libmatio was built "
                                             "without HDF5?){}; use --mat-version 5",
                                             MatioVersion(), MatioSaid()));
    throw Error(path.string(), fmt::format("matio {} cannot create the file{}", MatioVersion(), MatioSaid()));
  }
  // v5: zlib-compressed (MATLAB 7 and later, Octave, SciPy read it); v7.3: HDF5's own layout.
  const int wrote = Mat_VarWrite(mat, rths_var.get(), MAT_COMPRESSION_ZLIB);
  const int closed = Mat_Close(mat);
  if (wrote != 0 || closed != 0)
    throw Error(path.string(), fmt::format("matio could not write the data (error {}){}", wrote != 0 ? wrote : closed,
                                           MatioSaid()));
  tmp.Commit();
}

void WriteSignalsCsv(const fs::path& path, const RunSignals& signals) {
  TempBeside tmp(path);
  std::vector<std::string> header;
  for (const auto& c : signals.columns) header.push_back(c.name);
  {
    CsvWriter w(tmp.tmp(), header);
    std::vector<std::string> row(header.size());
    for (std::size_t k = 0; k < signals.steps(); ++k) {
      // The shortest text that reads back as the same double.
      for (std::size_t j = 0; j < signals.columns.size(); ++j) row[j] = fmt::format("{}", signals.columns[j].values[k]);
      w.Row(row);
    }
    try {
      w.Close();
    } catch (const Error& e) {
      throw Error(path.string(), e.problem());
    }
  }
  tmp.Commit();
}

}  // namespace rths::io
