#pragma once
// The rows behind cdpr-calibd.toml (daemon_config.cc holds the tables). A
// Table is one TOML table of the file ([winches.drive], say) bound to the
// struct its values go to; each row names one key once, with its type,
// unit, range and why that range, default and meaning. The rows read and
// range-check the keys (every refusal with file, line and dotted key), give
// the daemon its defaults, and list the keys for docs/configuration.md and
// for the test that holds the shipped example to the tables.
//
// A row's `field` is a data member pointer of the table's struct, or a
// generic lambda `[](auto& t) -> auto& { return t.map.decimals; }` for a
// member further down.

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "hal/clock.h"
#include "src/daemon/daemon_config.h"
#include "src/formats/toml_reader.h"

namespace cdpr::daemon {

// An integer key's allowed values, lo..hi; hex: shown as 0x... (masks, CANopen identities).
struct IntRange {
  std::int64_t lo = 0;
  std::int64_t hi = 0;
  bool hex = false;
};

// A number key's allowed values: lo..hi with either end open; `nonzero`
// leaves out 0 (a factor whose sign matters).
struct NumberRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;
  bool nonzero = false;
};
inline constexpr NumberRange kAnyNumber{};
inline constexpr NumberRange kPositive{0.0, std::numeric_limits<double>::infinity(), true};
inline constexpr NumberRange kNonNegative{0.0, std::numeric_limits<double>::infinity()};
inline constexpr NumberRange kNonZero{-std::numeric_limits<double>::infinity(),
                                      std::numeric_limits<double>::infinity(), false, false, true};

// The unit a duration key is written in (its name ends in _ms or _s); held in microseconds.
enum class TimeUnit { kMilliseconds, kSeconds };
inline constexpr TimeUnit kMs = TimeUnit::kMilliseconds;

// A duration key's allowed values, lo..hi (lo > 0) in the key's unit;
// `whole`: a whole number of it (a CANopen object holds whole milliseconds).
struct DurationRange {
  double lo = 0.0;
  double hi = 0.0;
  bool whole = false;
};

// An integer default, or one counted up per table of an array ([[winches.winch]]: node 1, 2, 3, 4).
struct IntDefault {
  IntDefault(std::int64_t value) : first(value) {}  // NOLINT: a plain number is the usual default
  static IntDefault per_cable(std::int64_t first) {
    IntDefault d(first);
    d.step = 1;
    return d;
  }
  std::int64_t at(int index) const { return first + step * index; }
  std::int64_t first = 0;
  std::int64_t step = 0;
};

// The key a row is reading: its checks, and the refusal naming it.
class KeyContext {
 public:
  KeyContext(formats::TomlReader& reader, const toml::table& table, std::string_view path, std::string_view key)
      : reader_(reader), table_(table), path_(path), key_(key) {}

  // The value, or nullopt after failing with what is wrong and what is expected.
  std::optional<std::int64_t> integer(const IntRange& range) const;
  std::optional<double> number(const NumberRange& range) const;
  std::optional<std::string> string() const;  // not empty
  std::optional<std::vector<std::string>> strings() const;
  std::optional<bool> boolean() const;
  void fail(const std::string& reason) const;

 private:
  formats::TomlReader& reader_;
  const toml::table& table_;
  std::string_view path_;
  std::string_view key_;
};

std::string range_text(const IntRange& range);
std::string range_text(const NumberRange& range);
std::string range_text(const DurationRange& range);
std::string integer_text(std::int64_t value, bool hex);
std::string number_text(double value);
// The message of a value outside its range: "must be in 1..127, got 300".
std::string out_of_range(const std::string& range, const std::string& value);

template <class T>
struct Row {
  KeyInfo info;
  std::function<void(T&, int index)> set_default;      // index: of the table in an array of tables
  std::function<void(const KeyContext&, T&)> read;     // the key is there
  std::function<std::string(const T&)> show;           // the value as TOML text
  std::function<std::string(const T&)> refuse;         // after read: "" or what is wrong beyond the range
  std::function<void(T&)> then;                        // after read and set_default (a preset's map)
  std::function<std::string(const T&)> unsafe;         // after read: "" or how the value defeats a safety function
};

template <class T>
class Table {
 public:
  explicit Table(std::string path) : path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  const std::vector<Row<T>>& rows() const { return rows_; }

  template <class Field>
  Table& integer(std::string_view name, Field field, IntDefault fallback, IntRange range, std::string_view unit,
                 std::string_view meaning) {
    using V = Value<Field>;
    Row<T>& row = add(name, "integer", unit, range_text(range), meaning);
    row.set_default = [field, fallback](T& t, int index) { std::invoke(field, t) = static_cast<V>(fallback.at(index)); };
    row.read = [field, range](const KeyContext& key, T& t) {
      if (const auto value = key.integer(range)) std::invoke(field, t) = static_cast<V>(*value);
    };
    row.show = [field, range](const T& t) {
      return integer_text(static_cast<std::int64_t>(std::invoke(field, t)), range.hex);
    };
    return *this;
  }

  template <class Field>
  Table& number(std::string_view name, Field field, double fallback, NumberRange range, std::string_view unit,
                std::string_view meaning) {
    Row<T>& row = add(name, "number", unit, range_text(range), meaning);
    row.set_default = [field, fallback](T& t, int) { std::invoke(field, t) = fallback; };
    row.read = [field, range](const KeyContext& key, T& t) {
      if (const auto value = key.number(range)) std::invoke(field, t) = *value;
    };
    row.show = [field](const T& t) { return number_text(std::invoke(field, t)); };
    return *this;
  }

  // A hal::TimeUs written in the unit the key's name gives.
  template <class Field>
  Table& duration(std::string_view name, Field field, double fallback, TimeUnit unit, DurationRange range,
                  std::string_view meaning) {
    const double us_per_unit = unit == TimeUnit::kMilliseconds ? 1e3 : 1e6;
    Row<T>& row = add(name, "number", unit == TimeUnit::kMilliseconds ? "ms" : "s", range_text(range), meaning);
    row.set_default = [field, fallback, us_per_unit](T& t, int) { std::invoke(field, t) = microseconds(fallback, us_per_unit); };
    row.read = [field, us_per_unit, range](const KeyContext& key, T& t) {
      const auto value = key.number({range.lo, range.hi});
      if (!value) return;
      if (range.whole && *value != std::floor(*value)) {
        return key.fail("must be a whole number, got " + number_text(*value));
      }
      std::invoke(field, t) = microseconds(*value, us_per_unit);
    };
    row.show = [field, us_per_unit](const T& t) {
      return number_text(static_cast<double>(std::invoke(field, t)) / us_per_unit);
    };
    return *this;
  }

  // An array of strings; empty by default.
  template <class Field>
  Table& strings(std::string_view name, Field field, std::string_view meaning) {
    Row<T>& row = add(name, "array of strings", "", "", meaning);
    row.set_default = [field](T& t, int) { std::invoke(field, t).clear(); };
    row.read = [field](const KeyContext& key, T& t) {
      if (auto value = key.strings()) std::invoke(field, t) = std::move(*value);
    };
    row.show = [field](const T& t) {
      std::string text;
      for (const std::string& item : std::invoke(field, t)) text += (text.empty() ? "" : ", ") + quoted(item);
      return "[" + text + "]";
    };
    return *this;
  }

  // Not empty when given; fallback "": absent unless given.
  template <class Field>
  Table& string(std::string_view name, Field field, std::string fallback, std::string_view meaning) {
    Row<T>& row = add(name, "string", "", "", meaning);
    row.set_default = [field, fallback](T& t, int) { std::invoke(field, t) = fallback; };
    row.read = [field](const KeyContext& key, T& t) {
      if (auto value = key.string()) std::invoke(field, t) = std::move(*value);
    };
    row.show = [field](const T& t) { return quoted(std::invoke(field, t)); };
    return *this;
  }

  template <class Field>
  Table& boolean(std::string_view name, Field field, bool fallback, std::string_view meaning) {
    Row<T>& row = add(name, "boolean", "", "", meaning);
    row.set_default = [field, fallback](T& t, int) { std::invoke(field, t) = fallback; };
    row.read = [field](const KeyContext& key, T& t) {
      if (const auto value = key.boolean()) std::invoke(field, t) = *value;
    };
    row.show = [field](const T& t) { return std::invoke(field, t) ? "true" : "false"; };
    return *this;
  }

  // One of the named values; the field holds the value of the name given.
  template <class Field, class V>
  Table& choice(std::string_view name, Field field, std::vector<std::pair<std::string, V>> choices, V fallback,
                std::string_view meaning) {
    std::string names;
    for (const auto& [choice_name, value] : choices) names += (names.empty() ? "" : ", ") + quoted(choice_name);
    Row<T>& row = add(name, names, "", "", meaning);
    row.set_default = [field, fallback](T& t, int) { std::invoke(field, t) = fallback; };
    row.read = [field, choices, names](const KeyContext& key, T& t) {
      const auto value = key.string();
      if (!value) return;
      for (const auto& [choice_name, choice_value] : choices) {
        if (choice_name == *value) {
          std::invoke(field, t) = choice_value;
          return;
        }
      }
      key.fail(quoted(*value) + " is not one of " + names);
    };
    row.show = [field, choices](const T& t) {
      for (const auto& [choice_name, choice_value] : choices) {
        if (choice_value == std::invoke(field, t)) return quoted(choice_name);
      }
      return std::string("?");
    };
    return *this;
  }

  // A key without a default (robot, the device endpoints): refused when absent.
  Table& required() {
    rows_.back().info.required = true;
    return *this;
  }
  // A check of the last row's value beyond its type and range; `range`
  // replaces the range the docs show.
  Table& refusing(std::string range, std::function<std::string(const T&)> refuse) {
    rows_.back().info.range = std::move(range);
    rows_.back().refuse = std::move(refuse);
    return *this;
  }
  // Why the last row's range is what it is: the safety function or the
  // physical limit behind it (docs/configuration.md shows it).
  Table& why(std::string_view reason) {
    rows_.back().info.range_reason = std::string(reason);
    return *this;
  }
  // Values of the last row's key, inside its range, that defeat a safety
  // function: refused unless unsafe_ok lists the key. `unsafe` returns ""
  // or what the value gives up; `when` says in the docs which values these are.
  Table& unsafe_unless_acknowledged(std::string when, std::function<std::string(const T&)> unsafe) {
    rows_.back().info.unsafe_when = std::move(when);
    rows_.back().unsafe = std::move(unsafe);
    return *this;
  }
  // What setting the last row's key does besides setting its field.
  Table& then(std::function<void(T&)> effect) {
    rows_.back().then = std::move(effect);
    return *this;
  }

  void set_defaults(T& target, int index = 0) const {
    for (const Row<T>& row : rows_) {
      row.set_default(target, index);
      if (row.then) row.then(target);
    }
  }

  // Reads the keys of `table` (its unknown keys already refused) into
  // `target`; a missing required key is left to the caller (it is named
  // after the values given are checked), an unsafe value is noted in `unsafe`.
  void read(formats::TomlReader& reader, const toml::table& table, std::string_view path, T& target,
            KeyLines& key_lines, std::vector<UnsafeValue>& unsafe) const {
    for (const Row<T>& row : rows_) {
      if (reader.failed()) return;
      const toml::node* node = table.get(row.info.name);
      if (node == nullptr) continue;
      const std::string dotted = formats::join_key(path, row.info.name);
      key_lines[dotted] = formats::TomlReader::line_of(*node);
      const KeyContext key(reader, table, path, row.info.name);
      row.read(key, target);
      if (reader.failed()) return;
      if (row.refuse) {
        if (const std::string reason = row.refuse(target); !reason.empty()) return key.fail(reason);
      }
      if (row.unsafe) {
        if (std::string reason = row.unsafe(target); !reason.empty()) {
          unsafe.push_back({dotted, formats::TomlReader::line_of(*node), std::move(reason)});
        }
      }
      if (row.then) row.then(target);
    }
  }

 private:
  template <class Field>
  using Value = std::remove_cvref_t<std::invoke_result_t<Field, T&>>;

  static hal::TimeUs microseconds(double value, double us_per_unit) {
    return static_cast<hal::TimeUs>(std::llround(value * us_per_unit));
  }
  static std::string quoted(const std::string& text) { return "\"" + text + "\""; }

  Row<T>& add(std::string_view name, std::string type, std::string_view unit, std::string range,
              std::string_view meaning) {
    Row<T>& row = rows_.emplace_back();
    row.info.table = path_;
    row.info.name = std::string(name);
    row.info.type = std::move(type);
    row.info.unit = std::string(unit);
    row.info.range = std::move(range);
    row.info.meaning = std::string(meaning);
    return row;
  }

  std::string path_;
  std::vector<Row<T>> rows_;
};

// Refuses a key of `table` that is not one of `names` (its keys and
// sub-tables), naming its line and the nearest allowed name.
void refuse_unknown_keys(formats::TomlReader& reader, const toml::table& table, std::string_view path,
                         const std::vector<std::string_view>& names);

}  // namespace cdpr::daemon
