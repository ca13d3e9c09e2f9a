// The small HTML writer (report/html.h).
#include "report/html.h"

#include <fstream>
#include <system_error>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::report {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStyle = R"(
body { font-family: sans-serif; max-width: 1150px; margin: 1.5em auto; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.25em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
.where { color: #666; margin-top: 0; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { text-align: left; vertical-align: top; padding: 0.25em 0.8em 0.25em 0; border-bottom: 1px solid #eee; }
th { font-weight: 600; white-space: nowrap; }
.banner { padding: 0.8em 1em; margin: 1em 0; border-radius: 4px; font-size: 1.05em; }
.banner.failed { background: #fde2e1; border: 2px solid #c62828; }
.banner.note { background: #fff4d6; border: 1px solid #d9a400; }
.banner.ok { background: #e5f4e7; border: 1px solid #2e7d32; }
.banner p { margin: 0.3em 0; }
figure { margin: 1em 0 2em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { color: #444; font-size: 0.95em; margin-top: 0.3em; }
tr.sel td { background: #dfd; }
pre { background: #f6f6f6; padding: 0.8em; overflow-x: auto; font-size: 0.9em; }
)";

}  // namespace

std::string HtmlRow(const std::string& name, const std::string& value_html, const std::string& id) {
  return fmt::format("<tr><th>{}</th><td{}>{}</td></tr>\n", name, id.empty() ? "" : " id=\"" + id + "\"", value_html);
}

std::string HtmlHead(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" + HtmlEscape(title) +
         "</title>\n<style>" + kStyle + "</style></head><body>\n";
}

std::string FigureHtml(const std::string& id, const std::string& heading, const std::string& png_file, int width_px,
                       const std::string& caption_html) {
  return fmt::format("<h3 id=\"{}\">{}</h3>\n<figure><img src=\"figures/{}\" alt=\"{}\" width=\"{}\">\n"
                     "<figcaption>{} (<a href=\"figures/{}\">{}</a>; data and gnuplot script beside it)</figcaption>"
                     "</figure>\n",
                     id, HtmlEscape(heading), png_file, HtmlEscape(heading), width_px, caption_html, png_file, png_file);
}

void WriteFileAtomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!(f << text) || !(f.flush())) throw Error(tmp.string(), "cannot write");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw Error(path.string(), "cannot write: " + ec.message());
}

}  // namespace rths::report
