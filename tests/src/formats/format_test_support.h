#pragma once
// Shared pieces of the data-format tests: spoil one value of a valid example
// and check that the error names the right line, key or column, and reason.

#include <algorithm>
#include <cctype>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "src/formats/format_error.h"

namespace cdpr::formats::test {

// `text` with the first occurrence of `from` replaced by `to`.
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "example has no '" << from << "'";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// 1-based line where `needle` (after any leading newlines) starts in `text`.
inline int line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  if (at == std::string::npos) return -1;
  const auto leading = static_cast<int>(std::min(needle.find_first_not_of('\n'), needle.size()));
  return 1 + leading + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

inline constexpr int kLineOfEdit = -1;

// One spoilt example: `from` replaced by `to` must be refused naming `field`,
// with `reason_part` in the reason, at `line` (kLineOfEdit: where `to` is;
// 0: no line, the whole file).
struct BadEdit {
  const char* what;
  const char* from;
  const char* to;
  const char* field;
  const char* reason_part;
  int line = kLineOfEdit;
};

// GoogleTest prints a failing case by its description, not its bytes.
inline void PrintTo(const BadEdit& bad, std::ostream* out) { *out << bad.what; }

inline void expect_refusal(const FormatError& error, const BadEdit& bad, const std::string& text) {
  EXPECT_EQ(error.field, bad.field) << bad.what;
  EXPECT_NE(error.reason.find(bad.reason_part), std::string::npos) << bad.what << ": " << error.reason;
  const bool locatable = bad.line != kLineOfEdit || *bad.to != '\0';
  if (locatable) {
    EXPECT_EQ(error.line, bad.line == kLineOfEdit ? line_of(text, bad.to) : bad.line) << bad.what;
  }
}

// Test-case names for INSTANTIATE_TEST_SUITE_P, from `what`.
inline std::string case_name(const testing::TestParamInfo<BadEdit>& info) {
  std::string name = info.param.what;
  for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

}  // namespace cdpr::formats::test
