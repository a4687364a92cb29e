#include "panmap/lcm/log_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "panmap/core/error.h"
#include "panmap/io/coco_panoptic_reader.h"
#include "panmap/io/opencv_image.h"
#include "panmap/io/semantic_mask_reader.h"
#include "panmap/io/text_files.h"
#include "panmap/lcm/log_writer.h"

namespace panmap {

namespace {

// A mask of its colour image's size is kept. One of the same shape (within 1 %: a network run
// on a scaled image, its output not scaled back) is scaled to it with `resize`, each pixel
// taking the label under its centre; otherwise, or without `resize`, the sizes are an error.
// Returns whether the mask was scaled.
bool fitMaskToColour(LabelImage* mask, const DatasetFrame& frame, bool resize,
                     const std::string& what) {
  const int w = frame.color_source_width, h = frame.color_source_height;
  if (mask->width() == w && mask->height() == h) return false;
  std::ostringstream msg;
  msg << what << ": mask is " << mask->width() << "x" << mask->height()
      << " but its colour image is " << w << "x" << h;
  const double shape =
      static_cast<double>(mask->width()) * h / (static_cast<double>(w) * mask->height());
  if (std::abs(shape - 1.0) > 0.01) {
    msg << " (another shape: have the network's post-processing return masks at the image's "
           "size)";
    throw Error(msg.str());
  }
  if (!resize) {
    msg << " (--resize-masks scales such masks to the image)";
    throw Error(msg.str());
  }
  cv::Mat scaled;
  cv::resize(asMat(*mask), scaled, cv::Size(w, h), 0, 0, cv::INTER_NEAREST_EXACT);
  *mask = labelsFromMat(scaled);
  return true;
}

// How the user's pose file is written, from the depth of frame pairs: 8 frames spread over the
// import, each with partners 3, 10 and 30 frames later (0.1 to 1 s at 30 Hz), so that some
// pairs see the camera move while still overlapping. Frames that cannot be read or have no pose
// are left out here; the import itself reports them.
PoseConventionVerdict checkPoseConvention(const DatasetReader& reader, size_t total,
                                          const PoseConventionChoice& fixed) {
  constexpr size_t kBases = 8;
  constexpr size_t kGaps[] = {3, 10, 30};
  std::map<size_t, int> sample_of;
  std::vector<PoseSample> samples;
  auto sampleOf = [&](size_t index) {
    const auto found = sample_of.find(index);
    if (found != sample_of.end()) return found->second;
    int sample = -1;
    try {
      DatasetFrame frame = reader.read(index);
      if (frame.T_W_C) {
        frame.rgbd.color = ColorImage();
        samples.push_back(PoseSample{std::move(frame.rgbd), *frame.T_W_C});
        sample = static_cast<int>(samples.size()) - 1;
      }
    } catch (const Error&) {
    }
    sample_of.emplace(index, sample);
    return sample;
  };
  std::vector<std::pair<int, int>> pairs;
  for (size_t b = 0; b < kBases; ++b) {
    const size_t base = b * total / kBases;
    for (const size_t gap : kGaps) {
      if (base + gap >= total) continue;
      const int first = sampleOf(base), second = sampleOf(base + gap);
      if (first >= 0 && second >= 0) pairs.emplace_back(first, second);
    }
  }
  return detectPoseConvention(
      samples, pairs,
      reader.posesAreQuaternions() ? QuaternionInput::kScalarLast : QuaternionInput::kNone, fixed);
}

}  // namespace

std::string unlistedMaskPixels(const ImportStats& stats) {
  const auto percent = [](size_t part, size_t whole) {
    char text[16];
    std::snprintf(text, sizeof(text), "%.1f %%", whole ? 100.0 * part / whole : 0.0);
    return std::string(text);
  };
  std::string text = "masks: " + percent(stats.unlisted_mask_pixels, stats.mask_pixels) +
                     " of the pixels with a segment id carry an id their segments_info does "
                     "not list (left unlabelled)";
  if (2 * stats.unlisted_bgr_mask_pixels > stats.unlisted_mask_pixels) {
    text += "; with R and B swapped " +
            percent(stats.unlisted_bgr_mask_pixels, stats.unlisted_mask_pixels) +
            " of them would match: the PNGs look written as BGR (cv2.imwrite of an RGB array; "
            "cv2.cvtColor(ids_rgb, cv2.COLOR_RGB2BGR) before writing)";
  }
  return text;
}

ImportStats importDataset(const std::string& dataset_dir, const std::string& log_path,
                          const ImportOptions& options,
                          const std::function<void(size_t, size_t)>& progress) {
  const std::unique_ptr<DatasetReader> reader = openDataset(dataset_dir, options.dataset);
  std::unique_ptr<MaskReader> masks;
  size_t stats_table_rows = 0;
  if (!options.mask_dir.empty()) {
    LabelTable table = options.label_table.empty() ? LabelTable::nyu40Identity()
                                                   : LabelTable::load(options.label_table);
    if (options.contiguous_ids) table = table.contiguous();
    stats_table_rows = table.size();
    if (options.mask_format == ImportOptions::MaskFormat::kSemantic) {
      if (!options.mask_json.empty()) {
        throw Error("semantic masks have no JSON (" + options.mask_json + ")");
      }
      masks = std::make_unique<SemanticMaskReader>(options.mask_dir, std::move(table));
    } else {
      masks = std::make_unique<CocoPanopticReader>(options.mask_dir, options.mask_json,
                                                   std::move(table));
    }
  }
  bool skip_invalid = reader->invalidPosesExpected();
  if (options.invalid_pose == ImportOptions::InvalidPose::kSkip) skip_invalid = true;
  if (options.invalid_pose == ImportOptions::InvalidPose::kError) skip_invalid = false;

  ImportStats stats;
  stats.label_table_rows = stats_table_rows;
  stats.layout = reader->layoutName();
  stats.frames_found = reader->size();
  stats.unmatched_frames = reader->unmatchedFrames();
  if (stats.unmatched_frames) stats.unmatched_what = reader->unmatchedWhat();
  stats.notes = reader->notes();
  const size_t total =
      options.max_frames ? std::min(options.max_frames, reader->size()) : reader->size();
  // Pose files the user brings are checked against depth; a dataset's own follow its documented
  // convention unless the user says otherwise.
  const PoseConventionChoice& fixed = options.pose_convention;
  const bool user_poses = stats.layout == "folder" || !options.dataset.poses_path.empty();
  PoseConvention convention;
  if (user_poses) {
    stats.pose_convention = checkPoseConvention(*reader, total, fixed);
    convention = stats.pose_convention->convention;
    stats.notes.push_back(stats.pose_convention->note);
  } else {
    convention.translation_scale = fixed.translation_scale.value_or(1.0);
    convention.scalar_moved = fixed.scalar_moved.value_or(false);
    convention.inverted = fixed.inverted.value_or(false);
    convention.body_frame = fixed.body_frame.value_or(false);
    if (reader->posesAreQuaternions()) convention.quaternions = QuaternionInput::kScalarLast;
  }

  // Write beside the target and rename at the end: a failed import leaves no partial log.
  const std::string partial = log_path + ".partial";
  try {
    LogWriter writer(partial);
    int64_t last_utime = INT64_MIN;
    std::set<std::string> used_masks;  // colour stems whose mask a frame took
    std::string first_color_stem;
    for (size_t i = 0; i < total; ++i) {
      // Everything that reads a file comes first, so a bad frame is skipped whole.
      DatasetFrame frame;
      std::optional<PanopticFrame> panoptic;
      try {
        frame = reader->read(i);
        if (frame.T_W_C && masks && masks->has(frame.color_stem)) {
          panoptic = masks->read(frame.color_stem);
          used_masks.insert(frame.color_stem);
          const std::string what = "mask of " + frame.color_stem;
          if (fitMaskToColour(&panoptic->segment_ids, frame, options.resize_masks, what)) {
            ++stats.masks_resized;
          }
          panoptic->segment_ids = registerLabelsToDepth(panoptic->segment_ids, frame, what);
        }
      } catch (const Error& e) {
        if (!options.skip_bad) throw;
        stats.skipped_bad.push_back(e.what());
        if (progress) progress(i + 1, total);
        continue;
      }
      if (!frame.T_W_C) {
        if (!skip_invalid) {
          throw Error(frame.pose_problem +
                      " (to leave such frames out: panmap-import --invalid-poses skip)");
        }
        if (stats.first_skip_reason.empty()) stats.first_skip_reason = frame.pose_problem;
        ++stats.skipped_invalid_pose;
        if (progress) progress(i + 1, total);
        continue;
      }
      if (first_color_stem.empty()) first_color_stem = frame.color_stem;
      if (frame.rgbd.utime <= last_utime) {
        throw Error("frame " + std::to_string(frame.rgbd.frame_id) +
                    ": timestamps are not increasing");
      }
      last_utime = frame.rgbd.utime;
      const int64_t utime = frame.rgbd.utime;

      const DepthImage& depth = frame.rgbd.depth;
      if (std::all_of(depth.data(), depth.data() + depth.size(),
                      [](uint16_t d) { return d == 0; })) {
        ++stats.frames_without_depth;
      }
      writer.write(options.channel_rgbd, utime,
                   toMessage(frame.rgbd, options.encoding, &frame.color_jpeg, &frame.depth_png));
      ++stats.frames_written;

      StampedPose pose;
      pose.utime = utime;
      pose.frame_id = frame.rgbd.frame_id;
      pose.T_W_C = convention.isIdentity() ? *frame.T_W_C : convention.apply(*frame.T_W_C);
      pose.source = options.pose_source;
      stats.recorded_poses.push_back(pose);
      if (options.pose_filter) pose.T_W_C = options.pose_filter(pose.T_W_C);
      stats.written_poses.push_back(pose);
      writer.write(options.channel_pose, utime, toMessage(pose));
      ++stats.poses_written;

      if (panoptic) {
        panoptic->utime = utime;
        panoptic->frame_id = frame.rgbd.frame_id;
        writer.write(options.channel_panoptic, utime, toMessage(*panoptic, options.encoding));
        ++stats.panoptic_written;
      } else if (masks) {
        ++stats.frames_without_mask;
      }
      if (progress) progress(i + 1, total);
    }
    // Masks named otherwise than their images (a stem with or without ".color", other
    // numbering) would give a map without a single class and no word of why.
    if (masks && stats.frames_written > 0 && stats.panoptic_written == 0) {
      throw Error("no mask in " + options.mask_dir + " matches a frame: a mask is found by its " +
                  "colour image's name (the first frame's is '" + first_color_stem +
                  "', its mask '" + first_color_stem + ".png')");
    }
    if (masks) {
      for (const std::string& stem : masks->stems()) {
        ++stats.masks_found;
        if (used_masks.count(stem)) continue;
        if (stats.masks_unused++ == 0) stats.first_unused_mask = stem;
      }
      const MaskReaderStats& m = masks->stats();
      stats.mask_pixels = m.labelled_pixels;
      stats.unlisted_mask_pixels = m.unlisted_pixels;
      stats.unlisted_bgr_mask_pixels = m.unlisted_bgr_pixels;
      // Masks most of whose pixels name no segment would map as void: refused, with the
      // likeliest cause.
      if (2 * m.unlisted_pixels > m.labelled_pixels) {
        throw Error(unlistedMaskPixels(stats) + "; not imported");
      }
    }
    if (stats.frames_written == 0 && stats.skipped_invalid_pose > 0) {
      throw Error("no frame has a valid pose: all " + std::to_string(stats.skipped_invalid_pose) +
                  " were left out (first: " + stats.first_skip_reason + ")");
    }
    stats.bytes_written = writer.bytes();
  } catch (...) {
    std::remove(partial.c_str());
    throw;
  }
  if (masks) {
    stats.unknown_category_segments = masks->stats().unknown_category_segments;
    stats.unknown_category_ids = masks->stats().unknown_category_ids;
    stats.mask_void_ids = masks->stats().void_ids;
  }
  if (std::rename(partial.c_str(), log_path.c_str()) != 0) {
    std::remove(partial.c_str());
    throw Error("cannot write log " + log_path);
  }
  return stats;
}

}  // namespace panmap
