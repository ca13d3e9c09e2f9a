#include "io/signals_row.h"

#include <charconv>

namespace rths::io {

std::size_t FormatSignalsRow(char* row, std::int64_t k, double t_s, const std::array<double, 10>& values) {
  char* const end = row + kSignalsRowMaxBytes;
  char* p = std::to_chars(row, end, k).ptr;
  *p++ = ',';
  p = std::to_chars(p, end, t_s, std::chars_format::fixed, 6).ptr;
  for (const double v : values) {
    *p++ = ',';
    p = std::to_chars(p, end, v, std::chars_format::general, 17).ptr;
  }
  *p++ = '\n';
  return static_cast<std::size_t>(p - row);
}

}  // namespace rths::io
