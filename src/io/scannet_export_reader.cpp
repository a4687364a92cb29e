// ScanNet SensReader export: color/N.jpg (1296x968), depth/N.png (640x480, mm), pose/N.txt
// (4x4 camera-to-world, -inf rows where tracking was lost), intrinsic/{intrinsic,extrinsic}_
// {color,depth}.txt and the scene's <scene>.txt metadata (colorToDepthExtrinsics).
//
// Colour is registered to the depth camera. kReproject: each depth pixel is back-projected
// with its depth, moved into the colour camera by the colour-to-depth extrinsics and projected
// with the colour intrinsics; pixels without depth use the rotation-only (infinite depth)
// mapping. kResize: the colour image is resized to the depth size and treated as aligned.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/internal/readers.h"
#include "panmap/io/opencv_image.h"
#include "panmap/io/text_files.h"

namespace panmap {
namespace internal {
namespace {

PinholeCamera readIntrinsics4x4(const std::string& path) {
  if (!isRegularFile(path)) throw Error(path + ": intrinsics file missing");
  const Eigen::MatrixXd K = readMatrixFile(path, 4, 4);
  PinholeCamera camera{K(0, 0), K(1, 1), K(0, 2), K(1, 2), 1, 1};
  std::string why;
  if (!camera.isValid(&why)) throw Error(path + ": " + why);
  return camera;
}

class ScanNetReader : public DatasetReader {
 public:
  ScanNetReader(const std::string& dir, const DatasetOptions& options)
      : dir_(dir), options_(options) {
    frames_ = listNumberedFiles(dir + "/depth", R"((\d+)\.png)");
    if (frames_.empty()) throw Error(dir + "/depth: no N.png depth images (not a ScanNet export)");
    // A frame whose depth image is missing is left out; it is counted so the user hears of it.
    color_without_depth_ = unpairedFiles(frames_, dir + "/color", R"((\d+)\.(?:jpg|png))");
    depth_camera_ = readIntrinsics4x4(dir + "/intrinsic/intrinsic_depth.txt");
    color_camera_ = readIntrinsics4x4(dir + "/intrinsic/intrinsic_color.txt");
    if (options.intrinsics) {
      const Eigen::Vector4d& k = *options.intrinsics;
      depth_camera_.fx = k(0), depth_camera_.fy = k(1), depth_camera_.cx = k(2),
      depth_camera_.cy = k(3);
    }

    std::string meta_path;
    const auto meta = readScanNetSceneMeta(dir, &meta_path);
    if (const auto from_meta = scanNetColorFromDepth(meta, meta_path)) {
      T_C_D_ = *from_meta;
    } else {
      // Without metadata fall back to the export's extrinsics (poses of each sensor on the rig).
      const std::string ec = dir + "/intrinsic/extrinsic_color.txt";
      const std::string ed = dir + "/intrinsic/extrinsic_depth.txt";
      if (isRegularFile(ec) && isRegularFile(ed)) {
        const Eigen::Matrix4d T_R_C = readMatrixFile(ec, 4, 4);
        const Eigen::Matrix4d T_R_D = readMatrixFile(ed, 4, 4);
        T_C_D_ = nearestIsometry(T_R_C).inverse() * nearestIsometry(T_R_D);
      }
    }

    const std::string first_depth = depthPath(0);
    const DepthImage depth = readDepthFile(first_depth);
    depth_camera_.width = depth.width();
    depth_camera_.height = depth.height();
    const ColorImage color = readColorFile(colorPath(0));
    color_camera_.width = color.width();
    color_camera_.height = color.height();
    if (meta.count("depthWidth")) {
      checkImageSize(first_depth, "depth", depth.width(), depth.height(),
                     std::stoi(meta.at("depthWidth")), std::stoi(meta.at("depthHeight")));
      checkImageSize(colorPath(0), "colour", color.width(), color.height(),
                     std::stoi(meta.at("colorWidth")), std::stoi(meta.at("colorHeight")));
    }
  }

  std::string layoutName() const override { return "scannet"; }
  size_t size() const override { return frames_.size(); }
  size_t unmatchedFrames() const override { return color_without_depth_.size(); }
  std::string unmatchedWhat() const override {
    return "colour images without a depth image (first: color/" + color_without_depth_.front() +
           ")";
  }
  bool invalidPosesExpected() const override { return true; }

  DatasetPose pose(size_t index) const override {
    const long long number = frames_.at(index).first;
    DatasetPose out;
    out.utime = frameUtime(number, options_.frame_rate_hz);
    out.frame_id = number;
    out.T_W_C = readPoseFile(dir_ + "/pose/" + std::to_string(number) + ".txt",
                             options_.pose_tolerance, &out.problem);
    return out;
  }

  DatasetFrame read(size_t index) const override {
    DatasetFrame frame;
    const long long number = frames_.at(index).first;
    const std::string depth_path = depthPath(index);
    readDepthPng(depth_path, depth_camera_.width, depth_camera_.height, &frame);
    const std::string color_path = colorPath(index);
    const ColorImage color = readColorFile(color_path);
    checkImageSize(color_path, "colour", color.width(), color.height(), color_camera_.width,
                   color_camera_.height);
    frame.color_stem = fileStem(color_path);
    frame.color_source_width = color.width();
    frame.color_source_height = color.height();
    scanNetColorMap(frame.rgbd.depth, depth_camera_, color_camera_, T_C_D_,
                    options_.depth_scale_m.value_or(0.001), options_.registration,
                    &frame.color_map_u, &frame.color_map_v);
    cv::Mat registered;
    cv::remap(asMat(color), registered, asMat(frame.color_map_u), asMat(frame.color_map_v),
              cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0));
    frame.rgbd.color = colorFromMat(registered);

    frame.rgbd.utime = frameUtime(number, options_.frame_rate_hz);
    frame.rgbd.frame_id = number;
    frame.rgbd.camera_name = "scannet";
    frame.rgbd.camera = depth_camera_;
    frame.rgbd.depth_scale_m = options_.depth_scale_m.value_or(0.001);
    frame.T_W_C = readPoseFile(dir_ + "/pose/" + std::to_string(number) + ".txt",
                               options_.pose_tolerance, &frame.pose_problem);
    return frame;
  }

 private:
  std::string depthPath(size_t index) const { return dir_ + "/depth/" + frames_.at(index).second; }
  std::string colorPath(size_t index) const {
    const std::string base = dir_ + "/color/" + std::to_string(frames_.at(index).first);
    if (isRegularFile(base + ".jpg")) return base + ".jpg";
    if (isRegularFile(base + ".png")) return base + ".png";
    throw Error(base + ".jpg: colour image missing");
  }

  std::string dir_;
  DatasetOptions options_;
  PinholeCamera depth_camera_;
  PinholeCamera color_camera_;
  Eigen::Isometry3d T_C_D_ = Eigen::Isometry3d::Identity();
  std::vector<std::pair<long long, std::string>> frames_;
  std::vector<std::string> color_without_depth_;
};

}  // namespace

std::map<std::string, std::string> readScanNetMetaFile(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::map<std::string, std::string> meta;
  while (std::getline(in, line)) {
    const auto eq = line.find(" = ");
    if (eq != std::string::npos) meta[line.substr(0, eq)] = line.substr(eq + 3);
  }
  if (!meta.count("colorWidth") || !meta.count("depthWidth")) return {};
  return meta;
}

std::map<std::string, std::string> readScanNetSceneMeta(const std::string& dir,
                                                        std::string* path_out) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".txt") continue;
    std::map<std::string, std::string> candidate = readScanNetMetaFile(entry.path().string());
    if (!candidate.empty()) {
      *path_out = entry.path().string();
      return candidate;
    }
  }
  return {};
}

std::optional<Eigen::Isometry3d> scanNetColorFromDepth(
    const std::map<std::string, std::string>& meta, const std::string& meta_path) {
  const auto it = meta.find("colorToDepthExtrinsics");
  if (it == meta.end()) return std::nullopt;
  // p_D = E p_C, so T_C_D = E^-1.
  std::istringstream values(it->second);
  Eigen::Matrix4d E;
  for (int i = 0; i < 16; ++i) {
    if (!(values >> E(i / 4, i % 4))) throw Error(meta_path + ": bad colorToDepthExtrinsics");
  }
  std::string why;
  if (!isRigidTransform(E, 1e-3, &why)) throw Error(meta_path + ": colorToDepthExtrinsics " + why);
  return nearestIsometry(E).inverse();
}

void scanNetColorMap(const DepthImage& depth, const PinholeCamera& d, const PinholeCamera& c,
                     const Eigen::Isometry3d& T_C_D, double depth_scale_m,
                     ColorRegistration registration, Image<float>* map_u, Image<float>* map_v) {
  if (registration == ColorRegistration::kResize) {
    resizeColorMap(d.width, d.height, c.width, c.height, map_u, map_v);
    return;
  }
  *map_u = Image<float>(d.width, d.height);
  *map_v = Image<float>(d.width, d.height);
  const Eigen::Matrix3d R = T_C_D.linear();
  const Eigen::Vector3d t = T_C_D.translation();
  for (int v = 0; v < d.height; ++v) {
    const uint16_t* z_row = depth.row(v);
    for (int u = 0; u < d.width; ++u) {
      const double z = z_row[u] * depth_scale_m;
      const Eigen::Vector3d ray((u - d.cx) / d.fx, (v - d.cy) / d.fy, 1.0);
      // Without depth the point is taken at infinity: only the rotation matters.
      const Eigen::Vector3d p_C =
          z > 0.0 ? Eigen::Vector3d(R * (ray * z) + t) : Eigen::Vector3d(R * ray);
      float cu = -1.0f, cv = -1.0f;
      if (p_C.z() > 1e-6) {
        cu = static_cast<float>(c.fx * p_C.x() / p_C.z() + c.cx);
        cv = static_cast<float>(c.fy * p_C.y() / p_C.z() + c.cy);
      }
      (*map_u)(u, v) = cu;
      (*map_v)(u, v) = cv;
    }
  }
}

std::unique_ptr<DatasetReader> makeScanNetReader(const std::string& dir,
                                                 const DatasetOptions& options) {
  return std::make_unique<ScanNetReader>(dir, options);
}

}  // namespace internal
}  // namespace panmap
