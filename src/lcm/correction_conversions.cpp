#include "panmap/lcm/correction_conversions.h"

#include <string>

#include "panmap/core/error.h"
#include "panmap/lcm/conversions.h"

namespace panmap {

pose_correction_t toMessage(const PoseCorrection& correction) {
  pose_correction_t msg;
  msg.utime = correction.utime;
  msg.correction_id = correction.correction_id;
  msg.num_poses = static_cast<int32_t>(correction.poses.size());
  for (const StampedPose& p : correction.poses) msg.poses.push_back(toMessage(p));
  return msg;
}

PoseCorrection fromMessage(const pose_correction_t& msg) {
  const std::string what = "pose correction " + std::to_string(msg.correction_id);
  if (msg.num_poses < 0 || msg.poses.size() != static_cast<size_t>(msg.num_poses)) {
    throw Error(what + ": num_poses disagrees with the poses (" + std::to_string(msg.poses.size()) +
                " poses for num_poses " + std::to_string(msg.num_poses) + ")");
  }
  PoseCorrection c;
  c.utime = msg.utime;
  c.correction_id = msg.correction_id;
  for (const pose_t& p : msg.poses) {
    try {
      c.poses.push_back(fromMessage(p));
    } catch (const Error& e) {
      throw Error(what + ": " + e.what());
    }
  }
  c.check();
  return c;
}

}  // namespace panmap
