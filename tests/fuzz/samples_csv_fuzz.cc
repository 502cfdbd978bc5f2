// Fuzz target: samples.csv (src/formats/samples_csv.h), the measured static
// poses. Promises checked: never a crash; a refusal says why; accepted rows
// hold finite values and unit quaternions, and format to a text that parses
// back to the same samples.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "src/formats/samples_csv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::formats;
  using cdpr::fuzz::require;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto samples = parse_samples_csv(text, "fuzz.csv", cdpr::kCableCount);
  if (!samples) {
    require(!samples.error().reason.empty(), "a refusal names its reason");
    return 0;
  }
  require(!samples->empty(), "an accepted file has data rows");
  for (const cdpr::Sample& s : *samples) {
    require(std::abs(s.world_R_platform.norm() - 1.0) <= 1e-12, "accepted quaternions are unit");
    require(s.position_world.allFinite() && std::isfinite(s.force_n), "accepted values are finite");
    for (double e : s.encoder_m) require(std::isfinite(e), "accepted encoder readings are finite");
  }
  const std::string once = format_samples_csv(*samples);
  const auto again = parse_samples_csv(once, "formatted.csv", cdpr::kCableCount);
  require(again.has_value() && again->size() == samples->size(), "formatted samples parse back");
  require(format_samples_csv(*again) == once, "format(parse(format(samples))) == format(samples)");
  return 0;
}
