#include "src/control/start_waypoints.h"

#include <filesystem>
#include <system_error>

#include "src/formats/waypoints_csv.h"
#include "src/store/kept_run.h"

namespace cdpr::control {
namespace {

// A regular file small enough to read on the loop thread (not a FIFO or a
// device, which could block it); the reason when not.
std::string unreadable_reason(const std::string& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (error && !std::filesystem::exists(status)) {
    // The usual cause: a file the daemon's unit cannot see (systemd/cdpr-calibd.service).
    return path + ": " + error.message() +
           " (the daemon reads it as its own user in its sandbox, which hides /home and /root and has its own "
           "/tmp and /var/tmp)";
  }
  if (error) return path + ": " + error.message();
  if (!std::filesystem::is_regular_file(status)) return path + ": not a regular file";
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  if (error) return path + ": " + error.message();
  if (bytes > kMaxWaypointsFileBytes) {
    return path + ": " + std::to_string(bytes) + " bytes, a waypoints file has at most " +
           std::to_string(kMaxWaypointsFileBytes);
  }
  return {};
}

}  // namespace

Expected<calibration::GivenWaypoints, std::string> load_start_waypoints(const std::string& path, int run,
                                                                        const std::string& history_dir,
                                                                        const Robot& robot) {
  if (const std::string why = unreadable_reason(path); !why.empty()) return Unexpected{why};
  const auto waypoints = formats::read_waypoints_csv(path);
  if (!waypoints) return Unexpected{waypoints.error().message()};
  calibration::GivenWaypoints given;
  given.source = path;
  for (const formats::PlannedWaypoint& w : *waypoints) given.positions_world.push_back(w.position_world);
  if (run > 0) {
    auto earlier = store::read_kept_run(store::RunHistory(history_dir), run, robot.name, "appended to");
    if (!earlier) return Unexpected{earlier.error()};
    given.earlier_samples = std::move(earlier->samples);
    given.earlier_run = run;
  }
  return given;
}

}  // namespace cdpr::control
