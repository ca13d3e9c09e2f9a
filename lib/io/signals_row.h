#pragma once
/// @file A row of a run's signals.csv (written by the logger, docs/lockstep.md "Logging"):
///   k, t_s, r_mm, u_mm, u_ff_mm, u_fb_mm, y_mm, e_mm, f_kN, i_cmd_A, i_eff_A, ground_acc_mm_s2
/// k as an integer, t_s with six decimals, the others with 17 significant digits (exact doubles).
#include <array>
#include <cstddef>
#include <cstdint>

namespace rths::io {

/// The header line of signals.csv (with its newline).
inline constexpr const char* kSignalsCsvHeader =
    "k,t_s,r_mm,u_mm,u_ff_mm,u_fb_mm,y_mm,e_mm,f_kN,i_cmd_A,i_eff_A,ground_acc_mm_s2\n";
/// The longest row [bytes]: k (20), t and ten numbers of at most 24 characters, commas, newline.
inline constexpr std::size_t kSignalsRowMaxBytes = 20 + 1 + 24 + 10 * (1 + 24) + 1;

/// Writes the row of step k at `row` (at least kSignalsRowMaxBytes bytes) and returns its length:
/// the same bytes as printf("%" PRId64 ",%.6f" + ",%.17g" x 10 + "\n"), by std::to_chars (whose
/// precision overloads are printf's conversions, without its format parsing and locale).
/// `values`: r_mm, u_mm, u_ff_mm, u_fb_mm, y_mm, e_mm, f_kN, i_cmd_A, i_eff_A, ground_acc_mm_s2.
std::size_t FormatSignalsRow(char* row, std::int64_t k, double t_s, const std::array<double, 10>& values);

}  // namespace rths::io
