#pragma once
// Substring check the tests use on messages and file contents. One
// definition, so that test sources compiled in one unity batch share it.

#include <string>

namespace cdpr::test {

inline bool contains(const std::string& text, const std::string& words) { return text.find(words) != std::string::npos; }

}  // namespace cdpr::test
