#pragma once
// The daemon's persistent calibration: a state directory (systemd
// StateDirectory=, e.g. /var/lib/cdpr-calib) holding
//
//   calibration.toml                    the current calibration (what the robot controller reads)
//   history/calibration-000042.toml     every committed version, by sequence number
//
// calibration.toml is always a byte copy of one history entry (the newest
// after a commit, an older one after a rollback). The history keeps the
// newest `history_depth + 1` versions (the current plus N previous), and
// never prunes the entry equal to the current file. The format version is the
// `format` key inside each file (docs/FORMATS.md); every file is parsed before it is
// written and after it is read, so a corrupt or newer file is refused.
//
// Atomicity (src/store/atomic_file.h): commit = history entry written
// atomically (steps 1-5), then calibration.toml replaced atomically (steps
// 6-10), then old entries pruned (11) and the history directory fsynced (12).
// A crash at any step leaves calibration.toml either old or new, complete.
// A crash between steps 5 and 9 leaves a history entry that never became
// current; history() marks which entry is current. Rollback is steps 1-5 on
// calibration.toml alone. Stale temp files are removed by open().
//
// Not thread-safe: one store object, one thread (the daemon's main loop).
// No exceptions: every failure is a StoreError naming the path and errno.

#include <optional>
#include <string>
#include <vector>

#include "solver/model/calibration.h"
#include "src/store/atomic_file.h"
#include "src/store/store_error.h"

namespace cdpr::store {

struct StoreOptions {
  std::string state_dir;   // must be an existing directory's parent or the directory itself
  int history_depth = 10;  // previous versions kept besides the current one, >= 0
};

struct HistoryEntry {
  int seq = 0;
  std::string path;
  bool current = false;  // byte-identical to calibration.toml
  bool valid = false;    // parses as calibration.toml
  std::string created;   // from the file when valid
  std::string robot;
  int samples = 0;
  std::string problem;   // why it is not valid; empty when valid
};

struct CurrentCalibration {
  Calibration calibration;
  std::string text;  // the file's exact bytes
  int seq = 0;       // the history entry it equals; 0 when none does (e.g. history pruned by hand)
};

class CalibrationStore {
 public:
  static constexpr const char* kCurrentName = "calibration.toml";
  static constexpr const char* kHistoryDir = "history";
  static constexpr int kCommitSteps = 2 * kAtomicWriteSteps + 2;
  static constexpr int kRollbackSteps = kAtomicWriteSteps;
  // From the end of these steps on, calibration.toml holds the new content.
  static constexpr int kCommitReplacedStep = 1 + kAtomicWriteSteps + kAtomicRenameStepOffset;
  static constexpr int kRollbackReplacedStep = 1 + kAtomicRenameStepOffset;

  explicit CalibrationStore(StoreOptions options);

  // Creates the state and history directories when missing and removes
  // temp files a crash left behind. Call once before anything else.
  [[nodiscard]] StoreResult<Done> open();

  // The current calibration; empty when none was ever committed. A present
  // but unreadable or unparsable file is an error (operation "parse").
  [[nodiscard]] StoreResult<std::optional<CurrentCalibration>> load_current() const;

  // The newest history version that reads and parses (seq set), for the
  // change check when calibration.toml itself is unreadable; empty when
  // none does.
  [[nodiscard]] StoreResult<std::optional<CurrentCalibration>> newest_readable_version() const;

  // Formats and commits `calibration`; returns its sequence number.
  [[nodiscard]] StoreResult<int> commit(const Calibration& calibration);
  // Commits text that must parse as calibration.toml.
  [[nodiscard]] StoreResult<int> commit_text(const std::string& text);

  // Makes history entry `seq` current again (atomically); refuses an entry
  // that is missing or does not parse. Returns seq.
  [[nodiscard]] StoreResult<int> rollback(int seq);

  // All history entries, newest first.
  [[nodiscard]] StoreResult<std::vector<HistoryEntry>> history() const;

  // Proves a commit could write now (probe_writable() in the state and the
  // history directory): a run calls it before it moves anything.
  [[nodiscard]] StoreResult<Done> probe_writable() const;

  // What is wrong with the stored files, one operator sentence each: an
  // unreadable or unparsable calibration.toml, unreadable history entries,
  // a history that cannot be listed. Empty when all is well.
  std::vector<std::string> problems() const;

  // Test hook: stop as if killed after step k (see above).
  void set_crash_hook(CrashHook hook) { crash_hook_ = std::move(hook); }

  const std::string& state_dir() const { return options_.state_dir; }
  std::string current_path() const;
  std::string history_dir() const;
  static std::string history_name(int seq);

 private:
  StoreResult<std::vector<int>> history_seqs() const;
  StoreResult<Done> prune(const std::string& current_text, int first_step);

  StoreOptions options_;
  CrashHook crash_hook_;
};

}  // namespace cdpr::store
