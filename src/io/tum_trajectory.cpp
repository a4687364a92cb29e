#include "panmap/io/tum_trajectory.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"
#include "panmap/io/text_files.h"
#include "panmap/io/timestamps.h"

namespace panmap {

std::vector<StampedPose> readTumTrajectory(const std::string& path) {
  if (!isRegularFile(path)) throw Error("cannot read trajectory " + path);
  std::vector<StampedPose> out;
  const std::vector<NumberLine> lines = readNumberLines(path);
  std::vector<double> times;
  for (const NumberLine& line : lines) {
    if (!line.values.empty()) times.push_back(line.values[0]);
  }
  const TimestampUnit unit = timestampUnitOf(times);
  for (const NumberLine& line : lines) {
    const std::string where = path + ":" + std::to_string(line.line);
    const std::vector<double>& v = line.values;
    if (v.size() < 8) throw Error(where + ": expected 't tx ty tz qx qy qz qw'");
    for (size_t k = 0; k < 8; ++k) {
      if (!std::isfinite(v[k])) throw Error(where + ": non-finite pose");
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3) {
      throw Error(where + ": quaternion is not unit length");
    }
    StampedPose pose;
    pose.utime = utimeOfSeconds(v[0] * unit.seconds_per_unit, where);
    pose.T_W_C.linear() = q.normalized().toRotationMatrix();
    pose.T_W_C.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    out.push_back(pose);
  }
  if (out.empty()) throw Error("trajectory " + path + " has no poses");
  return out;
}

void writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& trajectory) {
  std::string text = "# timestamp tx ty tz qx qy qz qw\n";
  char buffer[256];
  for (const StampedPose& p : trajectory) {
    const Eigen::Quaterniond q(p.T_W_C.linear());
    const Eigen::Vector3d t = p.T_W_C.translation();
    std::snprintf(buffer, sizeof(buffer), "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n",
                  p.utime * 1e-6, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
    text += buffer;
  }
  writeFileAtomically(path, text);
}

}  // namespace panmap
