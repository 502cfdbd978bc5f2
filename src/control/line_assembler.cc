#include "src/control/line_assembler.h"

namespace cdpr::control {

void LineAssembler::feed(std::string_view bytes, const std::function<void(std::string_view)>& on_line,
                         const std::function<void()>& on_overlong) {
  while (!bytes.empty()) {
    const std::size_t newline = bytes.find('\n');
    const std::string_view chunk = bytes.substr(0, newline);
    if (!skipping_) {
      if (partial_.size() + chunk.size() > max_line_bytes_) {
        skipping_ = true;
        partial_.clear();
        on_overlong();
      } else {
        partial_.append(chunk);
      }
    }
    if (newline == std::string_view::npos) return;
    if (!skipping_) on_line(partial_);
    partial_.clear();
    skipping_ = false;
    bytes.remove_prefix(newline + 1);
  }
}

}  // namespace cdpr::control
