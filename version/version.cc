#include "version/version.h"

#include "version_generated.h"

namespace cdpr::version {

std::string version_text(const std::string& program) {
  const std::string describe = CDPR_GIT_DESCRIBE;
  return program + " " + CDPR_VERSION + (describe.empty() ? "" : " (git " + describe + ")");
}

const char* project_version() { return CDPR_VERSION; }

}  // namespace cdpr::version
