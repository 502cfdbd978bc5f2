// Fuzz target: waypoints.csv (src/formats/waypoints_csv.h), positions to
// rest at. Promises checked: never a crash; a refusal says why; accepted
// rows hold finite values and non-negative separations, and format to a
// text that parses back to the same waypoints.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "src/formats/waypoints_csv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::formats;
  using cdpr::fuzz::require;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto waypoints = parse_waypoints_csv(text, "fuzz.csv");
  if (!waypoints) {
    require(!waypoints.error().reason.empty(), "a refusal names its reason");
    return 0;
  }
  require(!waypoints->empty(), "an accepted file has rows");
  for (const PlannedWaypoint& w : *waypoints) {
    require(w.position_world.allFinite() && std::isfinite(w.separation_sigma), "accepted values are finite");
    require(w.separation_sigma >= 0.0, "accepted separations are not negative");
  }
  const std::string once = format_waypoints_csv(*waypoints, "fuzz");
  const auto again = parse_waypoints_csv(once, "formatted.csv");
  require(again.has_value() && again->size() == waypoints->size(), "formatted waypoints parse back");
  require(format_waypoints_csv(*again, "fuzz") == once, "format(parse(format(w))) == format(w)");
  return 0;
}
