// Fuzz target: robot.toml (src/formats/robot_toml.h), the robot description
// a user hands the daemon and the tools. Promises checked: never a crash or
// an escaped exception; a refusal says why; an accepted robot has four
// winches, positive masses and sigmas, and formats to a text that parses
// back to the same text (format is a fixpoint after one round).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "src/formats/robot_toml.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::formats;
  using cdpr::fuzz::require;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto robot = parse_robot_toml(text, "fuzz.toml");
  if (!robot) {
    require(!robot.error().reason.empty(), "a refusal names its reason");
    return 0;
  }
  require(robot->cable_count() == cdpr::kCableCount, "accepted robots have kCableCount winches");
  require(robot->platform_mass_kg > 0 && std::isfinite(robot->platform_mass_kg), "mass > 0 and finite");
  require(robot->reference_cable >= 0 && robot->reference_cable < robot->cable_count(), "reference is a cable");
  const std::string once = format_robot_toml(*robot);
  const auto again = parse_robot_toml(once, "formatted.toml");
  require(again.has_value(), "a formatted robot parses");
  require(format_robot_toml(*again) == once, "format(parse(format(robot))) == format(robot)");
  return 0;
}
