#include "src/formats/toml_writer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include <toml++/toml.h>

#include "src/formats/number_text.h"

namespace cdpr::formats {
namespace {

constexpr std::size_t kCommentColumn = 35;  // docs/FORMATS.md aligns comments here

template <class T, class Format>
std::string toml_array(const std::vector<T>& values, Format format) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i == 0 ? "" : ", ") + format(values[i]);
  return text + "]";
}

}  // namespace

std::string toml_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  std::string result = shortest_text(value);
  if (result.find_first_of(".e") == std::string::npos) result += ".0";
  return result;
}

std::string toml_vector3(const Eigen::Vector3d& value) {
  return "[" + toml_number(value.x()) + ", " + toml_number(value.y()) + ", " + toml_number(value.z()) + "]";
}

std::string toml_numbers(const std::vector<double>& values) { return toml_array(values, toml_number); }

std::string toml_string(std::string_view value) {
  std::string text = "\"";
  for (const char c : value) {
    switch (c) {
      case '"': text += "\\\""; break;
      case '\\': text += "\\\\"; break;
      case '\n': text += "\\n"; break;
      case '\t': text += "\\t"; break;
      case '\r': text += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
          char escape[8];
          std::snprintf(escape, sizeof escape, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          text += escape;
        } else {
          text += c;
        }
    }
  }
  return text + "\"";
}

std::string toml_strings(const std::vector<std::string>& values) {
  return toml_array(values, [](const std::string& s) { return toml_string(s); });
}

std::string toml_key(std::string_view key) {
  const auto bare_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; };
  const bool bare = !key.empty() && std::all_of(key.begin(), key.end(), bare_char);
  return bare ? std::string(key) : toml_string(key);
}

void append_line(std::string& out, std::string_view assignment, std::string_view comment) {
  out += assignment;
  if (!comment.empty()) {
    out.append(assignment.size() < kCommentColumn ? kCommentColumn - assignment.size() : 1, ' ');
    out += "# ";
    out += comment;
  }
  out += '\n';
}

bool is_offset_date_time(std::string_view text) {
  const std::string document = "t = " + std::string(text);
  try {
    const toml::table table = toml::parse(document);
    const toml::date_time* dt = table["t"].as_date_time() ? &table["t"].as_date_time()->get() : nullptr;
    return dt != nullptr && dt->offset.has_value() && table.size() == 1;
  } catch (const toml::parse_error&) {
    return false;
  }
}

}  // namespace cdpr::formats
