#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace panmap {

/// A trajectory file in one of the formats RGB-D exports use, poses camera-to-world.
struct PoseList {
  /// kTum: "t tx ty tz qx qy qz qw" per line; kMatrixPerLine: 12 (3x4) or 16 (4x4) row-major
  /// numbers per line, one line per frame; kStacked: a 4x4 matrix over four lines per frame;
  /// kLog: the .log trajectory of Redwood, Augmented ICL-NUIM and Open3D, per frame a line of
  /// three integers (frame ids and count) over a 4x4 camera-to-world matrix on four lines.
  enum class Format { kTum, kMatrixPerLine, kStacked, kLog };
  Format format = Format::kTum;
  std::vector<double> times_s;  ///< kTum only: each pose's timestamp, seconds
  /// kTum only: the unit the file's time column was in (see timestampUnitOf).
  std::string time_unit = "seconds";
  /// The poses in file order; empty where the entry is not a rigid transform (see problems).
  std::vector<std::optional<Eigen::Isometry3d>> poses;
  std::vector<std::string> problems;  ///< per pose: "" or "file:line: why"
};

/// Reads a trajectory file, detecting its format from the count of numbers per line. A pose
/// that is not rigid (within `tolerance`, see isRigidTransform) is kept as an empty entry with
/// its reason, so one bad line does not lose the others. Throws Error naming the file and line
/// when the file is missing, not numeric, or its lines disagree on the format.
PoseList readPoseList(const std::string& path, double tolerance);

/// Name of a pose list format ("TUM", "matrix per line", "stacked 4x4", ".log").
const char* poseListFormatName(PoseList::Format format);

}  // namespace panmap
