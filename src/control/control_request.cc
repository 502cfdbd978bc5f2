#include "src/control/control_request.h"

#include <array>
#include <vector>

namespace cdpr::control {
namespace {

struct Command {
  const char* name;
  RequestKind kind;
  bool takes_seq;
};

constexpr std::array<Command, 9> kCommands = {{
    {"start", RequestKind::kStart, false},
    {"abort", RequestKind::kAbort, false},
    {"status", RequestKind::kStatus, false},
    {"show", RequestKind::kShow, false},
    {"history", RequestKind::kHistory, false},
    {"rollback", RequestKind::kRollback, true},
    {"commit", RequestKind::kCommit, false},
    {"reset-faults", RequestKind::kResetFaults, false},
    {"refit", RequestKind::kRefit, false},
}};

constexpr const char* kExpected =
    "expected start [waypoints <path> [<run>]], abort, status, show, history, rollback <seq>, commit, reset-faults or "
    "refit <terms> [<run>]";

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// The word as it may be echoed back: printable ASCII only, shortened.
std::string quoted(std::string_view word) {
  std::string text = "'";
  for (std::size_t k = 0; k < word.size() && k < 32; ++k) {
    const unsigned char c = static_cast<unsigned char>(word[k]);
    text += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (word.size() > 32) text += "...";
  return text + "'";
}

// 1..999999999 from its digits; 0 when `digits` is not such a number.
int positive_number(std::string_view digits) {
  if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string_view::npos) return 0;
  int number = 0;
  for (const char c : digits) number = number * 10 + (c - '0');
  return number;
}

// A run as 7 or as its entry name run-000007; 0 when it is neither.
int run_number(std::string_view run) {
  if (run.starts_with("run-")) run.remove_prefix(4);
  return positive_number(run);
}

// `refit <terms> [<run>]`.
Expected<Request, std::string> parse_refit(const std::vector<std::string_view>& words) {
  if (words.size() < 2 || words.size() > 3) {
    return Unexpected{std::string("refit takes one or two arguments: <terms> [<run>]")};
  }
  Request request{RequestKind::kRefit, 0, std::string(words[1]), 0, {}};
  if (words.size() == 3) {
    request.run = run_number(words[2]);
    if (request.run < 1) return Unexpected{"run " + quoted(words[2]) + " is not a run number (7 or run-000007)"};
  }
  return request;
}

// `start` or `start waypoints <path> [<run>]`. The path is absolute: the
// daemon's working directory is not the client's.
Expected<Request, std::string> parse_start(const std::vector<std::string_view>& words) {
  Request request{RequestKind::kStart, 0, {}, 0, {}};
  if (words.size() == 1) return request;
  if (words[1] != "waypoints" || words.size() < 3 || words.size() > 4) {
    return Unexpected{std::string("start takes no argument or: waypoints <path> [<run>]")};
  }
  if (!words[2].starts_with('/')) return Unexpected{"waypoints path " + quoted(words[2]) + " is not absolute"};
  request.waypoints_path = std::string(words[2]);
  if (words.size() == 4) {
    request.run = run_number(words[3]);
    if (request.run < 1) return Unexpected{"run " + quoted(words[3]) + " is not a run number (7 or run-000007)"};
  }
  return request;
}

}  // namespace

const char* to_string(RequestKind kind) {
  for (const Command& command : kCommands) {
    if (command.kind == kind) return command.name;
  }
  return "unknown";
}

Expected<Request, std::string> parse_request(std::string_view line) {
  if (!line.empty() && line.back() == '\n') line.remove_suffix(1);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (line.size() > kMaxRequestBytes) {
    return Unexpected{"request longer than " + std::to_string(kMaxRequestBytes) + " bytes"};
  }
  for (const char c : line) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (!is_blank(c) && (u < 0x20 || u >= 0x7f)) return Unexpected{std::string("request contains a non-ASCII or control byte")};
  }
  std::vector<std::string_view> words;
  std::size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && is_blank(line[k])) ++k;
    const std::size_t start = k;
    while (k < line.size() && !is_blank(line[k])) ++k;
    if (k > start) words.push_back(line.substr(start, k - start));
  }
  if (words.empty()) return Unexpected{std::string("empty request (") + kExpected + ")"};

  if (words[0] == "refit") return parse_refit(words);
  if (words[0] == "start") return parse_start(words);
  for (const Command& command : kCommands) {
    if (words[0] != command.name) continue;
    if (!command.takes_seq) {
      if (words.size() != 1) return Unexpected{std::string(command.name) + " takes no argument"};
      return Request{command.kind, 0, {}, 0, {}};
    }
    if (words.size() != 2) return Unexpected{std::string(command.name) + " takes one argument: <seq>"};
    const int seq = positive_number(words[1]);
    if (seq < 1) return Unexpected{"sequence number " + quoted(words[1]) + " is not an integer in 1..999999999"};
    return Request{command.kind, seq, {}, 0, {}};
  }
  return Unexpected{"unknown command " + quoted(words[0]) + " (" + kExpected + ")"};
}

}  // namespace cdpr::control
