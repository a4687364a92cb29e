#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"

namespace panmap {

/// What the segmenter simulation knows of each ground-truth instance in view.
struct InstanceInfo {
  int32_t semantic = 0;   ///< NYU40 id
  float extent_m = 0.0f;  ///< longest side of its 3D bounding box, metres
  bool is_stuff = false;  ///< wall, floor, ceiling
  /// Share of the instance hidden by others in this frame, in [0, 1], when the caller can tell
  /// (e.g. by rendering it alone); 0 = unknown or fully visible.
  float occluded_fraction = 0.0f;
};

/// Parameters of the simulated 2D panoptic segmenter (DESIGN 10). All probabilities are per
/// instance and per time window (errors persist over neighbouring frames). The defaults are the
/// "clean" preset: ground-truth masks, no errors, every score 1.
struct SegmenterNoiseConfig {
  std::string preset = "clean";  ///< name of the preset the values came from (informational)

  // Persistence: a network fails on a view, not on a random frame.
  int window_frames = 15;  ///< per-instance errors are redrawn once per window of this many frames

  // Misses: probability linear in the instance's pixel count between the two sizes.
  double miss_probability_small = 0.0;  ///< objects of at most miss_small_px pixels
  double miss_probability_large = 0.0;  ///< objects of at least miss_large_px pixels
  int miss_small_px = 1000;
  int miss_large_px = 5000;
  /// Objects with InstanceInfo::occluded_fraction above occluded_threshold are missed with at
  /// least this probability.
  double miss_probability_occluded = 0.0;
  double occluded_threshold = 0.6;

  // Boundaries: the label image is warped by a smooth random displacement field.
  double boundary_mean_px = 0.0;    ///< mean normal displacement of outlines; 0 = exact masks
  int boundary_grid_px = 24;        ///< spacing of the field's random control points
  int boundary_period_frames = 30;  ///< the field drifts into an independent one over this long

  // Class confusion within groups of look-alike classes (NYU40 ids).
  double confusion_probability = 0.0;
  std::vector<std::vector<int32_t>> confusion_groups = {
      {5, 6, 39}, {7, 14, 12}, {3, 10, 24, 39}, {9, 16, 28, 11}};

  // Merges and splits.
  double merge_probability = 0.0;  ///< per pair of touching same-class instances
  int merge_min_contact_px = 5;    ///< pixel edges two instances must share to count as touching
  double split_probability = 0.0;  ///< per instance longer than split_min_extent_m
  float split_min_extent_m = 1.5f;

  // False positives: smooth blobs of a random thing class painted over stuff pixels.
  double false_positives_per_frame = 0.0;  ///< mean, at most kFalsePositiveSlots
  int false_positive_min_area_px = 500;
  int false_positive_max_area_px = 5000;

  // Unannotated clutter: surfaces of class 0 that still carry an instance id (things a scene's
  // annotation left without a class). A network paints them anyway; per instance and window
  // each is drawn as: painted into the stuff segment it touches most in the image (no stuff
  // in contact: void), painted as a thing of one of clutter_thing_classes (weighted by
  // clutter_thing_weights) with a wrong-detection score, or left void (the rest). Class-0
  // pixels without an instance id are always void.
  double clutter_stuff_probability = 0.0;
  double clutter_thing_probability = 0.0;
  std::vector<int32_t> clutter_thing_classes = {40, 39};  ///< otherprop, otherfurniture
  std::vector<double> clutter_thing_weights = {2.0, 1.0};

  // Scores: Beta-distributed; wrong = confused class, merged, split, false positive or clutter.
  bool sample_scores = false;  ///< false: every score is 1
  double true_score_alpha = 8.0;
  double true_score_beta = 2.0;
  double wrong_score_alpha = 3.0;
  double wrong_score_beta = 4.0;

  int stats_min_px = 50;  ///< things smaller than this in a frame are left out of the statistics

  /// Independent false-positive generators; each is on with false_positives_per_frame / slots.
  static constexpr int kFalsePositiveSlots = 4;

  /// Throws Error naming the bad field.
  void check() const;
  /// The named preset: "clean", "m2f" or "hard". Throws Error for other names.
  static SegmenterNoiseConfig fromPreset(const std::string& name);
};

/// Counts over the frames a SegmenterNoise has processed. "Things" are thing instances with at
/// least SegmenterNoiseConfig::stats_min_px ground-truth pixels in a frame, counted once per frame.
struct SegmenterNoiseStats {
  int64_t frames = 0;
  int64_t things_seen = 0;
  int64_t missed = 0;      ///< things that got no segment pixel
  int64_t small_seen = 0;  ///< things of at most miss_small_px pixels
  int64_t small_missed = 0;
  int64_t large_seen = 0;  ///< things of at least miss_large_px pixels
  int64_t large_missed = 0;
  int64_t confusable_seen = 0;   ///< detected things whose class is in a confusion group
  int64_t confused = 0;          ///< of those, labelled with another class
  int64_t touching_pairs = 0;    ///< pairs of detected same-class things touching in the image
  int64_t merged_pairs = 0;      ///< of those, merged into one segment
  int64_t split_candidates = 0;  ///< detected, unmerged things longer than split_min_extent_m
  int64_t split = 0;             ///< of those, split in two segments
  int64_t false_positives = 0;   ///< false-positive segments emitted
  int64_t clutter_seen = 0;      ///< unannotated clutter instances in view (stats_min_px)
  int64_t clutter_stuff = 0;     ///< of those, painted into a stuff segment
  int64_t clutter_thing = 0;     ///< of those, painted as a thing
  /// Pixels in the symmetric difference of ground-truth and warped thing masks.
  double boundary_error_area_px = 0.0;
  /// Ground-truth thing outline pixels (4-neighbour of another label inside the image).
  double boundary_length_px = 0.0;

  /// missed / things_seen (0 when nothing was seen).
  double missRate() const;
  /// small_missed / small_seen.
  double smallMissRate() const;
  /// large_missed / large_seen.
  double largeMissRate() const;
  /// confused / confusable_seen.
  double confusionRate() const;
  /// merged_pairs / touching_pairs.
  double mergeRate() const;
  /// split / split_candidates.
  double splitRate() const;
  /// false_positives / frames.
  double falsePositivesPerFrame() const;
  /// clutter_stuff / clutter_seen.
  double clutterStuffRate() const;
  /// clutter_thing / clutter_seen.
  double clutterThingRate() const;
  /// Area between true and warped outlines over outline length: the mean normal displacement
  /// actually applied to thing boundaries, pixels.
  double meanBoundaryErrorPx() const;
};

/// Where one output segment came from (for tests and diagnostics).
struct SegmentOrigin {
  /// Ground-truth instance ids it covers: one thing, several when merged, the stuff instances of
  /// its class for stuff, none for a false positive. Ascending.
  std::vector<int32_t> instances;
  bool confused = false;        ///< category differs from the instances' class
  bool merged = false;          ///< several instances in one mask
  bool split = false;           ///< one of the two halves of a split instance
  bool false_positive = false;  ///< hallucinated on stuff
  bool clutter = false;         ///< an unannotated clutter surface painted as a thing
};

/// Per-frame record of the simulated errors.
struct SegmenterTrace {
  std::vector<SegmentOrigin> origins;  ///< parallel to PanopticFrame::segments
  std::vector<int32_t> missed;         ///< thing instances in view that got no segment, ascending
};

/// Turns ground-truth label images into what a 2D panoptic network (Mask2Former on ScanNet)
/// would output: missed objects, wobbly boundaries, confused classes, merges, splits, false
/// positives and confidence scores. Deterministic for a seed; not thread-safe (it keeps stats).
class SegmenterNoise {
 public:
  /// @param config checked here (throws Error naming the bad field).
  /// @param seed every random decision is a hash of it; the same seed and inputs give the
  ///     identical output.
  SegmenterNoise(const SegmenterNoiseConfig& config, uint64_t seed);

  /// Simulates the segmenter on one frame.
  /// @param instances ground-truth instance id per pixel, 0 = nothing (e.g. no depth).
  /// @param semantics NYU40 id per pixel, same size, or empty; only read where `instances` is 0,
  ///     so stuff without instance ids still becomes a stuff segment.
  /// @param frame_index position in the sequence: errors persist over neighbouring indices.
  /// @param infos every instance id present in `instances`; throws Error for a missing one.
  ///     Instances of class 0 (unknown) are unannotated clutter: painted per the clutter_*
  ///     rates (void when they are 0).
  /// @param trace when not null, receives where each segment came from.
  /// @return segment ids at the size of `instances` (0 = no segment), frame_id = frame_index,
  ///     utime 0 (the caller's).
  PanopticFrame segment(const LabelImage& instances, const LabelImage& semantics, int frame_index,
                        const std::map<int32_t, InstanceInfo>& infos,
                        SegmenterTrace* trace = nullptr);

  /// Counts over every frame segmented since construction or resetStats().
  const SegmenterNoiseStats& stats() const { return stats_; }
  /// Zeroes the counts.
  void resetStats() { stats_ = SegmenterNoiseStats(); }
  /// The checked configuration.
  const SegmenterNoiseConfig& config() const { return config_; }

 private:
  SegmenterNoiseConfig config_;
  uint64_t seed_;
  /// Per NYU40 id, the classes it may be confused with (union of its groups, itself excluded).
  std::vector<std::vector<int32_t>> confusable_;
  SegmenterNoiseStats stats_;
};

}  // namespace panmap
