#pragma once
// A whole file as a string (empty when it cannot be read), for tests that
// look into what a program wrote. One definition, so that test sources
// compiled in one unity batch share it.

#include <fstream>
#include <sstream>
#include <string>

namespace cdpr::test {

inline std::string read_text(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace cdpr::test
