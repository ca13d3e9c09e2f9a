/// @file The messages' helpers of toml_section.h: lists, the closest allowed name, a node's type.
#include "scenario/toml_section.h"

namespace rths::scenario::detail {


/// Comma-separated list, each item wrapped in `quote`.
std::string JoinList(const std::vector<std::string_view>& items, std::string_view quote) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += ", ";
    out += quote;
    out += items[i];
    out += quote;
  }
  return out;
}

namespace {

std::size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

/// The allowed name closest to `name`, or "" if none is close (a typo or a missing/extra suffix).
std::string_view ClosestName(std::string_view name, const std::vector<std::string_view>& allowed) {
  std::string_view best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (std::string_view candidate : allowed) {
    std::size_t d = EditDistance(name, candidate);
    const bool close = d <= std::max<std::size_t>(2, name.size() / 3);
    const bool affix = name.size() >= 3 && (candidate.starts_with(name) || name.starts_with(candidate));
    if (!close && !affix) continue;
    if (affix) d = std::min<std::size_t>(d, 1);  // "noise_y_mm" -> "noise_y_mm_rms"
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

/// "string \"abc\"", "float 2.5", "table", ... for type errors.
std::string DescribeNode(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return fmt::format("string \"{}\"", node.as_string()->get());
    case toml::node_type::integer:
      return fmt::format("integer {}", node.as_integer()->get());
    case toml::node_type::floating_point:
      return fmt::format("float {}", node.as_floating_point()->get());
    case toml::node_type::boolean:
      return fmt::format("boolean {}", node.as_boolean()->get());
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    case toml::node_type::none:
      break;
  }
  return "nothing";
}

}  // namespace rths::scenario::detail
