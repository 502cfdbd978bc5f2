#include "src/report/html.h"

#include <algorithm>
#include <cctype>
#include <cstdarg>
#include <cstdio>

namespace cdpr::report {
namespace {

// Sized for the screen and for A4 (print margins 12 mm: 186 mm of text):
// plots scale down with their container (viewBox, max-width 100%), tables
// wrap their cells, preformatted text wraps, nothing sets a width wider
// than the page. Collapsed sections print open: the print rule on
// ::details-content where the browser has it, and kPrintScript for the rest.
const char* const kStyle =
    "*{box-sizing:border-box}"
    "body{font-family:system-ui,sans-serif;font-size:15px;line-height:1.4;max-width:60rem;margin:0 auto;"
    "padding:0 1rem 2rem;color:#222;overflow-wrap:anywhere}"
    "h1{font-size:1.35rem;margin:.8rem 0 .4rem}h2{font-size:1.1rem;margin:1.2rem 0 .4rem}"
    "h3{font-size:1rem;margin:.8rem 0 .3rem}"
    ".verdict{border:2px solid #2a7;border-radius:6px;padding:.6rem .9rem;margin:.6rem 0 1rem;background:#f3fbf6}"
    ".verdict.warning{border-color:#d90;background:#fffaf0}.verdict.bad{border-color:#c33;background:#fff4f4}"
    ".verdict .conclusion{font-size:1.15rem;font-weight:600;margin:.1rem 0 .5rem}"
    ".verdict dl{display:grid;grid-template-columns:minmax(7rem,max-content) 1fr;gap:.15rem .8rem;margin:0}"
    ".verdict dt{color:#555}.verdict dd{margin:0}"
    "table{border-collapse:collapse;margin:.3rem 0;max-width:100%;font-size:.85rem}"
    "td,th{border:1px solid #ccc;padding:2px 6px;vertical-align:top}th{background:#f2f2f2;text-align:left}"
    "td.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}"
    ".wide{overflow-x:auto;max-width:100%}"
    "pre{white-space:pre-wrap;background:#f6f6f6;padding:.6rem;font-size:.75rem;max-width:100%}"
    ".plots{display:grid;grid-template-columns:repeat(auto-fit,minmax(min(100%,22rem),1fr));gap:.6rem}"
    ".plots.single{grid-template-columns:1fr}"
    "figure{margin:0;break-inside:avoid}svg{display:block;max-width:100%;height:auto}"
    "figcaption{font-size:.8rem;color:#555}"
    "details{margin:.4rem 0}summary{cursor:pointer;font-weight:600}"
    "@page{size:A4;margin:12mm}"
    "@media print{body{font-size:10pt;max-width:none;padding:0}.plots{grid-template-columns:1fr 1fr}"
    "h2{break-after:avoid}.verdict{break-inside:avoid}}"
    "@media print{details::details-content{content-visibility:visible;display:contents}}";

// A stylesheet cannot open <details>: before printing every closed one is
// opened, and closed again after, so that paper shows what the screen folds.
const char* const kPrintScript =
    "addEventListener('beforeprint',()=>{for(const d of document.querySelectorAll('details:not([open])')){"
    "d.open=true;d.dataset.printOpened='1'}});"
    "addEventListener('afterprint',()=>{for(const d of document.querySelectorAll('details[data-print-opened]')){"
    "d.open=false;delete d.dataset.printOpened}});";

bool numeric(const std::string& cell) {
  if (cell.empty()) return false;
  for (char c : cell) {
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+' || c == 'e' || c == ' ' ||
          c == ',')) {
      return false;
    }
  }
  return true;
}

}  // namespace

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string format(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list copy;
  va_copy(copy, args);
  const int size = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::string out(static_cast<std::size_t>(std::max(size, 0)) + 1, '\0');
  std::vsnprintf(out.data(), out.size(), fmt, args);
  va_end(args);
  out.resize(static_cast<std::size_t>(std::max(size, 0)));
  return out;
}

std::string page_begin(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
         "<meta name=\"viewport\" content=\"width=device-width,initial-scale=1\"><title>" +
         html_escape(title) + "</title><style>" + kStyle + "</style><script>" + kPrintScript +
         "</script></head><body>\n";
}

std::string page_end() { return "</body></html>\n"; }

std::string verdict_card(const Verdict& v) {
  const char* tone = v.tone == Tone::kGood ? "" : v.tone == Tone::kWarning ? " warning" : " bad";
  std::string html = "<section class=\"verdict" + std::string(tone) + "\"><h1>" + html_escape(v.title) +
                     "</h1><p class=\"conclusion\">" + html_escape(v.conclusion) + "</p><dl>";
  for (const auto& [label, text] : v.facts) html += "<dt>" + html_escape(label) + "</dt><dd>" + html_escape(text) + "</dd>";
  return html + "</dl></section>\n";
}

std::string table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::string html = "<div class=\"wide\"><table><tr>";
  for (const std::string& h : header) html += "<th>" + html_escape(h) + "</th>";
  html += "</tr>";
  for (const std::vector<std::string>& row : rows) {
    html += "<tr>";
    for (const std::string& cell : row) html += (numeric(cell) ? "<td class=\"n\">" : "<td>") + html_escape(cell) + "</td>";
    html += "</tr>";
  }
  return html + "</table></div>\n";
}

std::string details(const std::string& summary, const std::string& body, bool open) {
  return std::string(open ? "<details open>" : "<details>") + "<summary>" + html_escape(summary) + "</summary>" + body +
         "</details>\n";
}

}  // namespace cdpr::report
