#pragma once
// Shared helpers of the store tests: a fresh temporary state directory and
// distinguishable calibrations.

#include <stdlib.h>

#include <filesystem>
#include <string>

#include "solver/model/calibration.h"
#include "src/store/atomic_file.h"

namespace cdpr::store::test {

// A new empty directory under the test temp dir, removed at destruction.
class TempStateDir {
 public:
  TempStateDir() {
    std::string pattern = std::filesystem::temp_directory_path().string() + "/cdpr-store-XXXXXX";
    path_ = ::mkdtemp(pattern.data());
  }
  ~TempStateDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// A valid calibration whose bytes differ with `version`.
inline Calibration calibration_version(int version) {
  Calibration calibration;
  calibration.created = "2026-11-22T10:15:00Z";
  calibration.robot = "large";
  calibration.samples = 30 + version;
  for (int i = 0; i < 4; ++i) {
    WinchCalibration& winch = calibration.winches.emplace_back();
    winch.anchor_world = Eigen::Vector3d(i * 10.0, 0.01 * version, 50.0);
    winch.anchor_sigma = Eigen::Vector3d(0.02, 0.02, 0.05);
    winch.offset_m = 3.0 + 0.001 * version;
    winch.offset_sigma_m = 0.03;
  }
  calibration.fit = {1.2e6, 30.0 + version, 14, 0.009, 4.8};
  return calibration;
}

inline std::string file_bytes(const std::string& path) {
  const auto bytes = read_file(path);
  return bytes ? *bytes : std::string("<missing: ") + bytes.error().message() + ">";
}

}  // namespace cdpr::store::test
