// libFuzzer target for every parser of outside input in src/formats
// (STYLE.md: fuzz targets for every parser). The first byte picks the
// format; the rest is the file. A crash, sanitizer report or escaped
// exception is a bug; refusals are the expected outcome.
//
// Build (not part of the default build; clang and its libFuzzer runtime):
//   clang++ -std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined \
//     -I<build>/include_views/src -I<build>/include_views/solver -I/usr/include/eigen3 \
//     -DTOML_HEADER_ONLY=0 -DTOML_SHARED_LIB=1 tests/src/formats/fuzz/formats_fuzz.cc \
//     src/formats/*.cc -ltomlplusplus -o formats_fuzz
//   ./formats_fuzz -max_total_time=60

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace {

// A refusal must still say why; a value must be what the format promises.
template <class Result>
void check(const Result& result) {
  if (!result.has_value() && result.error().reason.empty()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  const std::string source = "fuzz";
  using namespace cdpr::formats;
  switch (data[0] % 4) {
    case 0: check(parse_robot_toml(text, source)); break;
    case 1: check(parse_calibration_toml(text, source)); break;
    case 2: check(parse_truth_toml(text, source)); break;
    default: {
      const auto samples = parse_samples_csv(text, source, cdpr::kCableCount);
      check(samples);
      // Accepted samples must hold unit quaternions.
      if (samples) {
        for (const cdpr::Sample& s : *samples) {
          if (std::abs(s.world_R_platform.norm() - 1.0) > 1e-12) std::abort();
        }
      }
    }
  }
  return 0;
}
