#pragma once
// A small reader for the control socket's one-line JSON responses
// (src/control/control_response.h): objects, arrays, strings with escapes,
// numbers, true/false/null. Enough for calibctl; not a general JSON library
// (no duplicate-key checks, \u escapes outside the BMP are kept as two
// surrogate code points encoded separately).

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cdpr::calibctl {

class JsonValue {
 public:
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject };

  Kind kind() const { return kind_; }
  bool is_null() const { return kind_ == Kind::kNull; }

  // Accessors return a default for the wrong kind, so rendering a response
  // from a newer daemon with a changed field shows a blank, never crashes.
  bool boolean() const { return kind_ == Kind::kBool && bool_; }
  double number(double fallback = 0.0) const { return kind_ == Kind::kNumber ? number_ : fallback; }
  int integer() const { return static_cast<int>(number()); }
  const std::string& string() const { return string_; }
  const std::vector<JsonValue>& array() const { return array_; }
  // Member `key` of an object; a null value when absent.
  const JsonValue& operator[](std::string_view key) const;

  // One JSON text (surrounding white space allowed); the error names the
  // byte offset.
  static std::optional<JsonValue> parse(std::string_view text, std::string* error = nullptr);

 private:
  friend class JsonParser;
  Kind kind_ = Kind::kNull;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<JsonValue> array_;
  std::map<std::string, JsonValue, std::less<>> object_;
};

}  // namespace cdpr::calibctl
