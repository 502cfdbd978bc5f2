#include "src/formats/toml_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <utility>

#include "src/formats/nearest_name.h"
#include "src/formats/toml_text_check.h"

namespace cdpr::formats {
namespace {

const toml::table& empty_table() {
  static const toml::table empty;
  return empty;
}

std::string type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

std::string unknown_key_reason(const toml::node& node, std::string_view key, std::initializer_list<KeySpec> keys) {
  const std::string reason = node.is_table() || node.is_array_of_tables() ? "unknown table" : "unknown key";
  std::vector<std::string_view> allowed;
  for (const KeySpec& spec : keys) allowed.push_back(spec.name);
  if (const auto nearest = nearest_name(key, allowed))
    return reason + " (did you mean '" + std::string(*nearest) + "'?)";
  if (allowed.empty()) return reason + " (this table takes no keys)";
  std::string list;
  for (const std::string_view name : allowed) list += (list.empty() ? "" : ", ") + std::string(name);
  return reason + " (allowed here: " + list + ")";
}

// RFC 3339 text of an offset date-time, the form calibration.toml writes.
std::string rfc3339(const toml::date_time& dt) {
  char text[64];
  int n = std::snprintf(text, sizeof text, "%04u-%02u-%02uT%02u:%02u:%02u", dt.date.year, dt.date.month, dt.date.day,
                        dt.time.hour, dt.time.minute, dt.time.second);
  std::string result(text, static_cast<std::size_t>(n));
  if (dt.time.nanosecond != 0) {
    std::snprintf(text, sizeof text, ".%09u", dt.time.nanosecond);
    std::string fraction = text;
    fraction.erase(fraction.find_last_not_of('0') + 1);
    result += fraction;
  }
  const int offset = dt.offset->minutes;
  if (offset == 0) return result + "Z";
  const int magnitude = std::abs(offset);
  n = std::snprintf(text, sizeof text, "%c%02d:%02d", offset < 0 ? '-' : '+', magnitude / 60, magnitude % 60);
  return result + std::string(text, static_cast<std::size_t>(n));
}

// Where to point for a key missing from `table`: its header line, or no line
// (the whole file) for the root table.
int missing_key_line(const toml::table& table, std::string_view path) {
  return path.empty() ? 0 : TomlReader::line_of(table);
}

}  // namespace

Expected<toml::table, FormatError> parse_toml_document(std::string_view text, const std::string& source) {
  // Before toml++ sees it: some non-ASCII text makes toml++ 3.3.0 undefined.
  if (std::optional<FormatError> unsafe = find_unsafe_non_ascii(text, source)) return Unexpected{std::move(*unsafe)};
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return Unexpected{FormatError{source, static_cast<int>(e.source().begin.line), "",
                                  "TOML syntax: " + std::string(e.description())}};
  }
}

std::string join_key(std::string_view path, std::string_view key) {
  if (path.empty()) return std::string(key);
  return std::string(path) + "." + std::string(key);
}

void TomlReader::fail(int line, std::string field, std::string reason) {
  if (!error_) error_ = FormatError{source_, line, std::move(field), std::move(reason)};
}

void TomlReader::check_keys(const toml::table& table, std::string_view path, std::initializer_list<KeySpec> keys) {
  // Unknown keys first: a misspelt key also makes a required one "missing",
  // and the misspelling is the more useful thing to report.
  for (auto&& [key, node] : table) {
    const std::string_view name = key.str();  // (clang 14 cannot capture a structured binding)
    const bool known = std::any_of(keys.begin(), keys.end(), [name](const KeySpec& s) { return s.name == name; });
    if (!known) {
      fail(static_cast<int>(key.source().begin.line), join_key(path, key.str()),
           unknown_key_reason(node, key.str(), keys));
    }
  }
  std::string missing;
  for (const KeySpec& spec : keys) {
    if (spec.presence == Presence::kRequired && !table.contains(spec.name)) {
      missing += (missing.empty() ? "" : ", ") + join_key(path, spec.name);
    }
  }
  if (!missing.empty()) {
    const bool several = missing.find(',') != std::string::npos;
    fail(missing_key_line(table, path), missing, several ? "missing required keys" : "missing required key");
  }
}

const toml::node* TomlReader::require(const toml::table& table, std::string_view key, std::string_view path) {
  if (failed()) return nullptr;
  const toml::node* node = table.get(key);
  if (node == nullptr) fail(missing_key_line(table, path), join_key(path, key), "missing required key");
  return node;
}

const toml::table& TomlReader::table(const toml::table& parent, std::string_view key, std::string_view path,
                                     Presence presence) {
  if (failed()) return empty_table();
  const toml::node* node = parent.get(key);
  if (node == nullptr) {
    if (presence == Presence::kRequired) {
      fail(missing_key_line(parent, path), join_key(path, key), "missing required table");
    }
    return empty_table();
  }
  if (!node->is_table()) {
    fail(line_of(*node), join_key(path, key), "expected a table [" + std::string(key) + "], got " + type_name(*node));
    return empty_table();
  }
  return *node->as_table();
}

std::vector<const toml::table*> TomlReader::tables(const toml::table& parent, std::string_view key,
                                                   std::string_view path) {
  std::vector<const toml::table*> result;
  const toml::node* node = require(parent, key, path);
  if (node == nullptr) return result;
  if (!node->is_array_of_tables()) {
    fail(line_of(*node), join_key(path, key), "expected [[" + std::string(key) + "]] tables, got " + type_name(*node));
    return result;
  }
  for (const toml::node& element : *node->as_array()) result.push_back(element.as_table());
  return result;
}

std::optional<double> TomlReader::checked_number(const toml::node& node, const std::string& field, Bound bound) {
  if (!node.is_number()) {
    fail(line_of(node), field, "expected a number, got " + type_name(node));
    return std::nullopt;
  }
  // Integers are widened here: toml++'s own conversion refuses integers that
  // a double cannot hold exactly, which is no reason to refuse a mass.
  const double value =
      node.is_integer() ? static_cast<double>(node.as_integer()->get()) : node.as_floating_point()->get();
  if (!std::isfinite(value)) {
    fail(line_of(node), field, "expected a finite number, got " + number_text(value));
    return std::nullopt;
  }
  if (bound == Bound::kPositive && !(value > 0.0)) {
    fail(line_of(node), field, "must be > 0, got " + number_text(value));
    return std::nullopt;
  }
  if (bound == Bound::kNonNegative && !(value >= 0.0)) {
    fail(line_of(node), field, "must be >= 0, got " + number_text(value));
    return std::nullopt;
  }
  return value;
}

double TomlReader::number(const toml::table& table, std::string_view key, std::string_view path, Bound bound) {
  const toml::node* node = require(table, key, path);
  if (node == nullptr) return 0.0;
  return checked_number(*node, join_key(path, key), bound).value_or(0.0);
}

std::optional<double> TomlReader::optional_number(const toml::table& table, std::string_view key, std::string_view path,
                                                  Bound bound) {
  if (failed() || !table.contains(key)) return std::nullopt;
  return checked_number(*table.get(key), join_key(path, key), bound);
}

std::int64_t TomlReader::integer(const toml::table& table, std::string_view key, std::string_view path) {
  const toml::node* node = require(table, key, path);
  if (node == nullptr) return 0;
  if (!node->is_integer()) {
    fail(line_of(*node), join_key(path, key), "expected an integer, got " + type_name(*node));
    return 0;
  }
  return *node->value<std::int64_t>();
}

int TomlReader::count(const toml::table& table, std::string_view key, std::string_view path) {
  const std::int64_t value = integer(table, key, path);
  if (!failed() && (value < 0 || value > std::numeric_limits<int>::max())) {
    fail(line_of(*table.get(key)), join_key(path, key), "must be a count >= 0, got " + std::to_string(value));
    return 0;
  }
  return static_cast<int>(value);
}

std::string TomlReader::string(const toml::table& table, std::string_view key, std::string_view path) {
  const toml::node* node = require(table, key, path);
  if (node == nullptr) return {};
  if (!node->is_string()) {
    fail(line_of(*node), join_key(path, key), "expected a string, got " + type_name(*node));
    return {};
  }
  return *node->value<std::string>();
}

std::vector<std::string> TomlReader::strings(const toml::table& table, std::string_view key, std::string_view path) {
  std::vector<std::string> result;
  const toml::node* node = require(table, key, path);
  if (node == nullptr) return result;
  const toml::array* array = node->as_array();
  if (array == nullptr || !(array->empty() || array->is_homogeneous(toml::node_type::string))) {
    fail(line_of(*node), join_key(path, key), "expected an array of strings, got " + type_name(*node));
    return result;
  }
  for (const toml::node& element : *array) result.push_back(*element.value<std::string>());
  return result;
}

Eigen::Vector3d TomlReader::vector3(const toml::table& table, std::string_view key, std::string_view path,
                                    Bound bound) {
  Eigen::Vector3d result = Eigen::Vector3d::Zero();
  const toml::node* node = require(table, key, path);
  if (node == nullptr) return result;
  const std::string field = join_key(path, key);
  const toml::array* array = node->as_array();
  if (array == nullptr || array->size() != 3) {
    const std::string got =
        array == nullptr ? type_name(*node) : "an array of " + std::to_string(array->size()) + " elements";
    fail(line_of(*node), field, "expected an array of 3 numbers [x, y, z], got " + got);
    return result;
  }
  for (int i = 0; i < 3; ++i) {
    const toml::node& element = *array->get(static_cast<std::size_t>(i));
    result[i] = checked_number(element, field + "[" + std::to_string(i) + "]", bound).value_or(0.0);
  }
  return result;
}

std::vector<double> TomlReader::number_or_numbers(const toml::node& node, const std::string& field) {
  std::vector<double> result;
  if (failed()) return result;
  if (const toml::array* array = node.as_array()) {
    if (array->empty()) fail(line_of(node), field, "expected a number or a non-empty array of numbers, got []");
    for (std::size_t i = 0; i < array->size() && !failed(); ++i) {
      result.push_back(checked_number(*array->get(i), field + "[" + std::to_string(i) + "]", Bound::kAny).value_or(0));
    }
    return result;
  }
  if (!node.is_number()) {
    fail(line_of(node), field, "expected a number or an array of numbers, got " + type_name(node));
    return result;
  }
  result.push_back(checked_number(node, field, Bound::kAny).value_or(0.0));
  return result;
}

std::string TomlReader::offset_date_time(const toml::table& table, std::string_view key, std::string_view path) {
  const toml::node* node = require(table, key, path);
  if (node == nullptr) return {};
  const toml::date_time* dt = node->is_date_time() ? &node->as_date_time()->get() : nullptr;
  if (dt == nullptr || !dt->offset.has_value()) {
    const std::string got = dt == nullptr ? type_name(*node) : "a local date-time without offset";
    fail(line_of(*node), join_key(path, key), "expected an offset date-time like 2026-11-22T10:15:00Z, got " + got);
    return {};
  }
  return rfc3339(*dt);
}

}  // namespace cdpr::formats
