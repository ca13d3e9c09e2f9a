#pragma once
/// @file The live monitor's page (docs/monitor.md): HTML, CSS and the script that draws the pushed
/// points with dygraphs (served by the monitor from Debian's libjs-dygraphs, nothing from a CDN).
#include <string>

namespace rths::monitor {

/// The page, titled `title` (HTML-escaped). Its script reads the token from the page's own URL.
/// With `snapshot_json` (LiveView::Since's JSON) the page draws that state once and opens no event
/// stream: a page that finishes loading, for a headless browser's screenshot of a running test.
std::string PageHtml(const std::string& title, const std::string& snapshot_json = "");

}  // namespace rths::monitor
