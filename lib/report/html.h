#pragma once
/// @file The small HTML writer of rths's pages (the run report, docs/report.md; the diagnosis page): escaping, a
/// table row, the head of a page with the shared style sheet, and an atomic file write. Pages are
/// self-contained: no JavaScript, no network.
#include <filesystem>
#include <string>

#include "core/html_escape.h"

namespace rths::report {

/// Text with &, <, >, " and ' escaped for HTML (core/html_escape.h).
using rths::HtmlEscape;

/// One row of a two-column table: `<tr><th>name</th><td id="id">value_html</td></tr>` (no id
/// attribute if `id` is empty); `name` and `value_html` are HTML already.
std::string HtmlRow(const std::string& name, const std::string& value_html, const std::string& id = "");

/// The start of a page up to and including `<body>`: doctype, UTF-8, the title (escaped here) and
/// the shared style sheet (headings, tables, banners `.banner.failed|.note|.ok`, a selected row `tr.sel`, figures, `.where`).
std::string HtmlHead(const std::string& title);

/// One figure of a page: a heading `<h3 id="id">` and the PNG figures/`png_file` at `width_px`
/// with its caption (HTML already) and a link to it ("data and gnuplot script beside it").
std::string FigureHtml(const std::string& id, const std::string& heading, const std::string& png_file, int width_px,
                       const std::string& caption_html);

/// Writes `text` to `path` through `path.tmp` and a rename, so that a reader never sees half a
/// page. Throws rths::Error naming the file if it cannot be written.
void WriteFileAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace rths::report
