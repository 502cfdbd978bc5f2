#pragma once
// Records CalibrationResult::stages. calibrate()'s fallbacks nest up to four
// deep through helpers whose own results are mostly discarded (a restart
// that did not help, a start that lost), so the record is kept beside the
// call rather than in each intermediate result: calibrate() opens a
// StageRecorder, every stage below records into it, and a StageScope nests
// the stages run inside it one level deeper (or, for a search of many fits,
// keeps only its own summary). Without a recorder open (calibrate_once()
// called directly) recording does nothing. One recorder per thread, as
// calibrate() runs on one.

#include <limits>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"

namespace cdpr {

class StageRecorder {
 public:
  // Records into `stages` until destroyed; a recorder opened while another
  // is (a calibrate() inside a calibrate()) records apart from it.
  explicit StageRecorder(std::vector<CalibrationStage>& stages);
  ~StageRecorder();
  StageRecorder(const StageRecorder&) = delete;
  StageRecorder& operator=(const StageRecorder&) = delete;

 private:
  friend void record_stage(const std::string&, const std::string&, int, double, bool);
  friend class StageScope;
  std::vector<CalibrationStage>* stages_;
  StageRecorder* previous_;
  int depth_ = 0;
  int muted_ = 0;           // open summary-only scopes
  long iterations_ = 0;     // of every stage recorded, muted or not
};

// A stage at the current depth.
void record_stage(const std::string& name, const std::string& outcome, int iterations = 0,
                  double cost = std::numeric_limits<double>::quiet_NaN(), bool fallback = false);

// A stage holding others: recorded where it opens, its outcome given by
// finish() (or "abandoned" when it closes without), its iterations those
// of every stage run while it was open; those stages go one level deeper,
// or, Inner::kSummaryOnly, nowhere (a search of many fits).
class StageScope {
 public:
  enum class Inner { kNested, kSummaryOnly };
  StageScope(const std::string& name, bool fallback, Inner inner = Inner::kNested);
  ~StageScope();
  StageScope(const StageScope&) = delete;
  StageScope& operator=(const StageScope&) = delete;
  void finish(const std::string& outcome);

 private:
  StageRecorder* recorder_;
  std::size_t index_ = 0;
  long iterations_at_open_ = 0;
  bool summary_only_ = false;
};

}  // namespace cdpr
