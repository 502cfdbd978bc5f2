// libFuzzer target for the control socket's input path (STYLE.md: fuzz
// targets for every parser of outside input): the bytes of one connection go
// through the LineAssembler and every line through parse_request; the JSON
// error response of a refusal must be a single line. A crash, sanitizer
// report or escaped exception is a bug; refusals are the expected outcome.
//
// Build (not part of the default build; clang and its libFuzzer runtime):
//   clang++ -std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined \
//     -I<build>/include_views/src -I<build>/include_views/solver -I<build>/include_views/hal \
//     -I/usr/include/eigen3 tests/src/control/fuzz/control_fuzz.cc \
//     src/control/control_request.cc src/control/line_assembler.cc src/control/json_writer.cc \
//     src/formats/number_text.cc -o control_fuzz
//   ./control_fuzz -max_total_time=60

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "src/control/control_request.h"
#include "src/control/json_writer.h"
#include "src/control/line_assembler.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::control;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  LineAssembler assembler(kMaxRequestBytes + 2);
  const auto on_line = [](std::string_view line) {
    const auto request = parse_request(line);
    if (!request) {
      const std::string response = json_string(request.error());
      if (request.error().empty() || response.find('\n') != std::string::npos) std::abort();
    } else if (request->kind == RequestKind::kRollback && request->seq < 1) {
      std::abort();
    }
  };
  // Feed in two reads split at a data-dependent point, as a socket would.
  const std::size_t split = size == 0 ? 0 : data[0] % (size + 1);
  assembler.feed(bytes.substr(0, split), on_line, [] {});
  assembler.feed(bytes.substr(split), on_line, [] {});
  if (assembler.buffered() > kMaxRequestBytes + 2) std::abort();
  return 0;
}
