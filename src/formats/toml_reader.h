#pragma once
// Validated reads from a parsed TOML document, shared by the robot.toml,
// calibration.toml and truth.toml parsers (docs/FORMATS.md).
//
// Error policy: the first problem is recorded as a FormatError naming the
// file, the line and the dotted key ("winch[2].anchor"; tables of an array
// are numbered from 0, like cables), and every later read becomes a no-op
// that returns a default. A parser therefore reads straight through, then
// checks failed() once; nothing throws out of it.

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <toml++/toml.h>

#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

enum class Presence { kRequired, kOptional };

// One allowed key of a table. A table's schema is a list of these, so a new
// optional key or table is one more line in its parser.
struct KeySpec {
  std::string_view name;
  Presence presence;
};

// Range a number must lie in; refused values name the bound.
enum class Bound { kAny, kPositive, kNonNegative };

// Parses TOML text; a syntax error becomes a FormatError with toml++'s line.
Expected<toml::table, FormatError> parse_toml_document(std::string_view text, const std::string& source);

// "winch[2]" + "anchor" -> "winch[2].anchor"; "" + "name" -> "name".
std::string join_key(std::string_view path, std::string_view key);

class TomlReader {
 public:
  explicit TomlReader(std::string source) : source_(std::move(source)) {}

  bool failed() const { return error_.has_value(); }
  const FormatError& error() const { return *error_; }
  // Records a problem unless one is recorded already (the first one wins).
  void fail(int line, std::string field, std::string reason);

  // Refuses any key of `table` not in `keys` (naming it, its line and the
  // nearest allowed key), then names every required key that is absent.
  void check_keys(const toml::table& table, std::string_view path, std::initializer_list<KeySpec> keys);

  // A sub-table; an empty table when absent (after failing if required).
  const toml::table& table(const toml::table& parent, std::string_view key, std::string_view path,
                           Presence presence = Presence::kRequired);
  // An array of tables ([[key]]); empty when absent (after failing).
  std::vector<const toml::table*> tables(const toml::table& parent, std::string_view key, std::string_view path);

  // Integers are accepted where a number is expected (`mass = 34`); the
  // value must be finite and inside `bound`.
  double number(const toml::table& table, std::string_view key, std::string_view path, Bound bound = Bound::kAny);
  std::optional<double> optional_number(const toml::table& table, std::string_view key, std::string_view path,
                                        Bound bound = Bound::kAny);
  std::int64_t integer(const toml::table& table, std::string_view key, std::string_view path);
  // A non-negative integer that fits an int (counts: samples, iterations).
  int count(const toml::table& table, std::string_view key, std::string_view path);
  std::string string(const toml::table& table, std::string_view key, std::string_view path);
  std::vector<std::string> strings(const toml::table& table, std::string_view key, std::string_view path);
  // Exactly three finite numbers, each inside `bound`.
  Eigen::Vector3d vector3(const toml::table& table, std::string_view key, std::string_view path,
                          Bound bound = Bound::kAny);
  // A number (-> one value) or a non-empty array of numbers, all finite.
  std::vector<double> number_or_numbers(const toml::node& node, const std::string& field);
  // An offset date-time, returned in RFC 3339 form ("2026-11-22T10:15:00Z").
  std::string offset_date_time(const toml::table& table, std::string_view key, std::string_view path);

  static int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

 private:
  // The node at `key`, or nullptr after failing (missing required key).
  const toml::node* require(const toml::table& table, std::string_view key, std::string_view path);
  // A finite number inside `bound`, or nullopt after failing.
  std::optional<double> checked_number(const toml::node& node, const std::string& field, Bound bound);

  std::string source_;
  std::optional<FormatError> error_;
};

// The frame of every TOML parser: parse the text, let `read(reader, root)`
// build the value through `reader`, and return it or the first problem.
template <class T, class Read>
Expected<T, FormatError> parse_toml(std::string_view text, const std::string& source, Read read) {
  const auto document = parse_toml_document(text, source);
  if (!document) return Unexpected{document.error()};
  TomlReader reader(source);
  T value = read(reader, *document);
  if (reader.failed()) return Unexpected{reader.error()};
  return value;
}

}  // namespace cdpr::formats
