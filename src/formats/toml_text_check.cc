#include "src/formats/toml_text_check.h"

#include <cstddef>

namespace cdpr::formats {
namespace {

enum class Context { kCode, kComment, kBasic, kLiteral, kMultiBasic, kMultiLiteral };

bool starts_with_at(std::string_view text, std::size_t at, std::string_view prefix) {
  return text.substr(at, prefix.size()) == prefix;
}

bool non_ascii(char c) { return static_cast<unsigned char>(c) >= 0x80; }

// After a line-ending backslash in a """ string: the index of the first byte
// that is neither a blank nor a newline (toml++ skips those with its
// whitespace test), or npos when the backslash does not end the line.
std::size_t after_line_ending_backslash(std::string_view text, std::size_t backslash) {
  std::size_t i = backslash + 1;
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r')) ++i;
  if (i >= text.size() || text[i] != '\n') return std::string_view::npos;
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' || text[i] == '\n')) ++i;
  return i;
}

// Whether the escape at `backslash` (in a basic or """ string) puts a
// non-ASCII byte where toml++ tests for whitespace: right after the
// backslash, or first after blanks and newlines that follow it (toml++ reads
// those as a line-ending backslash's whitespace). No valid escape has
// non-ASCII text there. `lines` counts the newlines passed.
bool unsafe_escape(std::string_view text, std::size_t backslash, int& lines) {
  std::size_t i = backslash + 1;
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' || text[i] == '\n')) {
    lines += text[i] == '\n';
    ++i;
  }
  return i < text.size() && non_ascii(text[i]);
}

// Past a closing delimiter of a multi-line string: up to two more quotes
// belong to the content (TOML 1.0: """"" ends with two quotes of text).
std::size_t past_closing(std::string_view text, std::size_t at, char quote) {
  std::size_t end = at + 3;
  for (int extra = 0; extra < 2 && end < text.size() && text[end] == quote; ++extra) ++end;
  return end;
}

// What toml++ ends a bare value at (is_value_terminator, ASCII part).
bool ends_bare_value(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == ']' || c == '}' || c == '#';
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// The end of the bare value (number, boolean, date-time, inf/nan) that
// starts at `at`: toml++ scans it up to a terminator with its whitespace test
// on every character, quotes included (they open no string inside a value),
// and a date followed by one space and a digit continues as date-time.
std::size_t bare_value_end(std::string_view text, std::size_t at) {
  std::size_t end = at;
  for (;;) {
    while (end < text.size() && !ends_bare_value(text[end])) ++end;
    if (end + 1 < text.size() && text[end] == ' ' && is_digit(text[end + 1])) {
      ++end;
      continue;
    }
    return end;
  }
}

}  // namespace

std::optional<FormatError> find_unsafe_non_ascii(std::string_view text, const std::string& source) {
  Context context = Context::kCode;
  int line = 1;
  const auto refuse = [&](int at_line) {
    return FormatError{source, at_line, "",
                       "non-ASCII character outside a string or comment, inside a number, date or "
                       "boolean, or after a backslash in a string (toml++ 3.3.0 mishandles it there)"};
  };
  // Where a value starts (after '=', '[' of an array value, ',' in an
  // array) toml++ reads a bare value through its whitespace test, quotes
  // and all; elsewhere a quote opens a string. Open arrays ('[') and inline
  // tables ('{') of values, innermost last, tell what a ',' is followed by.
  bool value_expected = false;
  std::string open_brackets;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    switch (context) {
      case Context::kCode:
        if (non_ascii(c)) return refuse(line);
        if (value_expected && !ends_bare_value(c) && c != '"' && c != '\'' && c != '[' && c != '{') {
          const std::size_t end = bare_value_end(text, i);
          for (; i < end; ++i) {
            if (non_ascii(text[i])) return refuse(line);
          }
          value_expected = false;
          continue;
        }
        if (c == '=') {
          value_expected = true;
        } else if ((c == '[' || c == '{') && (value_expected || !open_brackets.empty())) {
          open_brackets.push_back(c);
          value_expected = c == '[';
        } else if (c == ',' && !open_brackets.empty()) {
          value_expected = open_brackets.back() == '[';
        } else if ((c == ']' || c == '}') && !open_brackets.empty()) {
          open_brackets.pop_back();
          value_expected = false;
        } else if (c != ' ' && c != '\t' && c != '\r' && c != '\n' && c != '#') {
          value_expected = false;  // a string or key starts: no bare value here
        }
        if (c == '#') {
          context = Context::kComment;
        } else if (starts_with_at(text, i, "\"\"\"")) {
          context = Context::kMultiBasic;
          i += 3;
          continue;
        } else if (starts_with_at(text, i, "'''")) {
          context = Context::kMultiLiteral;
          i += 3;
          continue;
        } else if (c == '"') {
          context = Context::kBasic;
        } else if (c == '\'') {
          context = Context::kLiteral;
        }
        break;
      case Context::kComment:
        if (c == '\n') context = Context::kCode;
        break;
      case Context::kBasic:
        if (int lines = line; c == '\\' && unsafe_escape(text, i, lines)) return refuse(lines);
        if (c == '\\' && i + 1 < text.size() && text[i + 1] != '\n') {
          ++i;  // an escaped character, e.g. \"
        } else if (c == '"' || c == '\n') {
          context = Context::kCode;  // a newline ends it in error; toml++ reports that
        }
        break;
      case Context::kLiteral:
        if (c == '\'' || c == '\n') context = Context::kCode;
        break;
      case Context::kMultiBasic:
        if (int lines = line; c == '\\' && unsafe_escape(text, i, lines)) return refuse(lines);
        if (c == '\\') {
          const std::size_t next = after_line_ending_backslash(text, i);
          if (next == std::string_view::npos) {
            ++i;  // an escaped character
          } else {
            for (std::size_t k = i; k < next; ++k) line += text[k] == '\n';
            if (next < text.size() && non_ascii(text[next])) return refuse(line);
            i = next;
            continue;
          }
        } else if (starts_with_at(text, i, "\"\"\"")) {
          context = Context::kCode;
          i = past_closing(text, i, '"');
          continue;
        }
        break;
      case Context::kMultiLiteral:
        if (starts_with_at(text, i, "'''")) {
          context = Context::kCode;
          i = past_closing(text, i, '\'');
          continue;
        }
        break;
    }
    if (i < text.size() && text[i] == '\n') ++line;
    ++i;
  }
  return std::nullopt;
}

}  // namespace cdpr::formats
