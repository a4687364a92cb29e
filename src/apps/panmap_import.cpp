// panmap-import: a dataset folder (7-Scenes, ScanNet export, TUM RGB-D, a generic rgb/ +
// depth/ folder) or a ScanNet .sens file -> an LCM log.
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include <CLI/CLI.hpp>

#include "cli_checks.h"

#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/progress.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/lcm/channels.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/log_import.h"
#include "panmap/lcm/log_writer.h"
#include "panmap/sim/pose_drift.h"

namespace {

// "fx,fy,cx,cy"; anything else is taken as a file name.
std::optional<Eigen::Vector4d> parseIntrinsics(const std::string& text) {
  std::istringstream in(text);
  Eigen::Vector4d k;
  char c1 = 0, c2 = 0, c3 = 0;
  if (!(in >> k(0) >> c1 >> k(1) >> c2 >> k(2) >> c3 >> k(3)) || c1 != ',' || c2 != ',' ||
      c3 != ',' || !(in >> std::ws).eof()) {
    return std::nullopt;
  }
  return k;
}

}  // namespace

int main(int argc, char** argv) {
  panmap::applyMemoryPolicy(argv);  // panmap-mapper's allocation policy
  CLI::App app{
      "Import an RGB-D dataset folder into an LCM log (channels CAMERA_RGBD, CAMERA_POSE and, "
      "with --masks, PANOPTIC).\nLayouts: 7scenes (frame-XXXXXX.{color.jpg,depth.png,pose.txt} "
      "+ camera-intrinsics.txt), scannet (SensReader export: color/, depth/, pose/, "
      "intrinsic/), scannet-sens (a ScanNet .sens file, or a scan's folder holding one, read "
      "without exporting it), tum (rgb.txt, depth.txt, groundtruth.txt), folder (rgb/ or color/ "
      "and "
      "depth/ images, an intrinsics file such as intrinsic.txt, a pose file such as "
      "gt_pose.txt or a pose/ folder; README, panmap-import)."};
  std::string dataset_dir, log_path, layout = "auto", intrinsics, registration = "reproject";
  std::string invalid_poses = "auto", pose_source = "gt", drift, reference_path;
  std::string pairing = "auto";
  double depth_scale = 0.0;
  uint64_t drift_seed = 1;
  panmap::ImportOptions options;
  bool raw = false, quiet = false;
  app.add_option("dataset", dataset_dir, "dataset folder, or a ScanNet .sens file")->required();
  app.add_option("output", log_path, "LCM log to write (.lcmlog)")->required();
  app.add_option("--layout", layout, "auto, 7scenes, scannet, scannet-sens, tum or folder")
      ->capture_default_str();
  app.add_option("--masks", options.mask_dir,
                 "folder of masks, one PNG per colour image named after it: COCO panoptic "
                 "(segment id = R + 256 G + 65536 B) or, with --masks-format semantic, class ids");
  std::string mask_format = "panoptic";
  app.add_option("--masks-format", mask_format,
                 "panoptic (COCO panoptic PNG + JSON) or semantic (greyscale PNG of class ids "
                 "from a network without instances: each stuff class one segment, each "
                 "connected region of a thing class one instance)")
      ->check(CLI::IsMember({"panoptic", "semantic"}))
      ->capture_default_str();
  app.add_option("--masks-json", options.mask_json,
                 "COCO panoptic JSON for --masks (default: <stem>.json beside each PNG)");
  app.add_option("--label-table", options.label_table,
                 "segmenter category -> NYU40 class table (default: NYU40 identity)");
  app.add_flag("--contiguous-ids", options.contiguous_ids,
               "the masks' category ids are a network's raw class indices (0 to N-1, the label "
               "table's rows in id order), as Mask2Former, OneFormer and Hugging Face "
               "transformers give them; not for Panoptic FPN's separate thing and stuff indices");
  app.add_flag("--resize-masks", options.resize_masks,
               "scale masks of another size than their colour image, but of its shape, to it "
               "(nearest pixel): a network run on a scaled image");
  app.add_flag("--raw", raw, "store images raw instead of JPEG colour + PNG depth");
  app.add_option("--jpeg-quality", options.encoding.jpeg_quality,
                 "quality when colour must be re-encoded")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--intrinsics", intrinsics,
                 "the depth camera: fx,fy,cx,cy (pixels) or a file with a 3x3 or 4x4 matrix or "
                 "'fx fy cx cy'");
  app.add_option("--poses", options.dataset.poses_path,
                 "folder and tum layouts: camera-to-world poses, a TUM file, a matrix per line "
                 "(12 or 16 numbers), stacked 4x4 matrices, or a folder of per-frame 4x4 files");
  std::string pose_convention = "auto", quaternion_order = "auto", pose_unit = "auto";
  app.add_option("--pose-convention", pose_convention,
                 "how the pose file is written: camera-to-world, world-to-camera, or auto (told "
                 "from the depth of frame pairs, for pose files of the folder layout or --poses)")
      ->check(CLI::IsMember({"auto", "camera-to-world", "world-to-camera"}))
      ->capture_default_str();
  app.add_option("--quaternion-order", quaternion_order,
                 "a TUM-style pose file's quaternion: xyzw (TUM's 'qx qy qz qw'), wxyz, or auto")
      ->check(CLI::IsMember({"auto", "xyzw", "wxyz"}))
      ->capture_default_str();
  app.add_option("--pose-unit", pose_unit, "the pose file's translations: m, cm, mm, or auto")
      ->check(CLI::IsMember({"auto", "m", "cm", "mm"}))
      ->capture_default_str();
  std::string camera_frame = "auto";
  app.add_option("--camera-frame", camera_frame,
                 "the frame the poses are of: optical (x right, y down, z forward), body (ROS's "
                 "camera_link: x forward, y left, z up), or auto")
      ->check(CLI::IsMember({"auto", "optical", "body"}))
      ->capture_default_str();
  app.add_option("--depth-scale", depth_scale,
                 "metres per depth unit (e.g. 0.001 for mm); default: the layout's convention, "
                 "for the folder layout detected from the values (mm or 1/5000 m)")
      ->check(panmap::cli::positive());
  app.add_option("--pairing", pairing,
                 "folder layout, colour to depth: auto, name (frame number or file name, else "
                 "sorted position) or time (file names are timestamps)")
      ->check(CLI::IsMember({"auto", "name", "time"}))
      ->capture_default_str();
  app.add_flag("--skip-bad", options.skip_bad,
               "skip frames whose files cannot be read (listed, and counted) instead of stopping");
  double max_pose_gap_ms = 200.0;
  app.add_option("--max-pose-gap-ms", max_pose_gap_ms,
                 "timed poses: a frame between two poses at most this far apart takes their "
                 "interpolation (a SLAM system's keyframes); otherwise it needs a pose within "
                 "20 ms")
      ->check(panmap::cli::nonNegative())
      ->capture_default_str();
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
  app.add_option("--max-frames", options.max_frames, "import at most N frames (0 = all)")
      ->check(panmap::cli::nonNegative());
  auto* drift_option = app.add_option(
      "--drift", drift,
      "inject SLAM-like drift into the recorded poses: light (1 %/m, 0.5 deg/m), heavy (3x), "
      "slam, slam-hard or gt (docs/SIMULATION.md); poses are flagged slam unless "
      "--pose-source says otherwise, the recorded ones are written as the reference");
  app.add_option("--seed", drift_seed, "seed of the injected drift")
      ->check(panmap::cli::nonNegative())
      ->needs(drift_option)
      ->capture_default_str();
  size_t correction_every = 0;
  app.add_option("--correction-every", correction_every,
                 "with --drift: end the log with the loop-closure correction a SLAM back-end "
                 "would publish on PANMAP_POSE_CORRECTION: the recorded poses of every Nth frame "
                 "(keyframes) and of the last one (docs/LOOP_CLOSURE.md)")
      ->needs(drift_option)
      ->check(panmap::cli::positive());
  app.add_option("--reference", reference_path,
                 "with --drift: TUM file for the recorded poses (default: LOG minus .lcmlog + "
                 ".reference.txt); the drifted ones go to .input.txt beside it")
      ->needs(drift_option);
  app.add_flag("-q,--quiet", quiet, "no progress line");
  CLI11_PARSE(app, argc, argv);

  try {
    options.dataset.layout = panmap::parseDatasetLayout(layout);
    options.mask_format = mask_format == "semantic"
                              ? panmap::ImportOptions::MaskFormat::kSemantic
                              : panmap::ImportOptions::MaskFormat::kCocoPanoptic;
    if (!intrinsics.empty()) {
      options.dataset.intrinsics = parseIntrinsics(intrinsics);
      if (!options.dataset.intrinsics) options.dataset.intrinsics_file = intrinsics;
    }
    if (depth_scale > 0.0) options.dataset.depth_scale_m = depth_scale;
    options.dataset.max_pose_gap_s = max_pose_gap_ms * 1e-3;
    if (pose_convention != "auto") {
      options.pose_convention.inverted = pose_convention == "world-to-camera";
    }
    if (quaternion_order != "auto") {
      options.pose_convention.scalar_moved = quaternion_order == "wxyz";
    }
    if (camera_frame != "auto") options.pose_convention.body_frame = camera_frame == "body";
    if (pose_unit != "auto") {
      options.pose_convention.translation_scale = pose_unit == "m"    ? 1.0
                                                  : pose_unit == "cm" ? 0.01
                                                                      : 0.001;
    }
    options.dataset.pairing = pairing == "name"   ? panmap::FramePairing::kName
                              : pairing == "time" ? panmap::FramePairing::kTime
                                                  : panmap::FramePairing::kAuto;
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
    for (const std::string& note : s.notes) std::printf("%s\n", note.c_str());
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
    if (correction_every > 0 && !s.recorded_poses.empty()) {
      const panmap::PoseCorrection correction =
          panmap::keyframeCorrection(s.recorded_poses, correction_every);
      panmap::LogWriter writer(log_path, /*append=*/true);
      writer.write(panmap::kChannelPoseCorrection, correction.utime, panmap::toMessage(correction));
      std::printf("correction 1 on %s: recorded poses of %zu keyframes (every %zu frames)\n",
                  panmap::kChannelPoseCorrection, correction.poses.size(), correction_every);
    }
    if (s.skipped_invalid_pose) {
      std::printf("skipped %zu frames with invalid poses (first: %s)\n", s.skipped_invalid_pose,
                  s.first_skip_reason.c_str());
    }
    if (!s.skipped_bad.empty()) {
      const std::string list_path = log_path + ".skipped.txt";
      std::ofstream list(list_path);
      for (const std::string& why : s.skipped_bad) list << why << "\n";
      std::printf("skipped %zu bad frames (--skip-bad), listed in %s:\n", s.skipped_bad.size(),
                  list_path.c_str());
      constexpr size_t kShown = 10;
      for (size_t i = 0; i < std::min(kShown, s.skipped_bad.size()); ++i) {
        std::printf("  %s\n", s.skipped_bad[i].c_str());
      }
      if (s.skipped_bad.size() > kShown) {
        std::printf("  ... and %zu more\n", s.skipped_bad.size() - kShown);
      }
    }
    if (s.frames_without_depth) {
      std::printf("%zu frames have no valid depth (every pixel 0): they map nothing\n",
                  s.frames_without_depth);
    }
    if (s.unmatched_frames) {
      std::printf("dropped %zu %s\n", s.unmatched_frames, s.unmatched_what.c_str());
    }
    if (!options.mask_dir.empty()) {
      std::printf(
          "%zu frames without a mask; %zu segments of categories unknown to the label "
          "table (class 0)\n",
          s.frames_without_mask, s.unknown_category_segments);
      if (s.masks_unused > 0) {
        std::printf("%zu of %zu masks matched no imported frame (first: %s)\n", s.masks_unused,
                    s.masks_found, s.first_unused_mask.c_str());
      }
      if (s.unlisted_mask_pixels > 0) {
        std::printf("warning: %s\n", panmap::unlistedMaskPixels(s).c_str());
      }
      if (!s.mask_void_ids.empty()) {
        std::string ids;
        for (int32_t id : s.mask_void_ids) ids += (ids.empty() ? "" : ", ") + std::to_string(id);
        std::printf("mask pixels of id %s (not in the label table) read as no class\n",
                    ids.c_str());
      }
      if (s.masks_resized > 0) {
        std::printf("%zu masks scaled to their colour image\n", s.masks_resized);
      }
      if (!s.unknown_category_ids.empty()) {
        std::string list;
        size_t shown = 0;
        bool all_row_indices = true;  // every unknown id could be a row counted from 0
        for (const auto& [id, segments] : s.unknown_category_ids) {
          all_row_indices =
              all_row_indices && id >= 0 && static_cast<size_t>(id) < s.label_table_rows;
          if (shown++ < 8) {
            list += (list.empty() ? "" : ", ") + std::to_string(id) + " (" +
                    std::to_string(segments) + ")";
          }
        }
        if (s.unknown_category_ids.size() > 8) list += ", ...";
        std::printf("  unknown categories (segments): %s\n", list.c_str());
        // Raw network output counts classes from 0: then every unknown id is a row index.
        if (all_row_indices && !options.contiguous_ids) {
          std::printf(
              "  if the masks number categories from 0 as a network's raw output does, import "
              "again with --contiguous-ids\n");
        }
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-import: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
