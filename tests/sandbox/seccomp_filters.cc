#include "seccomp_filters.h"

#include <seccomp.h>
#include <sys/prctl.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>

namespace cdpr::sandbox {
namespace {

// Address families are small integers below AF_MAX; every other value of
// socket()'s first argument is refused too.
constexpr int kFamilyLimit = AF_MAX;

std::string install_syscall_filter(const SandboxPolicy& policy) {
  const std::uint32_t refuse = policy.error_number == 0 ? SCMP_ACT_KILL_PROCESS : SCMP_ACT_ERRNO(policy.error_number);
  scmp_filter_ctx filter = seccomp_init(policy.allow_listed ? refuse : SCMP_ACT_ALLOW);
  if (filter == nullptr) return "seccomp_init failed";
  const std::uint32_t listed_action = policy.allow_listed ? SCMP_ACT_ALLOW : refuse;
  std::string error;
  for (const std::string& name : policy.syscalls) {
    const int number = seccomp_syscall_resolve_name(name.c_str());
    if (number == __NR_SCMP_ERROR) continue;  // not on this architecture (systemd skips these too)
    if (const int rc = seccomp_rule_add(filter, listed_action, number, 0); rc != 0) {
      error = "seccomp_rule_add(" + name + "): " + std::strerror(-rc);
      break;
    }
  }
  if (error.empty()) {
    if (const int rc = seccomp_load(filter); rc != 0) error = std::string("seccomp_load: ") + std::strerror(-rc);
  }
  seccomp_release(filter);
  return error;
}

// A second, stacked filter: the kernel applies the stricter answer of both.
std::string install_family_filter(const SandboxPolicy& policy) {
  scmp_filter_ctx filter = seccomp_init(SCMP_ACT_ALLOW);
  if (filter == nullptr) return "seccomp_init failed";
  const std::uint32_t refuse = SCMP_ACT_ERRNO(EAFNOSUPPORT);
  std::string error;
  for (int family = 0; family < kFamilyLimit && error.empty(); ++family) {
    const bool listed = std::find(policy.families.begin(), policy.families.end(), family) != policy.families.end();
    if (listed != policy.families_denied) continue;
    if (const int rc = seccomp_rule_add(filter, refuse, SCMP_SYS(socket), 1, SCMP_A0(SCMP_CMP_EQ, static_cast<scmp_datum_t>(family))); rc != 0) {
      error = "seccomp_rule_add(socket, " + std::to_string(family) + "): " + std::strerror(-rc);
    }
  }
  if (error.empty()) {
    const int rc = seccomp_rule_add(filter, refuse, SCMP_SYS(socket), 1, SCMP_A0(SCMP_CMP_GE, static_cast<scmp_datum_t>(kFamilyLimit)));
    if (rc != 0) error = std::string("seccomp_rule_add(socket, >= AF_MAX): ") + std::strerror(-rc);
  }
  if (error.empty()) {
    if (const int rc = seccomp_load(filter); rc != 0) error = std::string("seccomp_load: ") + std::strerror(-rc);
  }
  seccomp_release(filter);
  return error;
}

}  // namespace

std::string install_unit_filters(const SandboxPolicy& policy) {
  // NoNewPrivileges=yes (also what lets an unprivileged process load a filter).
  if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) return std::string("PR_SET_NO_NEW_PRIVS: ") + std::strerror(errno);
  // The call filter last: a unit may refuse seccomp() itself.
  if (policy.filters_families) {
    if (std::string failed = install_family_filter(policy); !failed.empty()) return failed;
  }
  if (policy.filters_syscalls) return install_syscall_filter(policy);
  return "";
}

}  // namespace cdpr::sandbox
