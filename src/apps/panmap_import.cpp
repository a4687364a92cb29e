// panmap-import: a dataset folder (7-Scenes, ScanNet export, TUM RGB-D) -> an LCM log.
#include <cstdio>
#include <memory>
#include <sstream>

#include <CLI/CLI.hpp>

#include "panmap/core/error.h"
#include "panmap/core/progress.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/lcm/log_import.h"
#include "panmap/sim/pose_drift.h"

namespace {

Eigen::Vector4d parseIntrinsics(const std::string& text) {
  std::istringstream in(text);
  Eigen::Vector4d k;
  char comma = 0;
  if (!(in >> k(0) >> comma >> k(1) >> comma >> k(2) >> comma >> k(3))) {
    throw panmap::Error("--intrinsics must be fx,fy,cx,cy");
  }
  return k;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Import an RGB-D dataset folder into an LCM log (channels CAMERA_RGBD, CAMERA_POSE and, "
      "with --masks, PANOPTIC).\nLayouts: 7scenes (frame-XXXXXX.{color.jpg,depth.png,pose.txt} "
      "+ camera-intrinsics.txt), scannet (SensReader export), tum (rgb.txt, depth.txt, "
      "groundtruth.txt)."};
  std::string dataset_dir, log_path, layout = "auto", intrinsics, registration = "reproject";
  std::string invalid_poses = "auto", pose_source = "gt", drift, reference_path;
  uint64_t drift_seed = 1;
  panmap::ImportOptions options;
  bool raw = false, quiet = false;
  app.add_option("dataset", dataset_dir, "dataset folder")->required();
  app.add_option("output", log_path, "LCM log to write (.lcmlog)")->required();
  app.add_option("--layout", layout, "auto, 7scenes, scannet or tum")->capture_default_str();
  app.add_option("--masks", options.mask_dir,
                 "folder of COCO panoptic PNGs (segment id = R + 256 G + 65536 B)");
  app.add_option("--masks-json", options.mask_json,
                 "COCO panoptic JSON for --masks (default: <stem>.json beside each PNG)");
  app.add_option("--label-table", options.label_table,
                 "segmenter category -> NYU40 class table (default: NYU40 identity)");
  app.add_flag("--raw", raw, "store images raw instead of JPEG colour + PNG depth");
  app.add_option("--jpeg-quality", options.encoding.jpeg_quality,
                 "quality when colour must be re-encoded")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--intrinsics", intrinsics, "override the depth camera: fx,fy,cx,cy (pixels)");
  app.add_option("--rate", options.dataset.frame_rate_hz,
                 "frame rate of datasets without timestamps, Hz")
      ->capture_default_str();
  app.add_option("--registration", registration,
                 "ScanNet colour-to-depth registration: reproject or resize")
      ->check(CLI::IsMember({"reproject", "resize"}))
      ->capture_default_str();
  app.add_option("--invalid-poses", invalid_poses,
                 "frames with invalid poses: skip (counted), error, or auto (skip for ScanNet)")
      ->check(CLI::IsMember({"auto", "skip", "error"}))
      ->capture_default_str();
  app.add_option("--pose-source", pose_source, "recorded pose source: gt, slam, odometry, unknown")
      ->check(CLI::IsMember({"gt", "slam", "odometry", "unknown"}))
      ->capture_default_str();
  app.add_option("--max-frames", options.max_frames, "import at most N frames (0 = all)");
  auto* drift_option = app.add_option(
      "--drift", drift,
      "inject SLAM-like drift into the recorded poses: light (1 %/m, 0.5 deg/m), heavy (3x), "
      "slam, slam-hard or gt (docs/SIMULATION.md); poses are flagged slam unless "
      "--pose-source says otherwise, the recorded ones are written as the reference");
  app.add_option("--seed", drift_seed, "seed of the injected drift")
      ->needs(drift_option)
      ->capture_default_str();
  app.add_option("--reference", reference_path,
                 "with --drift: TUM file for the recorded poses (default: LOG minus .lcmlog + "
                 ".reference.txt); the drifted ones go to .input.txt beside it")
      ->needs(drift_option);
  app.add_flag("-q,--quiet", quiet, "no progress line");
  CLI11_PARSE(app, argc, argv);

  try {
    options.dataset.layout = panmap::parseDatasetLayout(layout);
    if (!intrinsics.empty()) options.dataset.intrinsics = parseIntrinsics(intrinsics);
    options.dataset.registration = registration == "resize" ? panmap::ColorRegistration::kResize
                                                            : panmap::ColorRegistration::kReproject;
    using IP = panmap::ImportOptions::InvalidPose;
    options.invalid_pose = invalid_poses == "skip"    ? IP::kSkip
                           : invalid_poses == "error" ? IP::kError
                                                      : IP::kAuto;
    options.pose_source = pose_source == "gt"         ? panmap::PoseSource::kGroundTruth
                          : pose_source == "slam"     ? panmap::PoseSource::kSlam
                          : pose_source == "odometry" ? panmap::PoseSource::kOdometry
                                                      : panmap::PoseSource::kUnknown;
    std::string input_path;
    if (!drift.empty()) {
      const panmap::PoseDriftConfig drift_config = panmap::PoseDriftConfig::fromPreset(drift);
      auto model = std::make_shared<panmap::PoseDrift>(drift_config, drift_seed);
      options.pose_filter = [model](const Eigen::Isometry3d& T_W_C) { return model->next(T_W_C); };
      if (app.count("--pose-source") == 0) options.pose_source = panmap::PoseSource::kSlam;
      std::string stem = log_path;
      const std::string suffix = ".lcmlog";
      if (stem.size() > suffix.size() &&
          stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0) {
        stem.resize(stem.size() - suffix.size());
      }
      if (reference_path.empty()) reference_path = stem + ".reference.txt";
      input_path = stem + ".input.txt";
      if (reference_path == input_path) input_path = reference_path + ".input.txt";
    }
    if (raw) {
      options.encoding.color = panmap::image_t::COMPRESSION_NONE;
      options.encoding.depth = panmap::image_t::COMPRESSION_NONE;
      options.encoding.labels = panmap::image_t::COMPRESSION_NONE;
    }
    panmap::ProgressLine progress("import", "frames", !quiet);
    const panmap::ImportStats s =
        panmap::importDataset(dataset_dir, log_path, options,
                              [&](size_t done, size_t total) { progress.update(done, total); });
    progress.finish();
    std::printf("wrote %s (%s layout): %zu frames, %zu poses, %zu panoptic, %.1f MB\n",
                log_path.c_str(), s.layout.c_str(), s.frames_written, s.poses_written,
                s.panoptic_written, s.bytes_written / 1e6);
    if (!drift.empty()) {
      panmap::writeTumTrajectory(reference_path, s.recorded_poses);
      panmap::writeTumTrajectory(input_path, s.written_poses);
      std::printf("drift %s, seed %llu: recorded poses -> %s, drifted -> %s\n", drift.c_str(),
                  static_cast<unsigned long long>(drift_seed), reference_path.c_str(),
                  input_path.c_str());
    }
    if (s.skipped_invalid_pose) {
      std::printf("skipped %zu frames with invalid poses (first: %s)\n", s.skipped_invalid_pose,
                  s.first_skip_reason.c_str());
    }
    if (s.unmatched_frames) {
      std::printf("dropped %zu depth images without a colour image in time\n", s.unmatched_frames);
    }
    if (!options.mask_dir.empty()) {
      std::printf(
          "%zu frames without a mask; %zu segments of categories unknown to the label "
          "table (class 0)\n",
          s.frames_without_mask, s.unknown_category_segments);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-import: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
