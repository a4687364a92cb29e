// 7-Scenes / tsdf-fusion layout: frame-XXXXXX.{color.jpg,depth.png,pose.txt} and
// camera-intrinsics.txt (3x3 K) in one folder. Colour and depth are registered already.
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/internal/readers.h"
#include "panmap/io/text_files.h"

namespace panmap {
namespace internal {
namespace {

class SevenScenesReader : public DatasetReader {
 public:
  SevenScenesReader(const std::string& dir, const DatasetOptions& options)
      : dir_(dir), options_(options) {
    frames_ = listNumberedFiles(dir, R"(frame-(\d+)\.depth\.png)");
    if (frames_.empty()) {
      throw Error(dir + ": no frame-XXXXXX.depth.png files (not a 7-Scenes/tsdf-fusion folder)");
    }
    countColorWithoutDepth();
    const std::string path = dir + "/camera-intrinsics.txt";
    if (options.intrinsics) {
      const Eigen::Vector4d& k = *options.intrinsics;
      camera_ = PinholeCamera{k(0), k(1), k(2), k(3), 0, 0};
    } else {
      if (!isRegularFile(path)) {
        throw Error(path + ": intrinsics file missing (or pass --intrinsics fx,fy,cx,cy)");
      }
      const Eigen::MatrixXd K = readMatrixFile(path, 3, 3);
      camera_ = PinholeCamera{K(0, 0), K(1, 1), K(0, 2), K(1, 2), 0, 0};
    }
    // The sequence's size is that of its first depth image; every frame must agree.
    const std::string first = depthPath(0);
    const DepthImage depth = readDepthFile(first);
    camera_.width = depth.width();
    camera_.height = depth.height();
    std::string why;
    if (!camera_.isValid(&why)) throw Error(path + ": " + why);
    // Given on the command line, a cropped sensor may really have it off-centre.
    if (!options.intrinsics) checkPrincipalPoint(camera_, path);
  }

  std::string layoutName() const override { return "7scenes"; }
  size_t size() const override { return frames_.size(); }
  size_t unmatchedFrames() const override { return color_without_depth_.size(); }
  std::string unmatchedWhat() const override {
    return "colour images without a depth image (first: " + color_without_depth_.front() + ")";
  }

  DatasetFrame read(size_t index) const override {
    DatasetFrame frame;
    const long long number = frames_.at(index).first;
    const std::string prefix = dir_ + "/" + stemOf(index);
    const std::string depth_path = depthPath(index);
    readDepthPng(depth_path, camera_.width, camera_.height, &frame);

    std::string color_path = prefix + ".color.jpg";
    if (!isRegularFile(color_path) && isRegularFile(prefix + ".color.png")) {
      color_path = prefix + ".color.png";
    }
    readRegisteredColor(color_path, camera_.width, camera_.height, &frame);

    frame.rgbd.utime = frameUtime(number, options_.frame_rate_hz);
    frame.rgbd.frame_id = number;
    frame.rgbd.camera_name = "7scenes";
    frame.rgbd.camera = camera_;
    frame.rgbd.depth_scale_m = options_.depth_scale_m.value_or(0.001);
    frame.T_W_C = readPoseFile(prefix + ".pose.txt", options_.pose_tolerance, &frame.pose_problem);
    return frame;
  }

 private:
  std::string stemOf(size_t index) const {
    const std::string& name = frames_.at(index).second;
    return name.substr(0, name.size() - std::string(".depth.png").size());
  }
  std::string depthPath(size_t index) const { return dir_ + "/" + frames_.at(index).second; }

  // A frame whose depth image is missing is left out; it is counted so the user hears of it.
  void countColorWithoutDepth() {
    color_without_depth_ = unpairedFiles(frames_, dir_, R"(frame-(\d+)\.color\.(?:jpg|png))");
  }

  std::string dir_;
  DatasetOptions options_;
  PinholeCamera camera_;
  std::vector<std::pair<long long, std::string>> frames_;
  std::vector<std::string> color_without_depth_;
};

}  // namespace

std::unique_ptr<DatasetReader> makeSevenScenesReader(const std::string& dir,
                                                     const DatasetOptions& options) {
  return std::make_unique<SevenScenesReader>(dir, options);
}

}  // namespace internal
}  // namespace panmap
