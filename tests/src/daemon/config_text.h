#pragma once
// A cdpr-calibd.toml for the parser's tests: the case's own text with the
// device endpoints (required keys) it leaves out added after its lines (at
// the end of its own table, or as tables of their own at the end), so that
// a case's line numbers are its own and its mistake the only one.

#include <algorithm>
#include <string>
#include <utility>

namespace cdpr::daemon::test {

inline std::string with_endpoints(const std::string& text) {
  std::string out = text;
  const std::pair<const char*, const char*> endpoints[] = {
      {"winches", "socketcan:can0"}, {"load_cell", "rtu:/dev/ttyUSB0"}, {"pose", "tcp:127.0.0.1:5600"}};
  for (const auto& [table, endpoint] : endpoints) {
    const std::string header = "[" + std::string(table) + "]\n";
    const std::string line = "endpoint = \"" + std::string(endpoint) + "\"\n";
    const std::size_t at = out.find(header);
    if (at == std::string::npos) {
      out += header + line;
      continue;
    }
    // At the end of the case's own table: the lines of its keys stay as they are.
    const std::size_t next = std::min(out.find("\n[", at + header.size() - 1), out.size() - 1) + 1;
    if (out.substr(at, next - at).find("\nendpoint = ") == std::string::npos) out.insert(next, line);
  }
  return out;
}

inline std::string config_text(const std::string& text) { return with_endpoints("robot = \"r\"\n" + text); }

}  // namespace cdpr::daemon::test
