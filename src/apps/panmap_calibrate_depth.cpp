// panmap-calibrate-depth: learns a depth sensor's fixed-pattern depth error from a recording
// (docs/MAPPING.md, "Depth calibration"), for panmap-mapper --depth-calibration.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_checks.h"

#include "panmap/calibration/depth_calibrator.h"
#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/progress.h"
#include "panmap/io/output_path.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/lcm/offline_mapping.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/mapper.h"

namespace {

// The frames a round learns from, at the poses the mapper used for them or at the log's own.
struct Round {
  std::vector<panmap::CalibrationFrame> frames;
  std::vector<panmap::StampedPose> trajectory;
  int64_t integrated = 0, tracked = 0, corrected = 0;
};

Round mapOnce(const std::string& log, const panmap::MapperConfig& config, int64_t first,
              int64_t last, int every, bool at_given_poses, bool quiet) {
  panmap::Mapper mapper(config);
  panmap::SessionOptions options;
  Round round;
  int64_t index = 0;
  auto hook = [&](const panmap::SyncedFrame& f, const panmap::FrameStats& stats) {
    ++round.integrated;
    round.tracked += stats.tracked;
    round.corrected += stats.tracked && !stats.pose_kept &&
                       (stats.tracking_status == panmap::AlignmentStatus::kAccepted ||
                        stats.tracking_status == panmap::AlignmentStatus::kAcceptedPartially);
    panmap::StampedPose pose;
    pose.utime = f.frame.utime;
    pose.T_W_C = stats.T_W_C;
    round.trajectory.push_back(pose);
    const int64_t i = index++;
    if (i < first || (last >= 0 && i > last) || (i - first) % every != 0) return;
    panmap::CalibrationFrame c;
    c.camera = f.frame.camera;
    c.depth_scale_m = f.frame.depth_scale_m;
    c.depth = f.frame.depth;  // as read: the mapper corrected its own copy
    c.T_W_C = at_given_poses ? f.T_W_C : stats.T_W_C;
    round.frames.push_back(std::move(c));
  };
  // The shared line: in place on a terminal, every 10 % in a log, nothing for an empty log.
  panmap::ProgressLine line("  mapping", "MiB", !quiet);
  auto progress = [&](size_t done, size_t total) {
    line.setNote(std::to_string(round.integrated) + " frames");
    line.update(done >> 20, total >> 20);
  };
  panmap::mapLog(log, options, &mapper, progress, hook);
  line.finish();
  return round;
}

}  // namespace

int main(int argc, char** argv) {
  panmap::applyMemoryPolicy(argv);  // panmap-mapper's allocation policy
  CLI::App app{
      "Learns a depth sensor's fixed-pattern depth error from an LCM log of its frames and "
      "poses, and writes it for panmap-mapper --depth-calibration. The first round learns "
      "from the frames at the log's poses as given (poses refined against a map of "
      "uncalibrated depth take up part of its error); each next round maps the log again with "
      "the calibration so far (geometry only; poses refined as --tracking says) and learns "
      "from the frames at the poses it used, so refined poses and calibration improve "
      "together. Calibrate once per sensor, from a recording that sees surfaces from many "
      "viewpoints at the depths you map at (docs/MAPPING.md)."};
  std::string log_path, out_path, config_path, tracking = "auto", trajectory_out;
  int rounds = 3, every = 1, threads = 2;
  int64_t first = 0, last = -1;
  float voxel_m = 0.02f;
  bool quiet = false;
  panmap::DepthCalibrator::Config cal;
  app.add_option("--log", log_path, "LCM log to learn from (as panmap-mapper --log reads it)")
      ->required();
  app.add_option("--out", out_path, "calibration file to write (JSON)")->required();
  app.add_option("--config", config_path, "mapper YAML config for the mapping rounds");
  app.add_option("--tracking", tracking,
                 "refine the log's poses while mapping: off, auto (poses flagged SLAM or "
                 "odometry), on")
      ->check(CLI::IsMember({"off", "auto", "on"}))
      ->capture_default_str();
  app.add_option("--rounds", rounds, "map-then-calibrate rounds (1 when poses are not refined)")
      ->check(panmap::cli::positive())
      ->capture_default_str();
  app.add_option("--voxel-size", voxel_m, "voxel edge of the mapping rounds, metres")
      ->capture_default_str();
  app.add_option("--first", first, "first frame (0-based, in log order) to learn from")
      ->check(panmap::cli::nonNegative())
      ->capture_default_str();
  app.add_option("--last", last, "last frame to learn from (-1: the log's last)")
      ->capture_default_str();
  app.add_option("--every", every, "learn from every Nth frame (memory: 0.6 MB per 640x480 frame)")
      ->check(panmap::cli::positive())
      ->capture_default_str();
  app.add_option("--cells", cal.cells_x,
                 "image cells across (down: as many as the image's "
                 "aspect ratio gives)")
      ->capture_default_str();
  app.add_option("--passes", cal.passes, "map-and-measure passes per round")->capture_default_str();
  app.add_option("--calibration-voxel-size", cal.voxel_size_m,
                 "voxel edge of the maps the frames are compared with, metres")
      ->capture_default_str();
  app.add_option("--threads", threads, "threads")->capture_default_str();
  app.add_option("--trajectory-out", trajectory_out,
                 "also write the last round's poses (TUM) to this file");
  app.add_flag("-q,--quiet", quiet, "no progress lines");
  CLI11_PARSE(app, argc, argv);

  try {
    cal.check();
    // Fail before the work, not after it.
    if (last < -1 || (last >= 0 && last < first)) {
      throw panmap::Error("--last " + std::to_string(last) + ": not -1 (the log's last) and not " +
                          "at or after --first " + std::to_string(first));
    }
    panmap::checkOutputFile(out_path, "--out");
    if (!trajectory_out.empty()) panmap::checkOutputFile(trajectory_out, "--trajectory-out");
    panmap::MapperConfig config;
    if (!config_path.empty()) config = panmap::loadConfig(config_path).mapper;
    config.map.voxel_size_m = voxel_m;
    config.num_threads = threads;
    config.fusion.geometry_only = true;
    config.occupancy_enabled = false;
    config.depth_calibration.reset();
    config.depth_calibration_file.clear();
    if (tracking == "off") config.tracking_mode = panmap::MapperConfig::TrackingMode::kOff;
    if (tracking == "auto") config.tracking_mode = panmap::MapperConfig::TrackingMode::kAuto;
    if (tracking == "on") config.tracking_mode = panmap::MapperConfig::TrackingMode::kOn;
    // The depth check of auto tracking would keep every pose of an uncalibrated sensor as
    // given; the rounds refine poses and calibration together, which is the remedy it asks for.
    config.depth_check.frames = 0;
    config.check();
    panmap::ThreadPool pool(threads);
    std::shared_ptr<const panmap::DepthCalibration> calibration;
    Round round;
    for (int r = 1; r <= rounds; ++r) {
      if (!quiet) std::fprintf(stderr, "round %d/%d\n", r, rounds);
      config.depth_calibration = calibration;
      // Poses refined without a calibration carry part of the sensor's pattern, which the
      // calibration learnt at them then misses (a known pattern on rendered depth: refined
      // poses 0.96 cm from the truth with it, 0.54 cm when learnt at the given poses first;
      // docs/MAPPING.md); the log's own poses carry errors unrelated to the pattern.
      round = mapOnce(log_path, config, first, last, every, /*at_given_poses=*/r == 1, quiet);
      if (round.frames.empty()) {
        throw panmap::Error("no frames to learn from in " + log_path + " (frames " +
                            std::to_string(first) + " to " +
                            (last < 0 ? std::string("the end") : std::to_string(last)) + ")");
      }
      // Square cells: as many down as the image's aspect ratio gives.
      const panmap::PinholeCamera& camera = round.frames.front().camera;
      cal.cells_y = std::max(
          1, static_cast<int>(
                 std::lround(cal.cells_x * static_cast<double>(camera.height) / camera.width)));
      const panmap::DepthCalibrator calibrator(cal);
      std::vector<panmap::CalibrationPass> passes;
      panmap::ProgressLine line("  calibrating", "passes", !quiet);
      calibration = std::make_shared<const panmap::DepthCalibration>(
          calibrator.calibrate(round.frames, &pool, &passes, [&](int done, int total) {
            line.update(static_cast<size_t>(done), static_cast<size_t>(total));
          }));
      line.finish();
      std::printf(
          "round %d: %lld frames mapped (%lld tracked, %lld corrected), %zu learnt from; depth "
          "disagreement %.2f mm RMS before, calibration %.2f mm RMS\n",
          r, static_cast<long long>(round.integrated), static_cast<long long>(round.tracked),
          static_cast<long long>(round.corrected), round.frames.size(),
          passes.front().rms_residual_m * 1e3, calibration->rmsOffsetM() * 1e3);
      if (round.tracked == 0 && r < rounds) {
        std::printf(
            "poses are not refined (tracking %s or poses flagged ground truth): the "
            "next rounds would learn the same, stopping\n",
            tracking.c_str());
        break;
      }
    }
    calibration->save(out_path);
    if (!trajectory_out.empty()) panmap::writeTumTrajectory(trajectory_out, round.trajectory);
    std::printf("wrote %s (%dx%d images, %dx%d cells, %d knots every %.2f m)\n", out_path.c_str(),
                calibration->width(), calibration->height(), calibration->cellsX(),
                calibration->cellsY(), calibration->knots(), calibration->knotSpacingM());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-calibrate-depth: %s\n", e.what());
    return 1;
  }
}
