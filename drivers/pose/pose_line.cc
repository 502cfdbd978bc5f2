#include "drivers/pose/pose_line.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace cdpr::drivers::pose {
namespace {

constexpr int kValueCount = 9;  // after the POSE keyword

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// Splits on blanks into at most `out.size()` words; returns the count, or
// out.size() + 1 when there are more.
template <std::size_t N>
std::size_t split_words(std::string_view line, std::array<std::string_view, N>& out) {
  std::size_t count = 0;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i == line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (count == N) return N + 1;
    out[count++] = line.substr(start, i - start);
  }
  return count;
}

template <typename T>
bool parse_number(std::string_view word, T& value) {
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+') ++first;  // from_chars refuses a leading '+'
  const auto [end, ec] = std::from_chars(first, last, value);
  return ec == std::errc() && end == last && first != last;
}

}  // namespace

const char* to_string(PoseLineResult result) {
  switch (result) {
    case PoseLineResult::kSample: return "sample";
    case PoseLineResult::kComment: return "comment";
    case PoseLineResult::kNotPose: return "not a POSE line";
    case PoseLineResult::kFieldCount: return "wrong number of fields";
    case PoseLineResult::kBadNumber: return "bad number";
    case PoseLineResult::kNonFinite: return "non-finite number";
    case PoseLineResult::kBadQuaternion: return "quaternion not of unit norm";
    case PoseLineResult::kBadValid: return "valid flag not 0 or 1";
    case PoseLineResult::kTooLong: return "line too long";
  }
  return "unknown";
}

PoseLineResult parse_pose_line(std::string_view line, hal::PoseSample& sample) {
  if (line.size() >= kMaxPoseLineBytes) return PoseLineResult::kTooLong;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  std::size_t first = 0;
  while (first < line.size() && is_blank(line[first])) ++first;
  if (first == line.size() || line[first] == '#') return PoseLineResult::kComment;

  std::array<std::string_view, kValueCount + 1> words;
  const std::size_t count = split_words(line, words);
  if (words[0] != "POSE") return PoseLineResult::kNotPose;
  if (count != kValueCount + 1) return PoseLineResult::kFieldCount;

  std::int64_t time_us = 0;
  if (!parse_number(words[1], time_us)) return PoseLineResult::kBadNumber;
  std::array<double, 7> v{};
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!parse_number(words[2 + i], v[i])) return PoseLineResult::kBadNumber;
    if (!std::isfinite(v[i])) return PoseLineResult::kNonFinite;
  }
  int valid = 0;
  if (!parse_number(words[9], valid)) return PoseLineResult::kBadNumber;
  if (valid != 0 && valid != 1) return PoseLineResult::kBadValid;
  const double norm = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
  if (!(std::abs(norm - 1.0) <= 1e-3)) return PoseLineResult::kBadQuaternion;

  sample = hal::PoseSample{};
  sample.source_time_us = time_us;
  sample.platform_world = {v[0], v[1], v[2]};
  sample.world_R_platform = {v[3] / norm, v[4] / norm, v[5] / norm, v[6] / norm};
  sample.valid = valid == 1;
  return PoseLineResult::kSample;
}

std::string format_pose_line(const hal::PoseSample& s) {
  char buffer[kMaxPoseLineBytes];
  const int n = std::snprintf(buffer, sizeof(buffer), "POSE %lld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d\n",
                              static_cast<long long>(s.source_time_us), s.platform_world.x, s.platform_world.y,
                              s.platform_world.z, s.world_R_platform.w, s.world_R_platform.x, s.world_R_platform.y,
                              s.world_R_platform.z, s.valid ? 1 : 0);
  return std::string(buffer, n > 0 ? static_cast<std::size_t>(n) : 0);
}

}  // namespace cdpr::drivers::pose
