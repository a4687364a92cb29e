#include "panmap/sim/segmenter_noise.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {
namespace {

void checkProbability(double p, const char* field) {
  if (!(p >= 0.0 && p <= 1.0)) {
    throw Error(std::string("segmenter noise: ") + field + " = " + std::to_string(p) +
                " is outside [0, 1]");
  }
}

void checkPositive(double v, const char* field) {
  if (!(v > 0.0 && std::isfinite(v))) {
    throw Error(std::string("segmenter noise: ") + field + " = " + std::to_string(v) +
                " must be positive");
  }
}

}  // namespace

void SegmenterNoiseConfig::check() const {
  checkPositive(window_frames, "window_frames");
  checkProbability(miss_probability_small, "miss_probability_small");
  checkProbability(miss_probability_large, "miss_probability_large");
  checkProbability(miss_probability_occluded, "miss_probability_occluded");
  checkProbability(occluded_threshold, "occluded_threshold");
  if (miss_small_px < 0) throw Error("segmenter noise: miss_small_px must be >= 0");
  if (miss_large_px <= miss_small_px) {
    throw Error("segmenter noise: miss_large_px must be larger than miss_small_px");
  }
  if (!(boundary_mean_px >= 0.0 && boundary_mean_px <= 100.0)) {
    throw Error("segmenter noise: boundary_mean_px = " + std::to_string(boundary_mean_px) +
                " is outside [0, 100]");
  }
  if (boundary_grid_px < 2) throw Error("segmenter noise: boundary_grid_px must be >= 2");
  checkPositive(boundary_period_frames, "boundary_period_frames");
  checkProbability(confusion_probability, "confusion_probability");
  for (const auto& group : confusion_groups) {
    if (group.size() < 2) throw Error("segmenter noise: a confusion_groups entry has < 2 classes");
    for (int32_t c : group) {
      if (c < 1 || c > kMaxNyu40Class || isStuffClass(c)) {
        throw Error("segmenter noise: confusion_groups holds " + std::to_string(c) +
                    ", not a NYU40 thing class");
      }
    }
  }
  checkProbability(merge_probability, "merge_probability");
  if (merge_min_contact_px < 1) throw Error("segmenter noise: merge_min_contact_px must be >= 1");
  checkProbability(split_probability, "split_probability");
  if (!(split_min_extent_m >= 0.0f)) {
    throw Error("segmenter noise: split_min_extent_m must be >= 0");
  }
  if (!(false_positives_per_frame >= 0.0 && false_positives_per_frame <= kFalsePositiveSlots)) {
    throw Error("segmenter noise: false_positives_per_frame = " +
                std::to_string(false_positives_per_frame) + " is outside [0, " +
                std::to_string(kFalsePositiveSlots) + "]");
  }
  if (false_positive_min_area_px < 1) {
    throw Error("segmenter noise: false_positive_min_area_px must be >= 1");
  }
  if (false_positive_max_area_px < false_positive_min_area_px) {
    throw Error("segmenter noise: false_positive_max_area_px is below false_positive_min_area_px");
  }
  checkProbability(clutter_stuff_probability, "clutter_stuff_probability");
  checkProbability(clutter_thing_probability, "clutter_thing_probability");
  if (clutter_stuff_probability + clutter_thing_probability > 1.0) {
    throw Error("segmenter noise: clutter_stuff_probability + clutter_thing_probability > 1");
  }
  if (clutter_thing_classes.empty() ||
      clutter_thing_classes.size() != clutter_thing_weights.size()) {
    throw Error("segmenter noise: clutter_thing_classes and clutter_thing_weights must be "
                "non-empty and equally long");
  }
  double weight_sum = 0.0;
  for (size_t k = 0; k < clutter_thing_classes.size(); ++k) {
    const int32_t c = clutter_thing_classes[k];
    if (c < 1 || c > kMaxNyu40Class || isStuffClass(c)) {
      throw Error("segmenter noise: clutter_thing_classes holds " + std::to_string(c) +
                  ", not a NYU40 thing class");
    }
    if (!(clutter_thing_weights[k] >= 0.0 && std::isfinite(clutter_thing_weights[k]))) {
      throw Error("segmenter noise: clutter_thing_weights must be finite and >= 0");
    }
    weight_sum += clutter_thing_weights[k];
  }
  if (!(weight_sum > 0.0)) throw Error("segmenter noise: clutter_thing_weights sum to 0");
  checkPositive(true_score_alpha, "true_score_alpha");
  checkPositive(true_score_beta, "true_score_beta");
  checkPositive(wrong_score_alpha, "wrong_score_alpha");
  checkPositive(wrong_score_beta, "wrong_score_beta");
  if (stats_min_px < 0) throw Error("segmenter noise: stats_min_px must be >= 0");
}

SegmenterNoiseConfig SegmenterNoiseConfig::fromPreset(const std::string& name) {
  SegmenterNoiseConfig c;
  c.preset = name;
  if (name == "clean") return c;
  if (name == "m2f") {
    // DESIGN 10: what Mask2Former does on ScanNet frames.
    c.miss_probability_small = 0.4;
    c.miss_probability_large = 0.1;
    c.miss_probability_occluded = 0.4;
    c.boundary_mean_px = 3.0;
    c.confusion_probability = 0.1;
    c.merge_probability = 0.2;
    c.split_probability = 0.1;
    c.false_positives_per_frame = 0.5;
    // docs/SIMULATION.md, "Unannotated surfaces": half painted into the touching stuff,
    // a quarter as a low-score thing, a quarter void.
    c.clutter_stuff_probability = 0.5;
    c.clutter_thing_probability = 0.25;
    c.sample_scores = true;
    return c;
  }
  if (name == "hard") {
    // About twice the m2f error rates (small-object misses capped below 1) and 1.5x boundaries.
    c.miss_probability_small = 0.7;
    c.miss_probability_large = 0.2;
    c.miss_probability_occluded = 0.7;
    c.boundary_mean_px = 4.5;
    c.confusion_probability = 0.2;
    c.merge_probability = 0.4;
    c.split_probability = 0.2;
    c.false_positives_per_frame = 1.0;
    c.clutter_stuff_probability = 0.5;
    c.clutter_thing_probability = 0.4;
    c.sample_scores = true;
    return c;
  }
  throw Error("segmenter noise: unknown preset '" + name + "' (clean, m2f, hard)");
}

namespace {
double ratio(int64_t a, int64_t b) { return b > 0 ? static_cast<double>(a) / b : 0.0; }
}  // namespace

double SegmenterNoiseStats::missRate() const { return ratio(missed, things_seen); }
double SegmenterNoiseStats::smallMissRate() const { return ratio(small_missed, small_seen); }
double SegmenterNoiseStats::largeMissRate() const { return ratio(large_missed, large_seen); }
double SegmenterNoiseStats::confusionRate() const { return ratio(confused, confusable_seen); }
double SegmenterNoiseStats::mergeRate() const { return ratio(merged_pairs, touching_pairs); }
double SegmenterNoiseStats::splitRate() const { return ratio(split, split_candidates); }
double SegmenterNoiseStats::falsePositivesPerFrame() const {
  return ratio(false_positives, frames);
}
double SegmenterNoiseStats::clutterStuffRate() const { return ratio(clutter_stuff, clutter_seen); }
double SegmenterNoiseStats::clutterThingRate() const { return ratio(clutter_thing, clutter_seen); }
double SegmenterNoiseStats::meanBoundaryErrorPx() const {
  return boundary_length_px > 0.0 ? boundary_error_area_px / boundary_length_px : 0.0;
}

}  // namespace panmap
