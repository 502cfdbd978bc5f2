#pragma once
// A minimal writer of one-line JSON objects for the control socket's
// responses. Strings are escaped (quotes, backslash, control bytes) and
// invalid UTF-8 is replaced by U+FFFD, so any message (paths, errno text)
// yields valid JSON. Non-finite numbers are written as null. No newline is
// ever emitted inside the line.

#include <string>
#include <string_view>

namespace cdpr::control {

class JsonWriter {
 public:
  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  // Next member's key (inside an object).
  JsonWriter& key(std::string_view name);
  JsonWriter& value(std::string_view text);
  JsonWriter& value(const char* text) { return value(std::string_view(text)); }
  JsonWriter& value(const std::string& text) { return value(std::string_view(text)); }
  JsonWriter& value(double number);
  JsonWriter& value(int number);
  JsonWriter& value(bool flag);

  const std::string& text() const { return text_; }

 private:
  void separate();

  std::string text_;
  bool first_in_container_ = true;
};

// `text` as a JSON string literal, with the quotes.
std::string json_string(std::string_view text);

}  // namespace cdpr::control
