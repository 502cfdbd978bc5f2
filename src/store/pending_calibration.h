#pragma once
// A validated fit whose commit failed (full disk, read-only or broken
// history directory), kept so that the run's work is not lost:
//
//   <state_dir>/pending/calibration.toml   the fit, exactly as it would have been committed
//   <state_dir>/pending/samples.csv        the samples it was fitted to (docs/FORMATS.md)
//
// Each file is written atomically (atomic_file.h), samples first, so a
// calibration.toml there always has its samples beside it. Once the cause is
// fixed, commit_into() commits it like a fresh fit (the store's atomicity
// holds) and removes pending/. A newer failed commit replaces an older one.
//
// Stateless apart from the paths; not thread-safe (the daemon's loop thread).

#include <string>
#include <string_view>

#include "solver/model/calibration.h"
#include "src/store/calibration_store.h"
#include "src/store/store_error.h"

namespace cdpr::store {

class PendingCalibration {
 public:
  static constexpr const char* kDirName = "pending";
  static constexpr const char* kCalibrationName = "calibration.toml";
  static constexpr const char* kSamplesName = "samples.csv";

  explicit PendingCalibration(const std::string& state_dir) : dir_(state_dir + "/" + kDirName) {}

  [[nodiscard]] StoreResult<Done> keep(const Calibration& calibration, std::string_view samples_csv) const;
  // True when pending/calibration.toml exists.
  bool exists() const;
  // Commits pending/calibration.toml into `store`, then removes pending/
  // (the samples too: the committed file says how many there were). Returns
  // the new sequence number. Errors: nothing pending (operation "read",
  // ENOENT), the store's commit error (pending/ is kept), or the removal's.
  [[nodiscard]] StoreResult<int> commit_into(CalibrationStore& store) const;
  // Removes pending/ and its files (absent is fine), durably.
  [[nodiscard]] StoreResult<Done> remove() const;

  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
};

}  // namespace cdpr::store
