// Fuzz target: an EDS/DCF file (CiA 306) as an operator may name in
// [winches.drive] / [winches.encoder] eds, parsed with libinih
// (drivers/can/eds.h), and the drive's and encoder's configuration fitted
// to it.
//
// Input: the file's text.
// Promises checked: never a crash; a refusal always says why, naming the
// file; an accepted file's PDO counts are within 0..512; a fit either
// refuses with a reason or keeps every step it was given but optional ones.

#include <cstddef>
#include <cstdint>
#include <string>

#include "drivers/can/device_configuration.h"
#include "drivers/can/eds.h"
#include "fuzz_check.h"

using cdpr::fuzz::require;
using namespace cdpr::drivers::can;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (text.find('\0') != std::string::npos) return 0;  // a C string to libinih
  std::string error;
  const std::optional<Eds> eds = Eds::parse(text, "fuzz.eds", error);
  if (!eds) {
    require(error.starts_with("fuzz.eds"), "a refusal names the file");
    return 0;
  }
  require(eds->rpdo_count() >= 0 && eds->rpdo_count() <= 512 && eds->tpdo_count() <= 512, "PDO counts bounded");
  for (std::vector<SdoStep> steps : {encoder_configuration(11, EncoderDescription{}),
                                     drive_configuration(1, 127, 1e-5, DriveUnits{1e5, "counts/s"}, DriveDescription{})}) {
    std::size_t needed = 0;
    for (const SdoStep& s : steps) needed += s.optional ? 0 : 1;
    const std::string why = fit_to_eds(*eds, steps);
    require(!why.empty() || steps.size() >= needed, "a fit keeps every needed step or refuses");
    require(why.empty() || why.starts_with("fuzz.eds"), "a refusal names the file");
  }
  return 0;
}
