#pragma once
/// @file "Did you mean ...?": the allowed name closest to a mistyped one, for the messages of the
/// scenario reader and the command lines.
#include <string_view>
#include <vector>

namespace rths {

/// The allowed name closest to `name`, or "" if none is close: within an edit distance (Levenshtein)
/// of max(2, |name| / 3), or one a prefix of the other (a missing or extra suffix, "noise_y_mm" ->
/// "noise_y_mm_rms", "duration" -> "duration_s"; names of 3 characters or more).
std::string_view ClosestName(std::string_view name, const std::vector<std::string_view>& allowed);

}  // namespace rths
