#pragma once
// Cuts a byte stream (one control-socket connection) into request lines with
// a hard size limit, so a client can never make the daemon buffer without
// bound. A line longer than the limit is reported once as overlong and
// skipped up to its newline. Bytes are never interpreted here.
// Memory: at most `max_line_bytes` buffered; not thread-safe.

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace cdpr::control {

class LineAssembler {
 public:
  explicit LineAssembler(std::size_t max_line_bytes) : max_line_bytes_(max_line_bytes) {}

  // Feeds received bytes; calls on_line(line without "\n") for every complete
  // line, and on_overlong() once per line that exceeded the limit.
  void feed(std::string_view bytes, const std::function<void(std::string_view)>& on_line,
            const std::function<void()>& on_overlong);

  std::size_t buffered() const { return partial_.size(); }

 private:
  std::size_t max_line_bytes_;
  std::string partial_;
  bool skipping_ = false;  // inside an overlong line
};

}  // namespace cdpr::control
