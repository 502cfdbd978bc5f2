#include "sandbox_policy.h"

#include <sys/socket.h>

#include <cerrno>
#include <map>
#include <sstream>

namespace cdpr::sandbox {
namespace {

// The names systemd accepts that a unit of ours could use; an unknown name
// is an error rather than a family silently let through.
const std::map<std::string, int>& family_numbers() {
  static const std::map<std::string, int> numbers = {
      {"AF_UNIX", AF_UNIX},     {"AF_LOCAL", AF_LOCAL},     {"AF_INET", AF_INET},
      {"AF_INET6", AF_INET6},   {"AF_CAN", AF_CAN},         {"AF_NETLINK", AF_NETLINK},
      {"AF_PACKET", AF_PACKET}, {"AF_BLUETOOTH", AF_BLUETOOTH}, {"AF_VSOCK", AF_VSOCK}};
  return numbers;
}

const std::map<std::string, int>& errno_numbers() {
  static const std::map<std::string, int> numbers = {{"EPERM", EPERM},   {"EACCES", EACCES}, {"ENOSYS", ENOSYS},
                                                     {"EINVAL", EINVAL}, {"EUCLEAN", EUCLEAN}};
  return numbers;
}

}  // namespace

bool parse_sandbox_policy(const std::string& text, SandboxPolicy& policy, std::string& error) {
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::string directive, value;
    if (!(words >> directive)) continue;
    const auto fail = [&](const std::string& why) {
      error = "policy line " + std::to_string(number) + ": " + why;
      return false;
    };
    if (directive == "mode") {
      words >> value;
      if (value != "allow" && value != "deny") return fail("mode is 'allow' or 'deny', not '" + value + "'");
      policy.allow_listed = value == "allow";
      policy.filters_syscalls = true;
    } else if (directive == "errno") {
      words >> value;
      if (value == "kill") {
        policy.error_number = 0;
      } else if (const auto found = errno_numbers().find(value); found != errno_numbers().end()) {
        policy.error_number = found->second;
      } else {
        return fail("unknown errno '" + value + "'");
      }
    } else if (directive == "syscall") {
      if (!(words >> value)) return fail("syscall without a name");
      policy.syscalls.push_back(value);
    } else if (directive == "address_families") {
      policy.filters_families = true;
      while (words >> value) {
        if (value.front() == '~') {
          policy.families_denied = true;
          value.erase(0, 1);
          if (value.empty()) continue;
        }
        const auto found = family_numbers().find(value);
        if (found == family_numbers().end()) return fail("unknown address family '" + value + "'");
        policy.families.push_back(found->second);
      }
    } else {
      return fail("unknown directive '" + directive + "'");
    }
  }
  return true;
}

}  // namespace cdpr::sandbox
