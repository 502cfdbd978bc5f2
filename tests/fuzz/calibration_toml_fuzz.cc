// Fuzz target: calibration.toml and truth.toml (src/formats/calibration_toml.h),
// which share the TOML reader and the [effects] table. calibration.toml is
// what the daemon reloads from its state directory at start, so a damaged
// file must be refused, never crash it. Promises checked: never a crash; a
// refusal says why; an accepted file formats (format aborts on a `created`
// that is no RFC 3339 date-time) to a text that parses back to the same text.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "src/formats/calibration_toml.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::formats;
  using cdpr::fuzz::require;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (const auto calibration = parse_calibration_toml(text, "fuzz.toml"); calibration) {
    const std::string once = format_calibration_toml(*calibration);
    const auto again = parse_calibration_toml(once, "formatted.toml");
    require(again.has_value(), "a formatted calibration parses");
    require(format_calibration_toml(*again) == once, "calibration format is a fixpoint after one round");
  } else {
    require(!calibration.error().reason.empty(), "a calibration refusal names its reason");
  }
  if (const auto truth = parse_truth_toml(text, "fuzz.toml"); truth) {
    const std::string once = format_truth_toml(*truth);
    const auto again = parse_truth_toml(once, "formatted.toml");
    require(again.has_value(), "a formatted truth parses");
    require(format_truth_toml(*again) == once, "truth format is a fixpoint after one round");
  } else {
    require(!truth.error().reason.empty(), "a truth refusal names its reason");
  }
  return 0;
}
