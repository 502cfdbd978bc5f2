#pragma once
// Replacing a small file so that a reader (or a reboot) sees either the old
// or the new content complete, never a mixture (chrony reference.c
// update_drift_file, with the fsyncs it leaves out):
//
//   step +1  half of the content written to "<dir>/.<name>.tmp"
//   step +2  all of it written
//   step +3  temp file fsynced (data on disk before the name points at it)
//   step +4  temp renamed over "<dir>/<name>" (atomic within one directory)
//   step +5  directory fsynced (the rename itself is durable)
//
// After each step `hook(first_step + k)` is asked whether to stop there as if
// the process had been killed (files left exactly as they are); tests use it
// to check every crash point, a SIGKILL test can raise(SIGKILL) from it.
// Single writer per file: the temp name is fixed.

#include <functional>
#include <string>
#include <string_view>

#include "src/store/store_error.h"

namespace cdpr::store {

// Returns true to simulate a crash right after step `step`.
using CrashHook = std::function<bool(int step)>;

inline constexpr int kAtomicWriteSteps = 5;
// Offset (from first_step) of the step after which the new content is in place.
inline constexpr int kAtomicRenameStepOffset = 3;

// Replaces dir/name by `content` as above. A simulated crash returns a
// StoreError with operation "crash" and leaves the files as they are; any
// other failure (ENOSPC, EIO) removes the temp file before it returns.
[[nodiscard]] StoreResult<Done> write_file_atomically(const std::string& dir, const std::string& name,
                                                     std::string_view content, const CrashHook& hook, int first_step);

// fsync of a directory, so that renames and unlinks inside it are durable.
[[nodiscard]] StoreResult<Done> fsync_directory(const std::string& dir);

// Proves that files can be made durable in `dir` now: "<dir>/.write-probe.tmp"
// created, written, fsynced, closed and removed, then the directory fsynced.
// The error names the step and errno (EROFS, ENOSPC, EACCES, ENOTDIR, EIO).
// A probe a crash leaves behind is a stale temp file (".<name>.tmp").
[[nodiscard]] StoreResult<Done> probe_writable(const std::string& dir);

// Whole-file read with errno on failure (ENOENT when absent).
[[nodiscard]] StoreResult<std::string> read_file(const std::string& path);

// True when the hook wants to stop after `step` (an empty hook never does).
bool crash_requested(const CrashHook& hook, int step);

// The StoreError reported for a simulated crash.
StoreError simulated_crash(const std::string& path, int step);

// The temp name write_file_atomically uses for `name`.
std::string temp_name(const std::string& name);

}  // namespace cdpr::store
