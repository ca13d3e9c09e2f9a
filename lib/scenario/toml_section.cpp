/// @file The messages' helpers of toml_section.h: lists, a node's type.
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
