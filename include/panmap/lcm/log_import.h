#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/convention/pose_convention.h"
#include "panmap/core/pose.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/lcm/conversions.h"

namespace panmap {

/// Options of panmap-import.
struct ImportOptions {
  DatasetOptions dataset;
  ImageEncoding encoding;  ///< JPEG colour + PNG depth unless --raw
  std::string mask_dir;    ///< COCO panoptic PNGs; "" for no PANOPTIC channel
  std::string mask_json;   ///< COCO panoptic JSON; "" for per-frame JSON files
  /// kCocoPanoptic: CocoPanopticReader; kSemantic: greyscale class-id PNGs of a semantic
  /// network, SemanticMaskReader (no mask_json).
  enum class MaskFormat { kCocoPanoptic, kSemantic } mask_format = MaskFormat::kCocoPanoptic;
  std::string label_table;  ///< segmenter -> panmap classes; "" = NYU40 identity
  /// The masks' category ids are the label table's rows counted from 0 in id order (a
  /// network's raw contiguous class indices, LabelTable::contiguous), not its source ids.
  bool contiguous_ids = false;
  /// Masks of another size than their colour image but of its shape (a network run on a
  /// scaled image) are scaled to it, nearest pixel; otherwise such a mask is an error.
  bool resize_masks = false;
  /// What to do with a frame whose pose is invalid: skip it (counted) or stop with an error.
  /// kAuto skips where the layout documents invalid poses (ScanNet) and stops elsewhere.
  enum class InvalidPose { kAuto, kSkip, kError } invalid_pose = InvalidPose::kAuto;
  PoseSource pose_source = PoseSource::kGroundTruth;  ///< recorded in every pose message
  /// Skip a frame whose files cannot be read (corrupt image, mask or pose file) instead of
  /// stopping; each is listed in ImportStats::skipped_bad.
  bool skip_bad = false;
  size_t max_frames = 0;  ///< 0 = all
  /// How the pose file is written, where the user said (panmap-import --pose-convention,
  /// --quaternion-order, --pose-unit); the rest is told from the depth of frame pairs for
  /// pose files the user brings (folder layout, or --poses), see detectPoseConvention.
  PoseConventionChoice pose_convention;
  /// Applied to each recorded pose, in frame order, before it is written (e.g. injected
  /// drift, panmap-import --drift); empty = written as recorded.
  std::function<Eigen::Isometry3d(const Eigen::Isometry3d&)> pose_filter;
  std::string channel_rgbd = "CAMERA_RGBD";
  std::string channel_pose = "CAMERA_POSE";
  std::string channel_panoptic = "PANOPTIC";
};

/// What an import wrote and skipped.
struct ImportStats {
  std::string layout;
  size_t frames_found = 0;
  size_t frames_written = 0;
  size_t poses_written = 0;
  size_t panoptic_written = 0;
  size_t skipped_invalid_pose = 0;
  size_t frames_without_mask = 0;
  size_t unknown_category_segments = 0;
  std::map<int32_t, size_t> unknown_category_ids;  ///< those categories, with their segments
  std::set<int32_t> mask_void_ids;  ///< ids read as no class (MaskReaderStats::void_ids)
  size_t label_table_rows = 0;      ///< rows of the label table the masks used
  /// Mask pixels with an id other than 0, and those of them whose id the segments do not list
  /// (left unlabelled; MaskReaderStats), of which a swap of R and B would have matched.
  size_t mask_pixels = 0;
  size_t unlisted_mask_pixels = 0;
  size_t unlisted_bgr_mask_pixels = 0;
  /// Frames written whose depth image has no valid pixel (they map nothing).
  size_t frames_without_depth = 0;
  size_t masks_found = 0;  ///< mask files in the mask folder (or its COCO JSON)
  /// Masks no imported frame took (their images absent, skipped, or beyond max_frames).
  size_t masks_unused = 0;
  std::string first_unused_mask;  ///< the first of those, by its colour-image stem
  size_t masks_resized = 0;       ///< with resize_masks: masks scaled to their colour image
  size_t unmatched_frames = 0;    ///< e.g. TUM depth without colour in time
  std::string unmatched_what;     ///< what those were (DatasetReader::unmatchedWhat)
  size_t bytes_written = 0;
  std::string first_skip_reason;
  std::vector<std::string> skipped_bad;  ///< with skip_bad: each skipped frame's error
  std::vector<std::string> notes;        ///< what the reader detected (DatasetReader::notes)
  /// How the poses were read, when checked against depth (empty when not checked).
  std::optional<PoseConventionVerdict> pose_convention;
  std::vector<StampedPose> recorded_poses;  ///< every written frame's pose as recorded
  std::vector<StampedPose> written_poses;   ///< as written (differs with a pose_filter)
};

/// One line on the mask pixels whose segment id no segments_info entry lists, naming a BGR
/// PNG when swapping R and B would match most of them.
std::string unlistedMaskPixels(const ImportStats& stats);

/// Reads a dataset folder and writes an LCM log with CAMERA_RGBD, CAMERA_POSE and (with
/// masks) PANOPTIC events, all stamped with the frame's utime. Throws Error naming the file
/// at fault (unless skip_bad); a partial log is removed on failure.
/// @param progress called after each frame with (frames done, frames total)
ImportStats importDataset(const std::string& dataset_dir, const std::string& log_path,
                          const ImportOptions& options,
                          const std::function<void(size_t, size_t)>& progress = {});

}  // namespace panmap
