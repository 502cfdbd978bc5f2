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

// Past a closing delimiter of a multi-line string: up to two more quotes
// belong to the content (TOML 1.0: """"" ends with two quotes of text).
std::size_t past_closing(std::string_view text, std::size_t at, char quote) {
  std::size_t end = at + 3;
  for (int extra = 0; extra < 2 && end < text.size() && text[end] == quote; ++extra) ++end;
  return end;
}

}  // namespace

std::optional<FormatError> find_unsafe_non_ascii(std::string_view text, const std::string& source) {
  Context context = Context::kCode;
  int line = 1;
  const auto refuse = [&](int at_line) {
    return FormatError{source, at_line, "",
                       "non-ASCII character outside a string or comment (or first on the line after a "
                       "line-ending backslash in a \"\"\" string)"};
  };
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    switch (context) {
      case Context::kCode:
        if (non_ascii(c)) return refuse(line);
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
