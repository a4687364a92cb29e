// TUM RGB-D layout: rgb.txt and depth.txt ("timestamp file" lines), groundtruth.txt
// ("timestamp tx ty tz qx qy qz qw"), depth PNGs in units of 1/5000 m. Each depth image is
// paired with the colour image nearest in time (within tum_max_dt_s) and the ground-truth
// pose interpolated between its neighbours (or the nearest one within tum_max_dt_s).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/internal/readers.h"
#include "panmap/io/text_files.h"
#include "panmap/io/timestamps.h"
#include "panmap/io/tum_trajectory.h"

namespace panmap {
namespace internal {
namespace {

struct Stamped {
  double t = 0.0;
  std::string file;
};

std::vector<Stamped> readFileList(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read " + path);
  std::vector<Stamped> out;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;  // as pose files are read
    std::istringstream fields(line);
    Stamped s;
    if (!(fields >> s.t >> s.file)) {
      throw Error(path + ":" + std::to_string(line_no) + ": expected 'timestamp file'");
    }
    out.push_back(s);
  }
  std::vector<double> times;
  for (const Stamped& s : out) times.push_back(s.t);
  const double unit_s = timestampUnitOf(times).seconds_per_unit;
  for (Stamped& s : out) s.t *= unit_s;
  std::sort(out.begin(), out.end(), [](const Stamped& a, const Stamped& b) { return a.t < b.t; });
  return out;
}

// Median depth below this at TUM's unit is not a Kinect's: the images are likely millimetres.
constexpr double kNearestPlausibleMedianM = 0.5;

// The last component of a folder path ("a/b/" -> "b").
std::string folderName(const std::string& dir) {
  std::string d = dir;
  while (d.size() > 1 && d.back() == '/') d.pop_back();
  const size_t slash = d.rfind('/');
  return slash == std::string::npos ? d : d.substr(slash + 1);
}

// 1, 2 or 3 when the folder's own name names TUM's camera as its sequences do
// ("rgbd_dataset_freiburg1_desk"): "freiburg" and one digit, not followed by another digit.
// Only the folder's own name counts: a parent folder names a collection, not a camera.
int freiburgCamera(const std::string& dir) {
  const std::string name = folderName(dir);
  for (size_t at = name.find("freiburg"); at != std::string::npos;
       at = name.find("freiburg", at + 1)) {
    const size_t d = at + 8;
    if (d < name.size() && name[d] >= '1' && name[d] <= '3' &&
        (d + 1 == name.size() || !std::isdigit(static_cast<unsigned char>(name[d + 1])))) {
      return name[d] - '0';
    }
  }
  return 0;
}

// Ground truth, sorted by time; a TUM folder without it yields frames without poses.
std::vector<StampedPose> readGroundTruth(const std::string& path) {
  if (!isRegularFile(path)) return {};
  std::vector<StampedPose> out = readTumTrajectory(path);
  std::sort(out.begin(), out.end(),
            [](const StampedPose& a, const StampedPose& b) { return a.utime < b.utime; });
  return out;
}

class TumReader : public DatasetReader {
 public:
  TumReader(const std::string& dir, const DatasetOptions& options) : dir_(dir), options_(options) {
    const auto rgb = readFileList(dir + "/rgb.txt");
    const auto depth = readFileList(dir + "/depth.txt");
    if (depth.empty()) throw Error(dir + "/depth.txt: no depth images listed");
    std::vector<double> rgb_times;
    for (const Stamped& c : rgb) rgb_times.push_back(c.t);
    for (const Stamped& d : depth) {
      const long c = nearestIndex(rgb_times, d.t, options.tum_max_dt_s);
      if (c < 0) {
        ++unmatched_;
        continue;
      }
      pairs_.push_back({d, rgb[static_cast<size_t>(c)]});
    }
    if (pairs_.empty()) {
      throw Error(dir + ": no depth image has a colour image within " +
                  std::to_string(options.tum_max_dt_s) + " s");
    }
    poses_path_ = options.poses_path.empty() ? dir + "/groundtruth.txt" : options.poses_path;
    if (!options.poses_path.empty() && !isRegularFile(poses_path_)) {
      throw Error(poses_path_ + ": pose file missing");
    }
    ground_truth_ = readGroundTruth(poses_path_);

    std::string from = dir + "/camera-intrinsics.txt";
    if (options.intrinsics) {
      const Eigen::Vector4d& k = *options.intrinsics;
      camera_ = PinholeCamera{k(0), k(1), k(2), k(3), 0, 0};
    } else if (isRegularFile(from)) {
      const Eigen::Vector4d k = readIntrinsicsFile(from);  // as the folder layout reads them
      camera_ = PinholeCamera{k(0), k(1), k(2), k(3), 0, 0};
    } else if (const int camera = freiburgCamera(dir); camera > 0) {
      // TUM's published values of its three Kinects.
      static const PinholeCamera kFreiburg[3] = {{517.3, 516.5, 318.6, 255.3, 0, 0},
                                                 {520.9, 521.0, 325.1, 249.7, 0, 0},
                                                 {535.4, 539.2, 320.1, 247.6, 0, 0}};
      camera_ = kFreiburg[camera - 1];
      from = "TUM's freiburg" + std::to_string(camera) + " intrinsics";
      notes_.push_back("intrinsics: " + from + " (the folder is named " + folderName(dir) +
                       "; --intrinsics overrides)");
    } else {
      throw Error(dir +
                  "/camera-intrinsics.txt: intrinsics file missing and the folder's name "
                  "names no freiburg camera (pass --intrinsics fx,fy,cx,cy)");
    }
    const DepthImage first = readDepthFile(dir + "/" + pairs_.front().depth.file);
    camera_.width = first.width();
    camera_.height = first.height();
    std::string why;
    if (!camera_.isValid(&why)) throw Error(dir + ": intrinsics: " + why);
    if (!options.intrinsics) checkPrincipalPoint(camera_, from);
    checkDepthScale(dir);
  }

  std::string layoutName() const override { return "tum"; }
  std::vector<std::string> notes() const override { return notes_; }
  bool posesAreQuaternions() const override { return true; }
  size_t size() const override { return pairs_.size(); }
  size_t unmatchedFrames() const override { return unmatched_; }

  DatasetFrame read(size_t index) const override {
    const Pair& p = pairs_.at(index);
    DatasetFrame frame;
    const std::string depth_path = dir_ + "/" + p.depth.file;
    readDepthPng(depth_path, camera_.width, camera_.height, &frame);
    readRegisteredColor(dir_ + "/" + p.color.file, camera_.width, camera_.height, &frame);

    frame.rgbd.utime = utimeOfSeconds(p.depth.t, dir_ + "/depth.txt");
    frame.rgbd.frame_id = static_cast<int64_t>(index);
    frame.rgbd.camera_name = "tum";
    frame.rgbd.camera = camera_;
    frame.rgbd.depth_scale_m = depth_scale_m_;
    frame.T_W_C = poseAtTime(ground_truth_, p.depth.t, options_.tum_max_dt_s,
                             options_.max_pose_gap_s, poses_path_, &frame.pose_problem);
    return frame;
  }

 private:
  // TUM's depth unit is 1/5000 m; depth in millimetres laid out as TUM would map everything a
  // fifth of its size. A Kinect measures nothing nearer than about 0.5 m, so a median nearer
  // than that at 1/5000 m is named (not changed: --depth-scale decides).
  void checkDepthScale(const std::string& dir) {
    depth_scale_m_ = options_.depth_scale_m.value_or(1.0 / 5000.0);
    if (options_.depth_scale_m) {
      notes_.push_back("depth scale: " + formatDepthScale(depth_scale_m_) + " (given)");
      return;
    }
    std::vector<std::string> paths;
    for (const Pair& p : pairs_) paths.push_back(dir + "/" + p.depth.file);
    const DepthValueSample sample = sampleDepthValues(paths);
    std::ostringstream note;
    note.precision(3);
    note << "depth scale: " << formatDepthScale(depth_scale_m_) << ", TUM's";
    if (sample.images == 0) {
      note << " (the depth images looked at are empty)";
    } else {
      const double median_m = sample.median * depth_scale_m_;
      note << " (median " << median_m << " m over " << sample.images
           << (sample.images == 1 ? " image" : " images") << "; --depth-scale overrides)";
      if (median_m < kNearestPlausibleMedianM) {
        note << "; WARNING: a median this near is closer than a Kinect measures: if the images "
             << "are in millimetres (median " << sample.median * 0.001
             << " m), pass --depth-scale 0.001";
      }
    }
    notes_.push_back(note.str());
  }

  struct Pair {
    Stamped depth;
    Stamped color;
  };

  std::string dir_;
  DatasetOptions options_;
  PinholeCamera camera_;
  std::vector<Pair> pairs_;
  std::vector<StampedPose> ground_truth_;
  std::string poses_path_;
  size_t unmatched_ = 0;
  double depth_scale_m_ = 1.0 / 5000.0;
  std::vector<std::string> notes_;
};

}  // namespace

std::unique_ptr<DatasetReader> makeTumReader(const std::string& dir,
                                             const DatasetOptions& options) {
  return std::make_unique<TumReader>(dir, options);
}

}  // namespace internal
}  // namespace panmap
