#include "drivers/can/node_configurator.h"

#include <cstdio>

namespace cdpr::drivers::can {
namespace {

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
    const std::uint32_t mask = step.size >= 4 ? 0xFFFFFFFFu : (1u << (8 * step.size)) - 1;
    bool advance = true;
    switch (step.kind) {
      case SdoStep::Kind::kWrite: break;
      case SdoStep::Kind::kWriteVerify:
        if (!reading_back_) {
          reading_back_ = true;
          advance = false;
          sdo_.clear();
          sdo_.start_upload(step.index, step.subindex, now_us);
        } else if ((sdo_.value() & mask) != (step.value & mask)) {
          fail(State::kFailed, name(step) + " reads " + hex(sdo_.value() & mask, 2 * step.size) + ", wrote " +
                                   hex(step.value & mask, 2 * step.size));
        }
        break;
      case SdoStep::Kind::kExpect:
        if ((sdo_.value() & mask) != (step.value & mask)) {
          fail(State::kFailed, name(step) + " is " + hex(sdo_.value() & mask, 2 * step.size) + ", expected " +
                                   hex(step.value & mask, 2 * step.size));
        }
        break;
      case SdoStep::Kind::kRead:
        read_values_[next_] = sdo_.value() & mask;
        read_done_[next_] = true;
        break;
    }
    if (state_ == State::kRunning && advance) {
      sdo_.clear();
      reading_back_ = false;
      if (++next_ == steps_->size()) state_ = State::kDone;
    }
  } else if (state_ == State::kRunning && sdo_.state() == SdoClient::State::kFailed) {
    const bool timeout = sdo_.abort_code() == 0;
    state_ = timeout ? State::kNoAnswer : State::kFailed;
    error_ = sdo_.error() + " [" + (*steps_)[next_].what + "]";
  }
  if (state_ == State::kRunning && sdo_.state() == SdoClient::State::kIdle) {
    const SdoStep& step = (*steps_)[next_];
    if (step.kind == SdoStep::Kind::kWrite || step.kind == SdoStep::Kind::kWriteVerify) {
      sdo_.start_download_value(step.index, step.subindex, step.value, step.size, now_us);
    } else {
      sdo_.start_upload(step.index, step.subindex, now_us);
    }
  }
  return sdo_.poll(now_us);
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
