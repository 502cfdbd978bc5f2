// Fuzz target: control-socket commands, the bytes any local client may send
// (src/control/line_assembler.h cuts them into lines, control_request.h
// parses each). Promises checked: never a crash; never more than the limit
// buffered; every line gets either a request or a reason whose JSON error
// response is one line; a rollback names a sequence number >= 1.
// The first byte picks where the stream is split into reads, as a socket
// may deliver it in any pieces.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "src/control/control_request.h"
#include "src/control/control_response.h"
#include "src/control/line_assembler.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::control;
  using cdpr::fuzz::require;
  if (size == 0) return 0;
  const std::size_t piece = 1 + data[0];
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  LineAssembler assembler(kMaxRequestBytes + 2);
  const auto on_line = [](std::string_view line) {
    require(line.size() <= kMaxRequestBytes + 2, "lines handed on are within the limit");
    const auto request = parse_request(line);
    if (!request) {
      const std::string response = format_error_response(request.error());
      require(!request.error().empty(), "a refusal names its reason");
      require(response.find('\n') == response.size() - 1, "the error response is one line");
    } else if (request->kind == RequestKind::kRollback) {
      require(request->seq >= 1, "rollback targets a sequence number >= 1");
    }
  };
  for (std::size_t at = 0; at < bytes.size(); at += piece) {
    assembler.feed(bytes.substr(at, piece), on_line, [] {});
    require(assembler.buffered() <= kMaxRequestBytes + 2, "never more than the limit buffered");
  }
  return 0;
}
