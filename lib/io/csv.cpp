#include "io/csv.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::io {

std::string CsvField(std::string_view field) {
  if (field.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(field);
  std::string out = "\"";
  for (char c : field) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

std::string CsvRecord(const std::vector<std::string>& fields) {
  std::string out;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (i) out += ',';
    out += CsvField(fields[i]);
  }
  out += "\r\n";
  return out;
}

std::vector<std::vector<std::string>> ParseCsv(std::string_view text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  std::size_t line = 1, i = 0;
  const std::size_t n = text.size();
  auto where = [&] { return fmt::format("csv:{}", line); };
  if (n == 0) return records;
  while (true) {
    // At the start of a field.
    field.clear();
    if (i < n && text[i] == '"') {
      const std::size_t start_line = line;
      ++i;
      while (true) {
        if (i >= n) throw Error(fmt::format("csv:{}", start_line), "quoted field is not terminated");
        const char c = text[i];
        if (c == '"') {
          if (i + 1 < n && text[i + 1] == '"') {
            field += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        if (c == '\n') ++line;
        field += c;
        ++i;
      }
      if (i < n && text[i] != ',' && text[i] != '\r' && text[i] != '\n') {
        throw Error(where(), "text after the closing quote of a field");
      }
    } else {
      while (i < n && text[i] != ',' && text[i] != '\r' && text[i] != '\n') {
        if (text[i] == '"') throw Error(where(), "double quote inside an unquoted field");
        field += text[i++];
      }
    }
    record.push_back(field);
    if (i >= n) {
      records.push_back(std::move(record));
      break;
    }
    if (text[i] == ',') {
      ++i;
      continue;
    }
    // End of record: CRLF or LF (a lone CR is accepted as well).
    if (text[i] == '\r') ++i;
    if (i < n && text[i] == '\n') ++i;
    ++line;
    records.push_back(std::move(record));
    record.clear();
    if (i >= n) break;
  }
  return records;
}

std::vector<std::vector<std::string>> ReadCsvFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string(), "cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  try {
    return ParseCsv(ss.str());
  } catch (const Error& e) {
    throw Error(path.string() + ":" + e.where(), e.problem());
  }
}

CsvWriter::CsvWriter(const std::filesystem::path& path, std::vector<std::string> header)
    : path_(path), width_(header.size()) {
  f_ = std::fopen(path.c_str(), "wb");
  if (!f_) throw Error(path.string(), "cannot open for writing");
  Row(header);
}

CsvWriter::~CsvWriter() {
  if (f_) std::fclose(f_);
}

void CsvWriter::Row(const std::vector<std::string>& fields) {
  if (!f_) throw Error(path_.string(), "already closed");
  if (fields.size() != width_) {
    throw Error(path_.string(), fmt::format("a row of {} fields in a table of {} columns", fields.size(), width_));
  }
  const std::string rec = CsvRecord(fields);
  if (std::fwrite(rec.data(), 1, rec.size(), f_) != rec.size()) throw Error(path_.string(), "write failed");
}

void CsvWriter::Close() {
  if (!f_) return;
  const bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
  std::fclose(f_);
  f_ = nullptr;
  if (!ok) throw Error(path_.string(), "write failed");
}

std::string FormatSig(double v, int digits) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:.{}g}", v, digits);
}

}  // namespace rths::io
