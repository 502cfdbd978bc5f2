#include "src/store/run_history.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>

#include "src/store/atomic_file.h"

namespace cdpr::store {
namespace {

constexpr std::string_view kPrefix = "run-";

// Run number of an entry name, or 0 when the name is not one.
int parse_entry_name(const std::string& name) {
  if (name.size() <= kPrefix.size() || name.compare(0, kPrefix.size(), kPrefix) != 0) return 0;
  const std::string digits = name.substr(kPrefix.size());
  if (digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return 0;
  }
  return std::stoi(digits);
}

bool is_temp_name(const std::string& name) { return name.size() > 5 && name.front() == '.' && name.ends_with(".tmp"); }

}  // namespace

std::string RunHistory::entry_name(int run) {
  char name[32];
  std::snprintf(name, sizeof name, "run-%06d", run);
  return name;
}

std::string RunHistory::entry_path(int run) const { return dir_ + "/" + entry_name(run); }

StoreResult<std::vector<int>> RunHistory::runs() const {
  std::vector<int> found;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir_, error)) {
    const int run = parse_entry_name(entry.path().filename().string());
    if (run > 0 && entry.is_directory()) found.push_back(run);
  }
  if (error) return Unexpected{StoreError{"list", dir_, error.value(), ""}};
  std::sort(found.begin(), found.end());
  return found;
}

RunEntry RunHistory::read_entry(int run) const {
  RunEntry entry;
  entry.run = run;
  entry.path = entry_path(run);
  std::error_code error;
  for (const auto& file : std::filesystem::directory_iterator(entry.path, error)) {
    std::error_code size_error;
    const std::uintmax_t size = file.file_size(size_error);
    if (!size_error) entry.bytes += size;
  }
  const std::string log_path = entry.path + "/" + kLogName;
  const auto text = read_file(log_path);
  if (!text) {
    entry.problem = text.error().message();
    return entry;
  }
  auto log = formats::parse_run_log_toml(*text, log_path);
  if (!log) {
    entry.problem = log.error().message();
    return entry;
  }
  entry.valid = true;
  entry.log = std::move(*log);
  return entry;
}

StoreResult<std::vector<RunEntry>> RunHistory::entries() const {
  const auto found = runs();
  if (!found) return Unexpected{found.error()};
  std::vector<RunEntry> list;
  for (auto run = found->rbegin(); run != found->rend(); ++run) list.push_back(read_entry(*run));
  return list;
}

StoreResult<int> RunHistory::next_run() const {
  const auto found = runs();
  if (!found) return Unexpected{found.error()};
  return found->empty() ? 1 : found->back() + 1;
}

StoreResult<Done> RunHistory::create(int run) const {
  const std::string path = entry_path(run);
  if (::mkdir(path.c_str(), 0755) != 0) {
    if (errno == EEXIST) return Done{};
    return Unexpected{errno_error("mkdir", path)};
  }
  return fsync_directory(dir_);
}

StoreResult<Done> RunHistory::write(int run, const std::string& name, std::string_view content) const {
  return write_file_atomically(entry_path(run), name, content, {}, 1);
}

StoreResult<std::vector<int>> RunHistory::recover_interrupted(const std::string& finished, const std::string& why,
                                                              const std::optional<RunProgress>& newest) const {
  const auto found = runs();
  if (!found) return Unexpected{found.error()};
  std::vector<int> changed;
  for (const int run : *found) {
    const std::string path = entry_path(run);
    std::error_code error;
    for (const auto& file : std::filesystem::directory_iterator(path, error)) {
      if (!is_temp_name(file.path().filename().string())) continue;
      if (::unlink(file.path().c_str()) != 0) return Unexpected{errno_error("unlink", file.path().string())};
    }
    RunEntry entry = read_entry(run);
    if (!entry.valid || entry.log.outcome != formats::kRunRunning) continue;
    entry.log.outcome = formats::kRunInterrupted;
    entry.log.reason = why;
    entry.log.finished = finished;
    if (newest && run == found->back()) {
      entry.log.waypoints_planned = std::max(entry.log.waypoints_planned, newest->waypoints_planned);
      entry.log.robot_time_s = std::max(entry.log.robot_time_s, newest->robot_time_s);
    }
    if (auto written = write(run, kLogName, formats::format_run_log_toml(entry.log)); !written) {
      return Unexpected{written.error()};
    }
    changed.push_back(run);
  }
  return changed;
}

StoreResult<Done> RunHistory::remove_entry(int run) const {
  const std::string path = entry_path(run);
  std::error_code error;
  std::vector<std::string> files;
  for (const auto& file : std::filesystem::directory_iterator(path, error)) files.push_back(file.path().string());
  if (error) return Unexpected{StoreError{"list", path, error.value(), ""}};
  for (const std::string& file : files) {
    if (::unlink(file.c_str()) != 0 && errno != ENOENT) return Unexpected{errno_error("unlink", file)};
  }
  if (::rmdir(path.c_str()) != 0 && errno != ENOENT) return Unexpected{errno_error("rmdir", path)};
  return Done{};
}

StoreResult<std::vector<int>> RunHistory::prune(std::uintmax_t budget_bytes,
                                                const std::vector<std::string>& protected_calibrations) const {
  auto list = entries();
  if (!list) return Unexpected{list.error()};
  std::uintmax_t total = 0;
  for (const RunEntry& entry : *list) total += entry.bytes;
  std::vector<int> removed;
  // Oldest first: the list is newest first. The newest entry is the last
  // run, which status and show name; it stays whatever the budget.
  const auto newest = list->empty() ? list->rend() : std::prev(list->rend());
  for (auto entry = list->rbegin(); entry != newest && total > budget_bytes; ++entry) {
    if (entry->valid && entry->log.outcome == formats::kRunRunning) continue;
    const auto calibration = read_file(entry->path + "/" + kCalibrationName);
    if (calibration && std::find(protected_calibrations.begin(), protected_calibrations.end(), *calibration) !=
                           protected_calibrations.end()) {
      continue;
    }
    if (auto gone = remove_entry(entry->run); !gone) return Unexpected{gone.error()};
    total -= entry->bytes;
    removed.push_back(entry->run);
  }
  if (!removed.empty()) {
    if (auto synced = fsync_directory(dir_); !synced) return Unexpected{synced.error()};
  }
  return removed;
}

std::optional<RunEntry> RunHistory::find(int run) const {
  if (run == 0) {
    const auto found = runs();
    if (!found || found->empty()) return std::nullopt;
    run = found->back();
  }
  if (!exists(run)) return std::nullopt;
  return read_entry(run);
}

bool RunHistory::exists(int run) const {
  std::error_code error;
  return run > 0 && std::filesystem::is_directory(entry_path(run), error);
}

std::optional<RunEntry> RunHistory::find_by_calibration(const std::string& calibration_text) const {
  const auto found = runs();
  if (!found) return std::nullopt;
  for (auto run = found->rbegin(); run != found->rend(); ++run) {
    const auto text = read_file(entry_path(*run) + "/" + kCalibrationName);
    if (text && *text == calibration_text) return read_entry(*run);
  }
  return std::nullopt;
}

}  // namespace cdpr::store
