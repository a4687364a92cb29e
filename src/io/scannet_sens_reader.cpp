// A ScanNet .sens recording read in place, frame by frame: what SensReader would export
// (frame N as color/N.jpg, depth/N.png, pose/N.txt), without the export. Colour is registered
// to the depth camera as for the export (scannet_export_reader.cpp), through the scene
// metadata's colorToDepthExtrinsics when <scene>.txt lies beside the file, else through the
// rig extrinsics the .sens header carries.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "panmap/core/error.h"
#include "panmap/io/internal/readers.h"
#include "panmap/io/opencv_image.h"
#include "panmap/io/scannet_sens.h"

namespace panmap {
namespace internal {
namespace {

constexpr const char* kSensExtension = ".sens";

PinholeCamera cameraOf(const Eigen::Matrix4f& K, uint32_t width, uint32_t height,
                       const std::string& what) {
  PinholeCamera camera{
      K(0, 0), K(1, 1), K(0, 2), K(1, 2), static_cast<int>(width), static_cast<int>(height)};
  std::string why;
  if (!camera.isValid(&why)) throw Error(what + ": " + why);
  return camera;
}

Eigen::Isometry3d rigPose(const Eigen::Matrix4f& T, const std::string& what) {
  std::string why;
  if (!isRigidTransform(T.cast<double>(), 1e-3, &why)) throw Error(what + ": " + why);
  return nearestIsometry(T.cast<double>());
}

class ScanNetSensReader : public DatasetReader {
 public:
  ScanNetSensReader(const std::string& path, const DatasetOptions& options)
      : file_(ScanNetSensFile::open(path)), options_(options) {
    const ScanNetSensHeader& h = file_.header();
    if (file_.size() == 0) throw Error(path + ": no frames");
    depth_camera_ =
        cameraOf(h.intrinsic_depth, h.depth_width, h.depth_height, path + ": depth intrinsics");
    color_camera_ =
        cameraOf(h.intrinsic_color, h.color_width, h.color_height, path + ": colour intrinsics");
    if (options.intrinsics) {
      const Eigen::Vector4d& k = *options.intrinsics;
      depth_camera_.fx = k(0), depth_camera_.fy = k(1), depth_camera_.cx = k(2),
      depth_camera_.cy = k(3);
    }
    depth_scale_m_ = options.depth_scale_m.value_or(1.0 / h.depth_shift);
    // Its own scene's metadata only (scans/<scene>/<scene>.txt): a folder of several scans'
    // files must not lend one scan's calibration to another.
    const std::string meta_path = std::filesystem::path(path).replace_extension(".txt").string();
    const auto meta = readScanNetMetaFile(meta_path);
    if (const auto from_meta = scanNetColorFromDepth(meta, meta_path)) {
      T_C_D_ = *from_meta;
      registration_note_ = "colour registered through colorToDepthExtrinsics of " + meta_path;
    } else {
      T_C_D_ = rigPose(h.extrinsic_color, path + ": colour extrinsics").inverse() *
               rigPose(h.extrinsic_depth, path + ": depth extrinsics");
      registration_note_ = "colour registered through the file's rig extrinsics (no " + meta_path +
                           " with colorToDepthExtrinsics)";
    }
  }

  std::string layoutName() const override { return "scannet-sens"; }
  size_t size() const override { return file_.size(); }
  bool invalidPosesExpected() const override { return true; }

  std::vector<std::string> notes() const override {
    const ScanNetSensHeader& h = file_.header();
    char line[320];
    std::snprintf(line, sizeof line,
                  "%s: %zu frames of '%s', colour %ux%u, depth %ux%u at %g units per metre; "
                  "mask names are frame numbers from 0 (N.png), as SensReader exports colour",
                  file_.path().c_str(), file_.size(), h.sensor_name.c_str(), h.color_width,
                  h.color_height, h.depth_width, h.depth_height, h.depth_shift);
    return {line, registration_note_};
  }

  DatasetPose pose(size_t index) const override {
    DatasetPose out;
    out.utime = frameUtime(static_cast<long long>(index), options_.frame_rate_hz);
    out.frame_id = static_cast<int64_t>(index);
    out.T_W_C = validPose(file_.readPose(index), index, &out.problem);
    return out;
  }

  DatasetFrame read(size_t index) const override {
    const ScanNetSensFrame stored = file_.readFrame(index);
    DatasetFrame frame;
    frame.rgbd.depth = file_.decodeDepth(stored, index);
    const ColorImage color = file_.decodeColor(stored, index);
    frame.color_stem = std::to_string(index);
    frame.color_source_width = color.width();
    frame.color_source_height = color.height();
    scanNetColorMap(frame.rgbd.depth, depth_camera_, color_camera_, T_C_D_, depth_scale_m_,
                    options_.registration, &frame.color_map_u, &frame.color_map_v);
    cv::Mat registered;
    cv::remap(asMat(color), registered, asMat(frame.color_map_u), asMat(frame.color_map_v),
              cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0));
    frame.rgbd.color = colorFromMat(registered);
    frame.rgbd.utime = frameUtime(static_cast<long long>(index), options_.frame_rate_hz);
    frame.rgbd.frame_id = static_cast<int64_t>(index);
    frame.rgbd.camera_name = "scannet";
    frame.rgbd.camera = depth_camera_;
    frame.rgbd.depth_scale_m = depth_scale_m_;
    frame.T_W_C = validPose(stored.camera_to_world, index, &frame.pose_problem);
    return frame;
  }

 private:
  // ScanNet writes -inf rows for frames its reconstruction lost.
  std::optional<Eigen::Isometry3d> validPose(const Eigen::Matrix4f& T, size_t index,
                                             std::string* problem) const {
    std::string why;
    if (isRigidTransform(T.cast<double>(), options_.pose_tolerance, &why)) {
      return nearestIsometry(T.cast<double>());
    }
    *problem = file_.path() + " frame " + std::to_string(index) + ": invalid pose, " + why;
    return std::nullopt;
  }

  ScanNetSensFile file_;
  DatasetOptions options_;
  PinholeCamera depth_camera_;
  PinholeCamera color_camera_;
  double depth_scale_m_ = 0.001;
  Eigen::Isometry3d T_C_D_ = Eigen::Isometry3d::Identity();
  std::string registration_note_;
};

}  // namespace

std::string missingForScanNetSens(const std::string& dir, std::string* found) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_regular_file() && entry.path().extension() == kSensExtension) {
      files.push_back(entry.path().string());
    }
  }
  if (files.empty()) return "no *.sens file";
  if (files.size() > 1) {
    return std::to_string(files.size()) + " *.sens files (give the one to import)";
  }
  if (found) *found = files.front();
  return "";
}

std::unique_ptr<DatasetReader> makeScanNetSensReader(const std::string& path,
                                                     const DatasetOptions& options) {
  return std::make_unique<ScanNetSensReader>(path, options);
}

}  // namespace internal
}  // namespace panmap
