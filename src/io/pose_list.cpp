#include "panmap/io/pose_list.h"

#include <cmath>

#include "panmap/core/error.h"
#include "panmap/core/pose.h"
#include "panmap/io/text_files.h"
#include "panmap/io/timestamps.h"

namespace panmap {
namespace {

using Line = NumberLine;

std::vector<Line> readLines(const std::string& path) {
  if (!isRegularFile(path)) throw Error("cannot read pose file " + path);
  std::vector<Line> out = readNumberLines(path);
  if (out.empty()) throw Error(path + ": no poses");
  return out;
}

void addMatrix(const Eigen::Matrix4d& T, const std::string& where, double tolerance,
               PoseList* list) {
  std::string why;
  if (isRigidTransform(T, tolerance, &why)) {
    list->poses.emplace_back(nearestIsometry(T));
    list->problems.emplace_back();
  } else {
    list->poses.emplace_back();
    list->problems.push_back(where + ": invalid pose, " + why);
  }
}

// Redwood's .log: five lines a frame, the first of three numbers, the others of four.
PoseList readLogPoses(const std::string& path, const std::vector<Line>& lines, double tolerance) {
  PoseList list;
  list.format = PoseList::Format::kLog;
  if (lines.size() % 5 != 0) {
    throw Error(path + ": " + std::to_string(lines.size()) +
                " lines, not a whole number of .log entries (a line of 3 numbers over a 4x4 "
                "matrix)");
  }
  for (size_t k = 0; k < lines.size(); k += 5) {
    for (size_t r = 0; r < 5; ++r) {
      const size_t want = r == 0 ? 3 : 4;
      if (lines[k + r].values.size() != want) {
        throw Error(path + ":" + std::to_string(lines[k + r].line) + ": " +
                    std::to_string(lines[k + r].values.size()) + " numbers where a .log entry " +
                    "has " + std::to_string(want));
      }
    }
    Eigen::Matrix4d T;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) T(r, c) = lines[k + 1 + r].values[static_cast<size_t>(c)];
    }
    addMatrix(T, path + ":" + std::to_string(lines[k + 1].line), tolerance, &list);
  }
  return list;
}

}  // namespace

const char* poseListFormatName(PoseList::Format format) {
  switch (format) {
    case PoseList::Format::kTum:
      return "TUM";
    case PoseList::Format::kMatrixPerLine:
      return "matrix per line";
    case PoseList::Format::kLog:
      return ".log";
    default:
      return "stacked 4x4";
  }
}

PoseList readPoseList(const std::string& path, double tolerance) {
  const std::vector<Line> lines = readLines(path);
  if (lines.front().values.size() == 3 && lines.size() > 1 && lines[1].values.size() == 4) {
    return readLogPoses(path, lines, tolerance);
  }
  const size_t width = lines.front().values.size();
  for (const Line& line : lines) {
    if (line.values.size() != width) {
      throw Error(path + ":" + std::to_string(line.line) + ": " +
                  std::to_string(line.values.size()) + " numbers where line " +
                  std::to_string(lines.front().line) + " has " + std::to_string(width));
    }
  }
  PoseList list;
  auto where = [&path](const Line& line) { return path + ":" + std::to_string(line.line); };
  if (width == 8) {
    list.format = PoseList::Format::kTum;
    for (const Line& line : lines) {
      const std::vector<double>& v = line.values;
      const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      list.times_s.push_back(v[0]);
      if (!std::isfinite(v[0]) || !std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3 ||
          !Eigen::Vector3d(v[1], v[2], v[3]).allFinite()) {
        list.poses.emplace_back();
        list.problems.push_back(where(line) + ": invalid pose, not a finite unit quaternion");
        continue;
      }
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = q.normalized().toRotationMatrix();
      T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
      list.poses.emplace_back(T);
      list.problems.emplace_back();
    }
  } else if (width == 12 || width == 16) {
    list.format = PoseList::Format::kMatrixPerLine;
    for (const Line& line : lines) {
      Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
      for (size_t i = 0; i < width; ++i) T(i / 4, i % 4) = line.values[i];
      addMatrix(T, where(line), tolerance, &list);
    }
  } else if (width == 4) {
    if (lines.size() % 4 != 0) {
      throw Error(path + ": " + std::to_string(lines.size()) +
                  " lines of 4 numbers, not a whole number of 4x4 matrices");
    }
    list.format = PoseList::Format::kStacked;
    for (size_t k = 0; k < lines.size(); k += 4) {
      Eigen::Matrix4d T;
      for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) T(r, c) = lines[k + r].values[static_cast<size_t>(c)];
      }
      addMatrix(T, where(lines[k]), tolerance, &list);
    }
  } else {
    throw Error(path + ":" + std::to_string(lines.front().line) + ": " + std::to_string(width) +
                " numbers per line; expected TUM (t tx ty tz qx qy qz qw), 12 or 16 (a 3x4 or "
                "4x4 matrix per line) or 4 (a 4x4 matrix over four lines)");
  }
  const TimestampUnit unit = timestampUnitOf(list.times_s);
  for (double& t : list.times_s) t *= unit.seconds_per_unit;
  list.time_unit = unit.name;
  return list;
}

}  // namespace panmap
