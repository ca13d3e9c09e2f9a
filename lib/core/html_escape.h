#pragma once
/// @file Text made safe inside HTML, for every page the project writes or serves (the reports, the
/// live monitor's page).
#include <string>

namespace rths {

/// Text with &, <, >, " and ' escaped for HTML.
std::string HtmlEscape(const std::string& text);

}  // namespace rths
