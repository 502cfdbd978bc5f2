#pragma once
// The system-call part of a systemd unit's sandbox, as written by
// resolve_unit_sandbox.sh: one directive per line, '#' starts a comment.
//   mode allow|deny             allow: only the listed calls run, the rest
//                               get `errno`; deny: the listed calls get it
//   errno EPERM|...|kill        SystemCallErrorNumber= (kill: SIGSYS)
//   syscall <name>              one per line
//   address_families AF_UNIX .. RestrictAddressFamilies= (a leading "~"
//                               denies the listed ones instead)

#include <string>
#include <vector>

namespace cdpr::sandbox {

struct SandboxPolicy {
  bool allow_listed = true;    // mode allow
  bool filters_syscalls = false;
  int error_number = 0;        // 0: kill the process
  std::vector<std::string> syscalls;
  bool filters_families = false;
  bool families_denied = false;  // "~": the listed families are the refused ones
  std::vector<int> families;
};

// Parses a policy; on failure returns false with `error` naming the line.
bool parse_sandbox_policy(const std::string& text, SandboxPolicy& policy, std::string& error);

}  // namespace cdpr::sandbox
