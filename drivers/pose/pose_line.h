#pragma once
// The pose stream's line protocol (ASCII, one sample per line):
//
//   POSE <t_us> <x> <y> <z> <qw> <qx> <qy> <qz> <valid>\n
//
//   t_us        sender's time stamp [us], integer (its own clock)
//   x y z       platform origin in the world frame [m], finite decimals
//   qw qx qy qz world_R_platform, unit quaternion (norm within 1e-3 of 1;
//               renormalised), Hamilton convention as samples.csv
//   valid       1: the localization tracks; 0: it says it does not
//
// Fields are separated by one or more spaces or tabs; a '\r' before the
// '\n' is tolerated. Empty lines and lines starting with '#' are comments.
// Lines longer than kMaxPoseLineBytes are malformed. Anything else is
// rejected with a reason and never crashes: the parser is a pure function of
// its input, fit for fuzzing.

#include <cstddef>
#include <string>
#include <string_view>

#include "hal/pose_source.h"

namespace cdpr::drivers::pose {

inline constexpr std::size_t kMaxPoseLineBytes = 256;  // including the '\n'

enum class PoseLineResult {
  kSample,         // `sample` filled (received_us left 0 for the caller)
  kComment,        // empty or '#': ignore, not an error
  kNotPose,        // first word is not POSE
  kFieldCount,     // not exactly 9 values after POSE
  kBadNumber,      // a field is not a number of its type
  kNonFinite,      // NaN or infinity
  kBadQuaternion,  // norm not 1 within 1e-3
  kBadValid,       // valid is not 0 or 1
  kTooLong,        // longer than kMaxPoseLineBytes
};

const char* to_string(PoseLineResult result);

// Parses one line without its '\n'.
PoseLineResult parse_pose_line(std::string_view line, hal::PoseSample& sample);

// The line for `sample` (with '\n'), as the virtual robot sends it: parses
// back to the same values (17 significant digits).
std::string format_pose_line(const hal::PoseSample& sample);

}  // namespace cdpr::drivers::pose
