#include "src/store/calibration_store.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>

#include "src/formats/calibration_toml.h"

namespace cdpr::store {
namespace {

constexpr const char* kHistoryPrefix = "calibration-";
constexpr const char* kHistorySuffix = ".toml";

// Sequence number of a history file name, or 0 when the name is not one.
int parse_history_name(const std::string& name) {
  const std::string prefix = kHistoryPrefix;
  const std::string suffix = kHistorySuffix;
  if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return 0;
  }
  const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  if (digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return 0;
  }
  return std::stoi(digits);
}

StoreResult<Done> make_directory(const std::string& path) {
  if (::mkdir(path.c_str(), 0755) != 0 && errno != EEXIST) return Unexpected{errno_error("mkdir", path)};
  return Done{};
}

// Temp files of interrupted writes: ".<name>.tmp".
StoreResult<Done> remove_stale_temps(const std::string& dir) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 5 && name.front() == '.' && name.ends_with(".tmp")) {
      if (::unlink(entry.path().c_str()) != 0) return Unexpected{errno_error("unlink", entry.path().string())};
    }
  }
  if (error) return Unexpected{StoreError{"list", dir, error.value(), ""}};
  return Done{};
}

StoreResult<Calibration> parse_text(const std::string& text, const std::string& path) {
  auto parsed = formats::parse_calibration_toml(text, path);
  if (!parsed) return Unexpected{StoreError{"parse", path, 0, parsed.error().message()}};
  return std::move(parsed.value());
}

}  // namespace

CalibrationStore::CalibrationStore(StoreOptions options) : options_(std::move(options)) {
  options_.history_depth = std::max(options_.history_depth, 0);
}

std::string CalibrationStore::current_path() const { return options_.state_dir + "/" + kCurrentName; }
std::string CalibrationStore::history_dir() const { return options_.state_dir + "/" + kHistoryDir; }

std::string CalibrationStore::history_name(int seq) {
  char name[64];
  std::snprintf(name, sizeof name, "%s%06d%s", kHistoryPrefix, seq, kHistorySuffix);
  return name;
}

StoreResult<Done> CalibrationStore::open() {
  for (const std::string& dir : {options_.state_dir, history_dir()}) {
    if (auto made = make_directory(dir); !made) return made;
    if (auto removed = remove_stale_temps(dir); !removed) return removed;
  }
  return Done{};
}

StoreResult<std::vector<int>> CalibrationStore::history_seqs() const {
  std::vector<int> seqs;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(history_dir(), error)) {
    const int seq = parse_history_name(entry.path().filename().string());
    if (seq > 0) seqs.push_back(seq);
  }
  if (error) return Unexpected{StoreError{"list", history_dir(), error.value(), ""}};
  std::sort(seqs.rbegin(), seqs.rend());
  return seqs;
}

StoreResult<std::optional<CurrentCalibration>> CalibrationStore::load_current() const {
  auto text = read_file(current_path());
  if (!text) {
    if (text.error().errno_value == ENOENT) return std::optional<CurrentCalibration>{};
    return Unexpected{text.error()};
  }
  auto calibration = parse_text(*text, current_path());
  if (!calibration) return Unexpected{calibration.error()};
  CurrentCalibration current{std::move(*calibration), std::move(*text), 0};
  const auto seqs = history_seqs();
  if (!seqs) return Unexpected{seqs.error()};
  for (const int seq : *seqs) {
    const auto entry = read_file(history_dir() + "/" + history_name(seq));
    if (entry && *entry == current.text) {
      current.seq = seq;
      break;
    }
  }
  return std::optional<CurrentCalibration>{std::move(current)};
}

StoreResult<std::optional<CurrentCalibration>> CalibrationStore::newest_readable_version() const {
  const auto seqs = history_seqs();
  if (!seqs) return Unexpected{seqs.error()};
  for (const int seq : *seqs) {
    const std::string path = history_dir() + "/" + history_name(seq);
    auto text = read_file(path);
    if (!text) continue;
    auto calibration = parse_text(*text, path);
    if (!calibration) continue;
    return std::optional<CurrentCalibration>{CurrentCalibration{std::move(*calibration), std::move(*text), seq}};
  }
  return std::optional<CurrentCalibration>{};
}

StoreResult<int> CalibrationStore::commit(const Calibration& calibration) {
  return commit_text(formats::format_calibration_toml(calibration));
}

StoreResult<int> CalibrationStore::commit_text(const std::string& text) {
  // Refuse before touching anything: a file that does not parse back would
  // leave the robot without a usable calibration.
  if (auto parsed = parse_text(text, current_path()); !parsed) return Unexpected{parsed.error()};
  const auto seqs = history_seqs();
  if (!seqs) return Unexpected{seqs.error()};
  const int seq = seqs->empty() ? 1 : seqs->front() + 1;

  if (auto written = write_file_atomically(history_dir(), history_name(seq), text, crash_hook_, 1); !written) {
    return Unexpected{written.error()};
  }
  if (auto written = write_file_atomically(options_.state_dir, kCurrentName, text, crash_hook_,
                                           1 + kAtomicWriteSteps);
      !written) {
    return Unexpected{written.error()};
  }
  if (auto pruned = prune(text, 1 + 2 * kAtomicWriteSteps); !pruned) return Unexpected{pruned.error()};
  return seq;
}

StoreResult<Done> CalibrationStore::prune(const std::string& current_text, int first_step) {
  const auto seqs = history_seqs();
  if (!seqs) return Unexpected{seqs.error()};
  const std::size_t keep = static_cast<std::size_t>(options_.history_depth) + 1;
  for (std::size_t k = keep; k < seqs->size(); ++k) {
    const std::string path = history_dir() + "/" + history_name((*seqs)[k]);
    const auto text = read_file(path);
    if (text && *text == current_text) continue;  // a rolled-back current stays recoverable
    if (::unlink(path.c_str()) != 0) return Unexpected{errno_error("unlink", path)};
  }
  if (crash_requested(crash_hook_, first_step)) return Unexpected{simulated_crash(history_dir(), first_step)};
  if (auto synced = fsync_directory(history_dir()); !synced) return synced;
  if (crash_requested(crash_hook_, first_step + 1)) return Unexpected{simulated_crash(history_dir(), first_step + 1)};
  return Done{};
}

StoreResult<int> CalibrationStore::rollback(int seq) {
  const std::string path = history_dir() + "/" + history_name(seq);
  const auto text = read_file(path);
  if (!text) return Unexpected{text.error()};
  if (auto parsed = parse_text(*text, path); !parsed) return Unexpected{parsed.error()};
  if (auto written = write_file_atomically(options_.state_dir, kCurrentName, *text, crash_hook_, 1); !written) {
    return Unexpected{written.error()};
  }
  return seq;
}

StoreResult<Done> CalibrationStore::probe_writable() const {
  for (const std::string& dir : {options_.state_dir, history_dir()}) {
    if (auto probed = store::probe_writable(dir); !probed) return probed;
  }
  return Done{};
}

std::vector<std::string> CalibrationStore::problems() const {
  std::vector<std::string> found;
  if (const auto current = load_current(); !current) {
    found.push_back("the current calibration is unreadable (" + current.error().message() +
                    "): the robot controller cannot use it; roll back to a good version or calibrate");
  }
  const auto entries = history();
  if (!entries) {
    found.push_back("the history cannot be listed: " + entries.error().message());
    return found;
  }
  for (const HistoryEntry& entry : *entries) {
    if (!entry.valid) {
      found.push_back("history entry " + std::to_string(entry.seq) + " is unreadable: " + entry.problem);
    }
  }
  return found;
}

StoreResult<std::vector<HistoryEntry>> CalibrationStore::history() const {
  const auto seqs = history_seqs();
  if (!seqs) return Unexpected{seqs.error()};
  const auto current = read_file(current_path());
  std::vector<HistoryEntry> entries;
  for (const int seq : *seqs) {
    HistoryEntry& entry = entries.emplace_back();
    entry.seq = seq;
    entry.path = history_dir() + "/" + history_name(seq);
    const auto text = read_file(entry.path);
    if (!text) {
      entry.problem = text.error().message();
      continue;
    }
    entry.current = current && *current == *text;
    const auto calibration = parse_text(*text, entry.path);
    if (!calibration) {
      entry.problem = calibration.error().reason;
      continue;
    }
    entry.valid = true;
    entry.created = calibration->created;
    entry.robot = calibration->robot;
    entry.samples = calibration->samples;
  }
  return entries;
}

}  // namespace cdpr::store
