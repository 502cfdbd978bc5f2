// The key tables of cdpr-calibd.toml against what ships beside them: the
// example lists exactly the tables' keys, each with its default, and
// docs/configuration.md is the tables' listing; refusals say what is wrong
// and what is expected.

#include <cstdlib>
#include <fstream>
// GCC 12 at -O1 with the sanitizers warns (falsely) that std::regex's NFA
// states may be used uninitialized; -Werror would stop the sanitizer build.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "config_text.h"
#include "src/daemon/daemon_config.h"
#include "drivers/modbus/load_cell_presets.h"

namespace cdpr::daemon {
namespace {

const std::string kShippedExample = std::string(CDPR_SOURCE_DIR) + "/systemd/cdpr-calibd.toml";
const std::string kDocs = std::string(CDPR_SOURCE_DIR) + "/docs/configuration.md";
constexpr std::string_view kBegin = "<!-- BEGIN keys: generated from src/daemon/daemon_config.cc -->\n";
constexpr std::string_view kEnd = "<!-- END keys -->\n";

std::string text_of(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// "table.key" of every key the example sets or shows commented out
// ("# group = ..."), in file order, each once (the [[winches.winch]] tables repeat theirs).
std::vector<std::string> keys_in_example(const std::string& text) {
  static const std::regex header(R"(^\[\[?([a-z_.]+)\]\]?\s*(#.*)?$)");
  static const std::regex key(R"(^(# )?([a-z_0-9]+) = .*$)");
  std::vector<std::string> keys;
  std::set<std::string> seen;
  std::string table;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch match;
    if (std::regex_match(line, match, header)) {
      table = match[1];
    } else if (std::regex_match(line, match, key)) {
      const std::string dotted = table.empty() ? match[2].str() : table + "." + match[2].str();
      if (seen.insert(dotted).second) keys.push_back(dotted);
    }
  }
  return keys;
}

TEST(ConfigTable, TheExampleListsExactlyTheTablesKeysInTheirOrder) {
  // GIVEN the tables and the example installed with the unit
  std::vector<std::string> table_keys;
  for (const KeyInfo& key : daemon_config_keys()) {
    table_keys.push_back(key.table.empty() ? key.name : key.table + "." + key.name);
  }
  // WHEN the example's keys are listed THEN they are the tables' keys
  EXPECT_EQ(keys_in_example(text_of(kShippedExample)), table_keys);
}

TEST(ConfigTable, TheExampleShowsEveryKeyWithItsDefault) {
  // GIVEN the example WHEN read
  const auto config = read_daemon_config(kShippedExample);
  ASSERT_TRUE(config) << config.error().message();
  // THEN every value equals the tables' default (the required keys have none)
  auto values = daemon_config_values(*config);
  auto defaults = daemon_config_values(default_daemon_config());
  for (const KeyInfo& key : daemon_config_keys()) {
    if (!key.required) continue;
    const std::string dotted = key.table.empty() ? key.name : key.table + "." + key.name;
    EXPECT_EQ(values.erase(dotted), 1u) << dotted;
    defaults.erase(dotted);
  }
  EXPECT_EQ(values, defaults);
}

TEST(ConfigTable, TheRegisterMapDefaultsAreTheDefaultPresets) {
  // GIVEN the defaults, and the defaults with the default preset's map put in
  const DaemonConfig defaults = default_daemon_config();
  DaemonConfig preset = defaults;
  preset.load_cell.map = *drivers::modbus::load_cell_preset(defaults.load_cell.preset);
  // WHEN shown THEN they are the same
  EXPECT_EQ(daemon_config_values(preset), daemon_config_values(defaults));
}

std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

// The tables as docs/configuration.md lists them: one markdown table per TOML table.
std::string keys_markdown() {
  std::string out;
  std::string table = "-";
  for (const KeyInfo& key : daemon_config_keys()) {
    if (key.table != table) {
      table = key.table;
      const bool array = table == "winches.winch";
      out += "\n### " + (table.empty() ? std::string("Top level") : (array ? "[[" : "[") + table + (array ? "]]" : "]")) +
             "\n\n| Key | Type | Unit | Default | Range | Why this range | Meaning |\n|---|---|---|---|---|---|---|\n";
    }
    const std::string fallback = key.required ? "required" : key.default_text.empty() ? "" : "`" + key.default_text + "`";
    const std::string unsafe = key.unsafe_when.empty() ? "" : "; unsafe (needs `unsafe_ok`): " + key.unsafe_when;
    out += "| `" + key.name + "` | " + escaped(key.type) + " | " + key.unit + " | " + escaped(fallback) + " | " +
           escaped(key.range + unsafe) + " | " + escaped(key.range_reason) + " | " + escaped(key.meaning) + " |\n";
  }
  return out;
}

TEST(ConfigTable, TheDocsPageListsTheTables) {
  // GIVEN docs/configuration.md
  std::string page = text_of(kDocs);
  const std::size_t begin = page.find(kBegin);
  const std::size_t end = page.find(kEnd);
  ASSERT_NE(begin, std::string::npos) << kDocs << " lacks " << kBegin;
  ASSERT_NE(end, std::string::npos) << kDocs << " lacks " << kEnd;
  const std::size_t listing = begin + kBegin.size();
  // WHEN its generated part is compared with the tables THEN they agree
  // (CDPR_UPDATE_DOCS=1 writes the tables' listing into the page).
  const std::string expected = keys_markdown();
  if (std::getenv("CDPR_UPDATE_DOCS") != nullptr) {
    page.replace(listing, end - listing, expected + "\n");
    std::ofstream(kDocs) << page;
    return;
  }
  EXPECT_EQ(page.substr(listing, end - listing), expected + "\n")
      << "run make docs (CDPR_UPDATE_DOCS=1 build/tests/daemon_tests --gtest_filter='ConfigTable.TheDocsPage*')";
}

TEST(ConfigTable, EveryNumberHasABoundedRangeAndItsReason) {
  // GIVEN every key of the tables
  for (const KeyInfo& key : daemon_config_keys()) {
    if (key.type != "integer" && key.type != "number") continue;
    // WHEN it is a number THEN its range is bounded on both sides ("a..b", "[a, b]", "(a, b]"), and says why
    const bool listed = key.range.find_first_not_of("0123456789, ") == std::string::npos;  // "0, 1, 2, 5, 6"
    const bool bounded = listed || key.range.find("..") != std::string::npos ||
                         ((key.range.starts_with("[") || key.range.starts_with("(")) &&
                          key.range.find("inf") == std::string::npos);
    EXPECT_TRUE(bounded) << key.table << "." << key.name << ": " << key.range;
    EXPECT_FALSE(key.range_reason.empty()) << key.table << "." << key.name << " does not say why its range is "
                                           << key.range;
  }
}

TEST(ConfigTable, RefusalsSayWhatIsWrongAndWhatIsExpected) {
  struct Case {
    std::string text;  // after `robot = "r"`
    std::string message;
  };
  const Case cases[] = {
      {"[winches]\nmaster_node_id = 300\n", "c.toml:3: winches.master_node_id: must be in 1..127, got 300"},
      {"[loop]\nperiod_msec = 10\n", "c.toml:3: loop.period_msec: unknown key (did you mean 'period_ms'?)"},
      {"[loops]\n", "c.toml:2: loops: unknown table (did you mean 'loop'?)"},
      {"[winches]\nmax_move_m = 0\n", "c.toml:3: winches.max_move_m: must be in (0, 1000], got 0"},
      {"[waypoints]\njitter = 0.5\n", "c.toml:3: waypoints.jitter: must be in [0, 0.5), got 0.5"},
      {"[load_cell]\nscale = 0\n", "c.toml:3: load_cell.scale: must be in [-1e+06, 1e+06], != 0, got 0"},
      {"[winches.drive]\nvendor_id = -1\n", "c.toml:3: winches.drive.vendor_id: must be in 0..0xFFFFFFFF, got -1"},
      {"[load_cell]\nbaud = \"fast\"\n", "c.toml:3: load_cell.baud: expected an integer, got a string"},
      {"[button]\nkind = \"gpoi\"\n", "c.toml:3: button.kind: \"gpoi\" is not one of \"gpio\", \"none\""},
      {"[[winches.winch]]\n[[winches.winch]]\n[[winches.winch]]\n[[winches.winch]]\nencoder_m_per_count = 0\n",
       "c.toml:6: winches.winch[3].encoder_m_per_count: must be in [-0.01, 0.01], != 0, got 0"},
  };
  for (const Case& c : cases) {
    // GIVEN one mistake WHEN parsed THEN the message names file, line and key and says what is expected
    const auto config = parse_daemon_config(test::config_text(c.text), "c.toml");
    ASSERT_FALSE(config) << c.text;
    EXPECT_EQ(config.error().message(), c.message);
  }
}

}  // namespace
}  // namespace cdpr::daemon
