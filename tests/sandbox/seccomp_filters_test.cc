// The seccomp half of the unit's sandbox: the policy resolved from
// systemd/cdpr-calibd.service refuses what the unit refuses, with the
// unit's errno, and lets through what the daemon needs.

#include "seccomp_filters.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace cdpr::sandbox {
namespace {

SandboxPolicy unit_policy() {
  std::ifstream file(CDPR_BINARY_DIR "/tests/sandbox/cdpr-calibd.sandbox");
  std::stringstream text;
  text << file.rdbuf();
  SandboxPolicy policy;
  std::string error;
  EXPECT_TRUE(parse_sandbox_policy(text.str(), policy, error)) << error;
  return policy;
}

// Runs `probe` in a child under `policy`'s filters; its exit status (0: as
// expected, 100: the filters could not be installed).
template <typename Probe>
int exit_status_under(const SandboxPolicy& policy, Probe probe) {
  const pid_t child = fork();
  if (child == 0) {
    if (!install_unit_filters(policy).empty()) _exit(100);
    _exit(probe());
  }
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 200 + WTERMSIG(status);
}

TEST(UnitSeccompFilters, ThePolicyIsTheUnitsAllowListWithEpermAndItsAddressFamilies) {
  const SandboxPolicy policy = unit_policy();
  EXPECT_TRUE(policy.filters_syscalls);
  EXPECT_TRUE(policy.allow_listed);
  EXPECT_EQ(policy.error_number, EPERM);
  EXPECT_GT(policy.syscalls.size(), 100u);
  EXPECT_TRUE(policy.filters_families);
  EXPECT_EQ(policy.families, (std::vector<int>{AF_UNIX, AF_CAN, AF_INET, AF_INET6}));
}

TEST(UnitSeccompFilters, ChownAndSetpriorityGetEpermOtherFamiliesEafnosupport) {
  const SandboxPolicy policy = unit_policy();
  char path[] = "/tmp/cdpr-seccomp-XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  // chown (@chown in ~@privileged), even to nothing, is refused with EPERM
  EXPECT_EQ(exit_status_under(policy, [&] { return chown(path, -1, -1) == -1 && errno == EPERM ? 0 : 1; }), 0);
  // setpriority (~@resources) too, even to the current niceness
  EXPECT_EQ(exit_status_under(policy, [] {
              const int nice = getpriority(PRIO_PROCESS, 0);
              return setpriority(PRIO_PROCESS, 0, nice) == -1 && errno == EPERM ? 0 : 1;
            }),
            0);
  // a netlink or packet socket is refused as systemd refuses it; Unix and IP sockets are not
  EXPECT_EQ(exit_status_under(policy, [] {
              const bool netlink = socket(AF_NETLINK, SOCK_RAW, 0) == -1 && errno == EAFNOSUPPORT;
              const bool packet = socket(AF_PACKET, SOCK_RAW, 0) == -1 && errno == EAFNOSUPPORT;
              const bool beyond = socket(AF_MAX + 5, SOCK_STREAM, 0) == -1 && errno == EAFNOSUPPORT;
              return netlink && packet && beyond ? 0 : 1;
            }),
            0);
  EXPECT_EQ(exit_status_under(policy, [] {
              return socket(AF_UNIX, SOCK_STREAM, 0) >= 0 && socket(AF_INET, SOCK_STREAM, 0) >= 0 ? 0 : 1;
            }),
            0);
  // AND without the filters the same chown works (so the refusal above is the filter's)
  EXPECT_EQ(chown(path, -1, -1), 0);
  unlink(path);
}

TEST(SandboxPolicy, AnUnknownDirectiveOrFamilyIsAnErrorNamingItsLine) {
  SandboxPolicy policy;
  std::string error;
  EXPECT_FALSE(parse_sandbox_policy("mode allow\nsyscals read\n", policy, error));
  EXPECT_NE(error.find("line 2"), std::string::npos) << error;
  EXPECT_FALSE(parse_sandbox_policy("address_families AF_UNIX AF_FOO\n", policy, error));
  EXPECT_NE(error.find("AF_FOO"), std::string::npos) << error;
  EXPECT_FALSE(parse_sandbox_policy("errno EWHAT\n", policy, error));
}

}  // namespace
}  // namespace cdpr::sandbox
