#include "solver/calibration/calibration_stages.h"

namespace cdpr {
namespace {

thread_local StageRecorder* current = nullptr;

}  // namespace

StageRecorder::StageRecorder(std::vector<CalibrationStage>& stages) : stages_(&stages), previous_(current) {
  current = this;
}

StageRecorder::~StageRecorder() { current = previous_; }

void record_stage(const std::string& name, const std::string& outcome, int iterations, double cost, bool fallback) {
  if (!current) return;
  current->iterations_ += iterations;
  if (current->muted_ > 0) return;
  current->stages_->push_back({name, current->depth_, fallback, iterations, cost, outcome});
}

StageScope::StageScope(const std::string& name, bool fallback, Inner inner)
    : recorder_(current && current->muted_ == 0 ? current : nullptr), summary_only_(inner == Inner::kSummaryOnly) {
  if (!recorder_) return;
  index_ = recorder_->stages_->size();
  iterations_at_open_ = recorder_->iterations_;
  recorder_->stages_->push_back(
      {name, recorder_->depth_, fallback, 0, std::numeric_limits<double>::quiet_NaN(), "abandoned"});
  if (summary_only_) ++recorder_->muted_;
  else ++recorder_->depth_;
}

StageScope::~StageScope() {
  if (!recorder_) return;
  if (summary_only_) --recorder_->muted_;
  else --recorder_->depth_;
}

void StageScope::finish(const std::string& outcome) {
  if (!recorder_) return;
  CalibrationStage& stage = (*recorder_->stages_)[index_];
  stage.outcome = outcome;
  stage.iterations = static_cast<int>(recorder_->iterations_ - iterations_at_open_);
}

}  // namespace cdpr
