#pragma once
// The frame every report page shares: one self-contained HTML5 file (inline
// CSS and SVG, no script, nothing fetched) that fits the screen and an A4
// page, opening with one verdict card; the statistics follow collapsed.

#include <string>
#include <utility>
#include <vector>

namespace cdpr::report {

// Text with &, <, >, " escaped for HTML and SVG.
std::string html_escape(const std::string& text);
// printf into a std::string.
std::string format(const char* format, ...) __attribute__((format(printf, 1, 2)));

// How the verdict reads at a glance: the card's colour and its headline mark.
enum class Tone { kGood, kWarning, kBad };

// What a reader must learn from the first screen. Every field is plain text.
struct Verdict {
  std::string title;       // "Calibration of robot large"
  Tone tone = Tone::kGood;
  std::string conclusion;  // one line: "explained by elasticity", "structure remains: ..."
  // Labelled lines in this order, e.g. {"model", "catenary + elasticity"},
  // {"added", "axial_stiffness = 1.5e6 +- 2e4 N"}, {"held-out misfit", ...}.
  std::vector<std::pair<std::string, std::string>> facts;
};

std::string page_begin(const std::string& title);
std::string page_end();
std::string verdict_card(const Verdict& verdict);

// A table: header cells and rows of cells (already escaped or plain text
// to escape: `escape`). Numeric-looking cells align right.
std::string table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
// `<details><summary>summary</summary>body</details>`; `body` is HTML.
std::string details(const std::string& summary, const std::string& body, bool open = false);

}  // namespace cdpr::report
