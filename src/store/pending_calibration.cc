#include "src/store/pending_calibration.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "src/formats/calibration_toml.h"
#include "src/store/atomic_file.h"

namespace cdpr::store {
namespace {

StoreResult<Done> remove_file(const std::string& path) {
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) return Unexpected{errno_error("unlink", path)};
  return Done{};
}

// The state directory holding pending/ (for the fsync that makes its removal durable).
std::string parent_of(const std::string& dir) { return dir.substr(0, dir.rfind('/')); }

}  // namespace

StoreResult<Done> PendingCalibration::keep(const Calibration& calibration, std::string_view samples_csv) const {
  if (::mkdir(dir_.c_str(), 0755) != 0 && errno != EEXIST) return Unexpected{errno_error("mkdir", dir_)};
  // An older calibration.toml must not sit beside the new samples, even for a moment.
  if (auto removed = remove_file(dir_ + "/" + kCalibrationName); !removed) return removed;
  if (auto written = write_file_atomically(dir_, kSamplesName, samples_csv, {}, 1); !written) return written;
  const std::string text = formats::format_calibration_toml(calibration);
  if (auto written = write_file_atomically(dir_, kCalibrationName, text, {}, 1); !written) return written;
  return fsync_directory(parent_of(dir_));
}

bool PendingCalibration::exists() const {
  struct stat info {};
  return ::stat((dir_ + "/" + kCalibrationName).c_str(), &info) == 0;
}

StoreResult<int> PendingCalibration::commit_into(CalibrationStore& store) const {
  const auto text = read_file(dir_ + "/" + kCalibrationName);
  if (!text) return Unexpected{text.error()};
  const auto committed = store.commit_text(*text);
  if (!committed) return committed;
  if (auto removed = remove(); !removed) return Unexpected{removed.error()};
  return committed;
}

StoreResult<Done> PendingCalibration::remove() const {
  for (const char* name : {kCalibrationName, kSamplesName}) {
    if (auto removed = remove_file(dir_ + "/" + name); !removed) return removed;
  }
  // Temp files of a keep() a crash interrupted would keep the directory.
  for (const char* name : {kCalibrationName, kSamplesName}) {
    if (auto removed = remove_file(dir_ + "/" + temp_name(name)); !removed) return removed;
  }
  if (::rmdir(dir_.c_str()) != 0 && errno != ENOENT) return Unexpected{errno_error("rmdir", dir_)};
  return fsync_directory(parent_of(dir_));
}

}  // namespace cdpr::store
