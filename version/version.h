#pragma once
// What every program prints for --version.

#include <string>

namespace cdpr::version {

// "<program> <version>", plus " (git <describe>)" when built from a git
// checkout, e.g. "calibctl 0.1.0 (git 8ef3ca0-dirty)".
std::string version_text(const std::string& program);

// The project version alone (CMake project(VERSION)), e.g. "0.1.0".
const char* project_version();

}  // namespace cdpr::version
