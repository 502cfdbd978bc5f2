#include "src/operation/pose_output_line.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace cdpr::operation {

std::string format_pose_output(hal::TimeUs source_time_us, const Pose& pose,
                               const Eigen::Matrix<double, 6, 6>& covariance) {
  const Eigen::Vector3d& p = pose.position_world;
  const Eigen::Quaterniond& q = pose.world_R_platform;
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "POSE %lld %.17g %.17g %.17g %.17g %.17g %.17g %.17g 1\n",
                static_cast<long long>(source_time_us), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
  std::string text = buffer;
  text += "COV " + std::to_string(source_time_us);
  for (int row = 0; row < 6; ++row) {
    for (int col = row; col < 6; ++col) {
      std::snprintf(buffer, sizeof buffer, " %.17g", covariance(row, col));
      text += buffer;
    }
  }
  return text + "\n";
}

std::optional<PoseCovarianceLine> parse_covariance_line(std::string_view line) {
  const std::string text(line);
  if (text.rfind("COV ", 0) != 0) return std::nullopt;
  const char* at = text.c_str() + 4;
  char* end = nullptr;
  PoseCovarianceLine out;
  out.source_time_us = std::strtoll(at, &end, 10);
  if (end == at) return std::nullopt;
  for (int row = 0; row < 6; ++row) {
    for (int col = row; col < 6; ++col) {
      at = end;
      const double value = std::strtod(at, &end);
      if (end == at || !std::isfinite(value)) return std::nullopt;
      out.covariance(row, col) = out.covariance(col, row) = value;
    }
  }
  while (*end == ' ' || *end == '\t' || *end == '\r') ++end;
  if (*end != '\0') return std::nullopt;
  return out;
}

}  // namespace cdpr::operation
