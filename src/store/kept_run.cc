#include "src/store/kept_run.h"

#include <filesystem>
#include <optional>
#include <system_error>
#include <utility>

#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::store {

Expected<KeptRun, std::string> read_kept_run(const RunHistory& history, int run, const std::string& robot_name,
                                             const std::string& use) {
  std::optional<RunEntry> entry = history.find(run);
  if (!entry) {
    if (run == 0) return Unexpected{"no run is kept in " + history.dir()};
    return Unexpected{"no such run: " + RunHistory::entry_name(run) + " is not in " + history.dir()};
  }
  const std::string name = RunHistory::entry_name(entry->run);
  if (!entry->valid) return Unexpected{name + " cannot be " + use + ": its log is unreadable: " + entry->problem};
  const std::string samples_path = entry->path + "/" + RunHistory::kSamplesName;
  std::error_code error;
  if (!std::filesystem::exists(samples_path, error)) {
    return Unexpected{name + " kept no samples (it ended before its first waypoint)"};
  }
  auto robot = formats::read_robot_toml(entry->path + "/" + RunHistory::kRobotName);
  if (!robot) return Unexpected{name + " cannot be " + use + ": " + robot.error().message()};
  if (robot->name != robot_name) {
    return Unexpected{name + " was measured on robot '" + robot->name + "', this daemon calibrates '" + robot_name +
                      "'"};
  }
  auto samples = formats::read_samples_csv(samples_path, robot->cable_count());
  if (!samples) return Unexpected{name + " cannot be " + use + ": " + samples.error().message()};
  if (samples->empty()) return Unexpected{name + " has no samples: it cannot be " + use};
  return KeptRun{std::move(*entry), std::move(*robot), std::move(*samples)};
}

}  // namespace cdpr::store
