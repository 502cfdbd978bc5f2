#pragma once
// The seccomp side of a systemd unit's sandbox, installed in the calling
// process as systemd's executor does just before execve(): no new
// privileges, then the address-family filter on socket()'s first argument
// (RestrictAddressFamilies=; refused families get EAFNOSUPPORT, as under
// systemd) and the system-call filter (SystemCallFilter=,
// SystemCallErrorNumber=; SystemCallArchitectures=native: libseccomp's
// filter admits the native architecture only). Irreversible.

#include <string>

#include "sandbox_policy.h"

namespace cdpr::sandbox {

// Empty on success, else what failed.
std::string install_unit_filters(const SandboxPolicy& policy);

}  // namespace cdpr::sandbox
