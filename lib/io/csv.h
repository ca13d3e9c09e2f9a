#pragma once
/// @file CSV as RFC 4180 says: fields separated by commas, records ended by CRLF; a field that
/// holds a comma, a double quote, CR or LF is enclosed in double quotes, and a double quote in it
/// is written twice ("G_FF,0.0A + LP" -> "\"G_FF,0.0A + LP\""). Every reproduction writes its
/// tables with this, so any spreadsheet or csv module reads them back unchanged.
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rths::io {

/// One field, quoted only when it must be (comma, double quote, CR or LF inside).
std::string CsvField(std::string_view field);
/// One record: the fields joined by commas, ended by CRLF.
std::string CsvRecord(const std::vector<std::string>& fields);

/// Parses RFC 4180 text (CRLF or LF line ends; an optional last line end). Returns the records,
/// header included. Throws rths::Error("csv:<line>", ...) for a quote inside an unquoted field,
/// text after a closing quote, or an unterminated quoted field.
std::vector<std::vector<std::string>> ParseCsv(std::string_view text);
/// Reads and parses a file (throws rths::Error naming the file).
std::vector<std::vector<std::string>> ReadCsvFile(const std::filesystem::path& path);

/// Writes a CSV file record by record: the header first, then rows with the same number of
/// fields (a row of another width throws rths::Error). Close() (or the destructor) flushes.
class CsvWriter {
 public:
  /// Creates `path` (overwrites); throws rths::Error if it cannot be opened.
  CsvWriter(const std::filesystem::path& path, std::vector<std::string> header);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  void Row(const std::vector<std::string>& fields);
  /// Flushes and closes; throws rths::Error if the data could not be written.
  void Close();

 private:
  std::filesystem::path path_;
  std::size_t width_;
  std::FILE* f_ = nullptr;
};

/// A number for a table: `digits` significant digits, no trailing exponent for ordinary sizes
/// ("46.07", "0.4631"); "nan" for NaN.
std::string FormatSig(double v, int digits = 4);

}  // namespace rths::io
