// unit-sandbox-exec POLICY COMMAND [ARG...]: runs COMMAND under the seccomp
// filters of a systemd unit (policy written by resolve_unit_sandbox.sh;
// seccomp_filters.h says what is applied). The tests run it inside
// bubblewrap for the rest of the unit's sandbox (user namespace, read-only
// file system, no capabilities). execve() is on every allow list
// (@default), so COMMAND starts under the filters.
// Exit 127 when the policy cannot be read or the filters not installed.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "sandbox_policy.h"
#include "seccomp_filters.h"

namespace {

int fail(const std::string& why) {
  std::fprintf(stderr, "unit-sandbox-exec: %s\n", why.c_str());
  return 127;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return fail("usage: unit-sandbox-exec POLICY COMMAND [ARG...]");
  std::ifstream file(argv[1]);
  if (!file) return fail(std::string("cannot read policy ") + argv[1]);
  std::stringstream text;
  text << file.rdbuf();
  cdpr::sandbox::SandboxPolicy policy;
  std::string error;
  if (!cdpr::sandbox::parse_sandbox_policy(text.str(), policy, error)) return fail(std::string(argv[1]) + ": " + error);
  if (error = cdpr::sandbox::install_unit_filters(policy); !error.empty()) return fail(error);
  execvp(argv[2], argv + 2);
  return fail(std::string("execvp ") + argv[2] + ": " + std::strerror(errno));
}
