#include "src/daemon/config_table.h"

#include <algorithm>
#include <cstdio>

#include "src/formats/nearest_name.h"
#include "src/formats/number_text.h"

namespace cdpr::daemon {

std::string integer_text(std::int64_t value, bool hex) {
  if (!hex || value <= 0) return std::to_string(value);
  char text[24];
  std::snprintf(text, sizeof text, value > 0xFFFF ? "0x%08llX" : "0x%04llX", static_cast<unsigned long long>(value));
  return text;
}

std::string number_text(double value) { return formats::shortest_text(value); }

std::string range_text(const IntRange& range) {
  return integer_text(range.lo, range.hex) + ".." + integer_text(range.hi, range.hex);
}

std::string range_text(const NumberRange& range) {
  const bool low = std::isfinite(range.lo);
  const bool high = std::isfinite(range.hi);
  const std::string nonzero = range.nonzero ? "!= 0" : "";
  if (low && high) {
    return std::string(range.lo_open ? "(" : "[") + number_text(range.lo) + ", " + number_text(range.hi) +
           (range.hi_open ? ")" : "]") + (range.nonzero ? ", " + nonzero : "");
  }
  if (range.nonzero) return nonzero;
  if (low) return (range.lo_open ? "> " : ">= ") + number_text(range.lo);
  if (high) return (range.hi_open ? "< " : "<= ") + number_text(range.hi);
  return "";
}

std::string range_text(const DurationRange& range) {
  return range_text(NumberRange{range.lo, range.hi}) + (range.whole ? ", whole" : "");
}

std::string out_of_range(const std::string& range, const std::string& value) {
  const bool interval = range.find("..") != std::string::npos || range.starts_with("[") || range.starts_with("(");
  return "must be " + std::string(interval ? "in " : "") + range + ", got " + value;
}

std::optional<std::int64_t> KeyContext::integer(const IntRange& range) const {
  const std::int64_t value = reader_.integer(table_, key_, path_);
  if (reader_.failed()) return std::nullopt;
  if (value < range.lo || value > range.hi) {
    fail(out_of_range(range_text(range), integer_text(value, range.hex)));
    return std::nullopt;
  }
  return value;
}

std::optional<double> KeyContext::number(const NumberRange& range) const {
  const std::optional<double> value = reader_.optional_number(table_, key_, path_, formats::Bound::kAny);
  if (!value) return std::nullopt;
  const bool inside = (range.lo_open ? *value > range.lo : *value >= range.lo) &&
                      (range.hi_open ? *value < range.hi : *value <= range.hi) && !(range.nonzero && *value == 0.0);
  if (!inside) {
    fail(out_of_range(range_text(range), number_text(*value)));
    return std::nullopt;
  }
  return value;
}

std::optional<std::string> KeyContext::string() const {
  std::string value = reader_.string(table_, key_, path_);
  if (reader_.failed()) return std::nullopt;
  if (value.empty()) {
    fail("must not be empty");
    return std::nullopt;
  }
  return value;
}

std::optional<std::vector<std::string>> KeyContext::strings() const {
  std::vector<std::string> values = reader_.strings(table_, key_, path_);
  if (reader_.failed()) return std::nullopt;
  return values;
}

std::optional<bool> KeyContext::boolean() const {
  const toml::node* node = table_.get(key_);
  if (node == nullptr || !node->is_boolean()) {
    fail("expected true or false");
    return std::nullopt;
  }
  return node->as_boolean()->get();
}

void KeyContext::fail(const std::string& reason) const {
  const toml::node* node = table_.get(key_);
  reader_.fail(formats::TomlReader::line_of(node ? *node : table_), formats::join_key(path_, key_), reason);
}

void refuse_unknown_keys(formats::TomlReader& reader, const toml::table& table, std::string_view path,
                         const std::vector<std::string_view>& names) {
  for (auto&& [key, node] : table) {
    const std::string_view name = key.str();
    if (std::find(names.begin(), names.end(), name) != names.end()) continue;
    std::string reason = node.is_table() || node.is_array_of_tables() ? "unknown table" : "unknown key";
    if (const auto nearest = formats::nearest_name(name, names)) {
      reason += " (did you mean '" + std::string(*nearest) + "'?)";
    } else {
      std::string list;
      for (const std::string_view allowed : names) list += (list.empty() ? "" : ", ") + std::string(allowed);
      reason += " (allowed here: " + list + ")";
    }
    reader.fail(static_cast<int>(key.source().begin.line), formats::join_key(path, name), reason);
  }
}

}  // namespace cdpr::daemon
