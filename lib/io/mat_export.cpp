#include "io/mat_export.h"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <matio.h>

#include "core/error.h"
#include "io/csv.h"
#include "io/matio_handles.h"

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
/// What matio said first, on one line (HDF5's error stacks run to dozens of lines).
std::string MatioSaid() {
  std::string m = MatioMessages();
  if (m.empty()) return "";
  m = m.substr(0, m.find('\n'));
  if (m.size() > 300) m = m.substr(0, 300) + "...";
  return " (matio: " + m + ")";
}

using Var = matio::Var;

// --- outputs: written under a temporary name, checked, then put in place -----------------------
/// An output file. A new or regular file is written beside the target under a temporary name and
/// renamed into place by Commit(). Anything else that is not a folder (a device such as
/// /dev/stdout, a FIFO, a symbolic link) is written to a temporary file in the system's temp
/// folder and copied into the target by Commit(), with every write checked. The temporary file is
/// removed unless it was renamed.
class Output {
 public:
  explicit Output(const fs::path& path) : path_(path) {
    std::error_code ec;
    if (fs::is_directory(fs::status(path, ec))) throw Error(path.string(), "is a folder, not a file");
    const auto status = fs::symlink_status(path, ec);
    copy_ = fs::exists(status) && !fs::is_regular_file(status);
    const std::string name = fmt::format(".{}.tmp-{}", path.filename().string(), ::getpid());
    tmp_ = copy_ ? fs::temp_directory_path() / name : path.parent_path() / name;
    // Can the target be written at all? (Says why not, before anything is computed.)
    std::FILE* f = std::fopen(copy_ ? path.c_str() : tmp_.c_str(), copy_ ? "ab" : "wb");
    if (!f) throw Error(path.string(), fmt::format("cannot write the file: {}", std::strerror(errno)));
    std::fclose(f);
  }
  ~Output() {
    std::error_code ec;
    if (!renamed_) fs::remove(tmp_, ec);
  }
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
  /// The file to write.
  const fs::path& tmp() const { return tmp_; }
  /// Puts the written file in place: renamed, or copied into a device / FIFO / link.
  void Commit() {
    if (!copy_) {
      if (std::rename(tmp_.c_str(), path_.c_str()) != 0)
        throw Error(path_.string(), fmt::format("cannot rename {} to it: {}", tmp_.string(), std::strerror(errno)));
      renamed_ = true;
      return;
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(tmp_.c_str(), "rb"), std::fclose);
    std::FILE* out = std::fopen(path_.c_str(), "wb");
    if (!in || !out) {
      if (out) std::fclose(out);
      throw Error(path_.string(), fmt::format("cannot write the file: {}", std::strerror(errno)));
    }
    std::vector<char> buf(1 << 16);
    bool ok = true;
    while (ok) {
      const std::size_t n = std::fread(buf.data(), 1, buf.size(), in.get());
      if (n == 0) break;
      ok = std::fwrite(buf.data(), 1, n, out) == n;
    }
    const int saved = errno;
    ok = std::fflush(out) == 0 && ok;
    const int flush_errno = errno;
    ok = std::fclose(out) == 0 && ok;
    if (!ok) throw Error(path_.string(), fmt::format("write failed: {}", std::strerror(saved ? saved : flush_errno)));
  }

 private:
  fs::path path_, tmp_;
  bool copy_ = false, renamed_ = false;
};

/// Checks that a MATLAB v5 file holds every byte its data elements announce (matio does not check
/// its writes: a full disk leaves a short file, which matio itself cannot read back safely).
void CheckV5Complete(const fs::path& file, const fs::path& target) {
  std::ifstream in(file, std::ios::binary);
  std::error_code ec;
  const std::uint64_t size = fs::file_size(file, ec);
  char header[128];
  if (ec || !in.read(header, sizeof header))
    throw Error(target.string(), "write failed: the file is shorter than a MAT-file header (disk full?)");
  const bool swap = header[126] == 'M' && header[127] == 'I';  // written big-endian
  const auto u32 = [swap](const unsigned char* b) {
    return swap ? (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3]
                : (std::uint32_t{b[3]} << 24) | (std::uint32_t{b[2]} << 16) | (std::uint32_t{b[1]} << 8) | b[0];
  };
  std::uint64_t at = 128;
  while (at < size) {
    unsigned char tag[8];
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(reinterpret_cast<char*>(tag), sizeof tag)) break;
    const std::uint32_t type = u32(tag), bytes = u32(tag + 4);
    std::uint64_t next = at + 8 + bytes;
    if (type != 15 /* miCOMPRESSED: not padded */) next = (next + 7) / 8 * 8;
    at = next;
  }
  if (at != size)
    throw Error(target.string(), fmt::format("write failed: the file written is cut short at byte {}, inside a data "
                                             "element (disk full?)",
                                             size));
}

/// Reads `file` back with matio: the struct `rths` with `steps` values in its last signal.
void CheckReadBack(const fs::path& file, const fs::path& target, const RunSignals& s) {
  mat_t* mat = Mat_Open(file.c_str(), MAT_ACC_RDONLY);
  if (!mat) throw Error(target.string(), fmt::format("the file written cannot be opened again{}", MatioSaid()));
  Var v(Mat_VarRead(mat, "rths"));
  Mat_Close(mat);
  matvar_t* signals = v ? Mat_VarGetStructFieldByName(v.get(), "signals", 0) : nullptr;
  matvar_t* last = signals && !s.columns.empty()
                       ? Mat_VarGetStructFieldByName(signals, s.columns.back().name.c_str(), 0)
                       : nullptr;
  if (!last || last->rank != 2 || last->dims[0] != s.steps() || (s.steps() > 0 && !last->data))
    throw Error(target.string(), fmt::format("the file written does not read back whole (disk full?){}", MatioSaid()));
}

// --- matio variables ------------------------------------------------------------------------
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

}  // namespace

void WriteMat(const fs::path& path, const RunSignals& signals, const ExportMeta& meta, MatVersion version) {
  Var rths_var = BuildRthsVar(path, signals, meta);
  Output tmp(path);
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
    throw Error(path.string(), fmt::format("write failed: matio error {} (disk full?){}", wrote != 0 ? wrote : closed,
                                           MatioSaid()));
  if (version == MatVersion::kV5) CheckV5Complete(tmp.tmp(), path);
  CheckReadBack(tmp.tmp(), path, signals);
  tmp.Commit();
}

void WriteSignalsCsv(const fs::path& path, const RunSignals& signals) {
  Output tmp(path);
  std::vector<std::string> header;
  for (const auto& c : signals.columns) header.push_back(c.name);
  try {
    CsvWriter w(tmp.tmp(), header);
    std::vector<std::string> row(header.size());
    for (std::size_t k = 0; k < signals.steps(); ++k) {
      // The shortest text that reads back as the same double.
      for (std::size_t j = 0; j < signals.columns.size(); ++j) row[j] = fmt::format("{}", signals.columns[j].values[k]);
      w.Row(row);
    }
    w.Close();
  } catch (const Error& e) {
    // CsvWriter names the temporary file; the user named the target.
    throw Error(path.string(), e.problem() + " (disk full?)");
  }
  tmp.Commit();
}

}  // namespace rths::io
