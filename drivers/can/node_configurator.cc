#include "drivers/can/node_configurator.h"

#include <cstdio>

namespace cdpr::drivers::can {
namespace {

constexpr std::uint32_t kAbortNoObject = 0x06020000;
constexpr std::uint32_t kAbortNoSubindex = 0x06090011;

std::string hex(std::uint32_t value, int digits) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%0*X", digits, static_cast<unsigned>(value));
  return text;
}

}  // namespace

void NodeConfigurator::start(const std::vector<SdoStep>* steps) {
  steps_ = steps;
  next_ = 0;
  reading_back_ = false;
  fell_back_ = false;
  state_ = State::kRunning;
  error_.clear();
  read_values_.assign(steps->size(), 0);
  read_done_.assign(steps->size(), false);
  sdo_.clear();
}

void NodeConfigurator::cancel() {
  if (state_ == State::kRunning) state_ = State::kIdle;
}

std::string NodeConfigurator::name(const SdoStep& step) const {
  return hex(step.index, 4) + ":" + hex(step.subindex, 2) + " (" + step.what + ")";
}

void NodeConfigurator::fail(State state, const std::string& why) {
  state_ = state;
  error_ = "node " + std::to_string(node_id_) + ": " + why;
}

std::optional<CanFrame> NodeConfigurator::poll(hal::TimeUs now_us) {
  if (state_ == State::kRunning && sdo_.state() == SdoClient::State::kDone) {
    const SdoStep& step = (*steps_)[next_];
    const std::uint32_t size_mask = step.size >= 4 ? 0xFFFFFFFFu : (1u << (8 * step.size)) - 1;
    const std::uint32_t mask = size_mask & step.compare_mask;
    bool advance = true;
    switch (step.kind) {
      case SdoStep::Kind::kWrite: break;
      case SdoStep::Kind::kWriteVerify:
        if (!reading_back_) {
          reading_back_ = true;
          advance = false;
          sdo_.clear();
          sdo_.start_upload(step.index, step.subindex, now_us);
        } else if ((sdo_.value() & mask) != (written_ & mask)) {
          fail(State::kFailed, name(step) + " reads " + hex(sdo_.value() & size_mask, 2 * step.size) + ", wrote " +
                                   hex(written_ & size_mask, 2 * step.size));
        }
        break;
      case SdoStep::Kind::kExpect:
        if ((sdo_.value() & mask) != (step.value & mask)) {
          fail(State::kFailed, name(step) + " is " + hex(sdo_.value() & mask, 2 * step.size) + ", expected " +
                                   hex(step.value & mask, 2 * step.size));
        }
        break;
      case SdoStep::Kind::kRead:
        read_values_[next_] = sdo_.value() & size_mask;
        read_done_[next_] = true;
        break;
    }
    if (state_ == State::kRunning && advance) next_step();
  } else if (state_ == State::kRunning && sdo_.state() == SdoClient::State::kFailed) {
    const SdoStep& step = (*steps_)[next_];
    const std::uint32_t code = sdo_.abort_code();
    const bool writing = !reading_back_ && (step.kind == SdoStep::Kind::kWrite || step.kind == SdoStep::Kind::kWriteVerify);
    if (step.optional && (code == kAbortNoObject || code == kAbortNoSubindex)) {
      next_step();  // the device does not have it: nothing to configure there
    } else if (writing && code != 0 && step.has_fallback && !fell_back_) {
      fell_back_ = true;
      written_ = step.fallback;
      sdo_.clear();
      sdo_.start_download_value(step.index, step.subindex, written_, step.size, now_us);
    } else {
      state_ = code == 0 ? State::kNoAnswer : State::kFailed;
      error_ = sdo_.error() + " [" + step.what + "]";
    }
  }
  if (state_ == State::kRunning && sdo_.state() == SdoClient::State::kIdle) {
    const SdoStep& step = (*steps_)[next_];
    if (step.kind == SdoStep::Kind::kWrite || step.kind == SdoStep::Kind::kWriteVerify) {
      written_ = step.value;
      sdo_.start_download_value(step.index, step.subindex, written_, step.size, now_us);
    } else {
      sdo_.start_upload(step.index, step.subindex, now_us);
    }
  }
  return sdo_.poll(now_us);
}

void NodeConfigurator::next_step() {
  sdo_.clear();
  reading_back_ = false;
  fell_back_ = false;
  if (++next_ == steps_->size()) state_ = State::kDone;
}

std::optional<std::uint32_t> NodeConfigurator::read_value(std::uint16_t index, std::uint8_t subindex) const {
  if (steps_ == nullptr) return std::nullopt;
  for (std::size_t i = 0; i < steps_->size(); ++i) {
    const SdoStep& step = (*steps_)[i];
    if (step.kind == SdoStep::Kind::kRead && step.index == index && step.subindex == subindex && read_done_[i]) {
      return read_values_[i];
    }
  }
  return std::nullopt;
}

}  // namespace cdpr::drivers::can
