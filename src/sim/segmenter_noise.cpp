#include "panmap/sim/segmenter_noise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <unordered_map>
#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Part of every hash, so that decisions of different kinds are independent.
enum Kind : uint64_t {
  kPhase = 1,
  kMiss,
  kConfuse,
  kConfuseClass,
  kMerge,
  kSplit,
  kSplitAngle,
  kFalsePositive,
  kFalsePositiveShape,
  kBoundary,
  kScore,
};

// splitmix64's finaliser: a bijective, well-mixing 64-bit hash.
uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

uint64_t hashOf(std::initializer_list<uint64_t> keys) {
  uint64_t h = 0x6a09e667f3bcc909ULL;
  for (uint64_t k : keys) h = mix64(h ^ mix64(k + 0x9e3779b97f4a7c15ULL));
  return h;
}

double toUnit(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

uint64_t key(int64_t v) { return static_cast<uint64_t>(v); }

int64_t floorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// splitmix64 with our own samplers: std:: distributions differ between standard libraries,
// and the output must be identical everywhere for a seed.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() { return mix64(state_ += 0x9e3779b97f4a7c15ULL); }
  /// Uniform in [0, 1).
  double uniform() { return toUnit(next()); }
  /// Standard normal (Box-Muller).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]: log stays finite
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  /// Gamma(shape, 1) by Marsaglia and Tsang (2000); shape < 1 through the boost u^(1/shape).
  double gamma(double shape) {
    if (shape < 1.0) return gamma(shape + 1.0) * std::pow(1.0 - uniform(), 1.0 / shape);
    const double d = shape - 1.0 / 3.0;
    const double c = 1.0 / std::sqrt(9.0 * d);
    for (;;) {
      double x = 0.0;
      double v = 0.0;
      do {
        x = normal();
        v = 1.0 + c * x;
      } while (v <= 0.0);
      v = v * v * v;
      const double u = 1.0 - uniform();
      if (std::log(u) < 0.5 * x * x + d - d * v + d * std::log(v)) return d * v;
    }
  }
  /// Beta(a, b) as X / (X + Y) of two Gammas.
  double beta(double a, double b) {
    const double x = gamma(a);
    const double y = gamma(b);
    return x / (x + y);
  }

 private:
  uint64_t state_;
};

// One label of the compact image: a thing instance, or all the stuff of one class.
struct Unit {
  int32_t instance = 0;  // thing: ground-truth id; stuff: 0
  int32_t cls = 0;
  bool stuff = false;
  float extent_m = 0.0f;
  float occluded = 0.0f;
  std::vector<int32_t> stuff_instances;
  int64_t gt_px = 0;
  int64_t warped_px = 0;
  double outline_px = 0.0;
  double diff_px = 0.0;
  bool missed = false;
  int32_t category = 0;
  int32_t parent = 0;  // union-find of merges
  bool split = false;
  double cx = 0.0, cy = 0.0, ax = 1.0, ay = 0.0;  // split line: centroid and major axis
  int32_t seg = 0;
  int32_t seg2 = 0;  // second half of a split
};

int32_t findRoot(std::vector<Unit>& units, int32_t k) {
  while (units[k].parent != k) {
    units[k].parent = units[units[k].parent].parent;
    k = units[k].parent;
  }
  return k;
}

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
double SegmenterNoiseStats::meanBoundaryErrorPx() const {
  return boundary_length_px > 0.0 ? boundary_error_area_px / boundary_length_px : 0.0;
}

SegmenterNoise::SegmenterNoise(const SegmenterNoiseConfig& config, uint64_t seed)
    : config_(config), seed_(seed), confusable_(kMaxNyu40Class + 1) {
  config_.check();
  for (const auto& group : config_.confusion_groups) {
    for (int32_t c : group) {
      for (int32_t other : group) {
        if (other != c) confusable_[c].push_back(other);
      }
    }
  }
  for (auto& list : confusable_) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
}

namespace {

// Everything segment() needs besides the images; keeps the hashing conventions in one place.
class FrameContext {
 public:
  FrameContext(const SegmenterNoiseConfig& config, uint64_t seed, int frame)
      : config_(config), seed_(seed), frame_(frame) {}

  // Index of the time window of (subject, kind) holding this frame. A per-subject phase keeps
  // the windows of different instances from switching on the same frame.
  int64_t window(uint64_t subject, Kind kind) const {
    const int64_t length = config_.window_frames;
    const int64_t phase = static_cast<int64_t>(hashOf({seed_, kPhase, kind, subject}) %
                                               static_cast<uint64_t>(length));
    return floorDiv(frame_ + phase, length);
  }
  // A uniform draw constant over the window.
  double draw(uint64_t subject, Kind kind) const {
    return toUnit(hashOf({seed_, kind, subject, key(window(subject, kind))}));
  }
  uint64_t windowHash(uint64_t subject, Kind kind, Kind sub_kind) const {
    return hashOf({seed_, sub_kind, subject, key(window(subject, kind))});
  }

 private:
  const SegmenterNoiseConfig& config_;
  uint64_t seed_;
  int frame_;
};

double missProbability(const SegmenterNoiseConfig& c, int64_t px, float occluded) {
  double p = 0.0;
  if (px <= c.miss_small_px) {
    p = c.miss_probability_small;
  } else if (px >= c.miss_large_px) {
    p = c.miss_probability_large;
  } else {
    const double t =
        static_cast<double>(px - c.miss_small_px) / (c.miss_large_px - c.miss_small_px);
    p = c.miss_probability_small + t * (c.miss_probability_large - c.miss_probability_small);
  }
  if (occluded > c.occluded_threshold) p = std::max(p, c.miss_probability_occluded);
  return p;
}

// Control points of one displacement field: two standard normals (du, dv) per grid node.
cv::Mat coarseField(uint64_t seed, int64_t index, int grid_w, int grid_h) {
  cv::Mat field(grid_h, grid_w, CV_32FC2);
  Rng rng(hashOf({seed, kBoundary, key(index)}));
  for (int r = 0; r < grid_h; ++r) {
    auto* row = field.ptr<cv::Vec2f>(r);
    for (int c = 0; c < grid_w; ++c) {
      row[c][0] = static_cast<float>(rng.normal());
      row[c][1] = static_cast<float>(rng.normal());
    }
  }
  return field;
}

// Backward-warps the compact label image by a smooth random field (nearest neighbour, so no
// label is invented): outlines move in blobs of about the grid size, not as per-pixel salt.
// The field is cos/sin-blended between two independent fields so it drifts smoothly in time with
// constant variance, and scaled so its mean per-axis displacement is boundary_mean_px, which for
// an isotropic field is the mean displacement normal to any outline.
void warpLabels(const SegmenterNoiseConfig& c, uint64_t seed, int frame, int width, int height,
                const std::vector<int32_t>& in, std::vector<int32_t>& out) {
  const int grid_w = std::max(2, (width + c.boundary_grid_px - 1) / c.boundary_grid_px);
  const int grid_h = std::max(2, (height + c.boundary_grid_px - 1) / c.boundary_grid_px);
  const int64_t period = c.boundary_period_frames;
  const int64_t index = floorDiv(frame, period);
  const double theta = 0.5 * kPi * static_cast<double>(frame - index * period) / period;
  cv::Mat coarse;
  cv::addWeighted(coarseField(seed, index, grid_w, grid_h), std::cos(theta),
                  coarseField(seed, index + 1, grid_w, grid_h), std::sin(theta), 0.0, coarse);
  cv::Mat field;
  cv::resize(coarse, field, cv::Size(width, height), 0.0, 0.0, cv::INTER_CUBIC);
  const double mean_abs = cv::norm(field, cv::NORM_L1) / (2.0 * width * height);
  const float scale = mean_abs > 0.0 ? static_cast<float>(c.boundary_mean_px / mean_abs) : 0.0f;
  out.resize(in.size());
  for (int v = 0; v < height; ++v) {
    const auto* d = field.ptr<cv::Vec2f>(v);
    int32_t* dst = out.data() + static_cast<size_t>(v) * width;
    for (int u = 0; u < width; ++u) {
      const int su = std::min(width - 1, std::max(0, u + cvRound(d[u][0] * scale)));
      const int sv = std::min(height - 1, std::max(0, v + cvRound(d[u][1] * scale)));
      dst[u] = in[static_cast<size_t>(sv) * width + su];
    }
  }
}

// A smooth random blob: radius r0 (1 + a2 cos 2(t - p2) + a3 cos 3(t - p3)) in polar angle t,
// evaluated without trigonometry per pixel.
struct Blob {
  double cx = 0.0, cy = 0.0, r0 = 0.0;
  double c2 = 0.0, s2 = 0.0, c3 = 0.0, s3 = 0.0;  // amplitude * cos / sin of the phases
  double reach() const { return r0 * (1.0 + std::hypot(c2, s2) + std::hypot(c3, s3)) + 1.0; }
  bool contains(double u, double v) const {
    const double x = u - cx;
    const double y = v - cy;
    const double rr = x * x + y * y;
    if (rr < 1e-9) return true;
    const double r = std::sqrt(rr);
    const double c = x / r;
    const double s = y / r;
    const double cos2 = c * c - s * s, sin2 = 2.0 * c * s;
    const double cos3 = 4.0 * c * c * c - 3.0 * c, sin3 = 3.0 * s - 4.0 * s * s * s;
    const double f = 1.0 + c2 * cos2 + s2 * sin2 + c3 * cos3 + s3 * sin3;
    return r < r0 * f;
  }
};

struct Draft {
  PanopticSegment segment;
  SegmentOrigin origin;
  uint64_t score_key = 0;
  int64_t px = 0;
};

}  // namespace

PanopticFrame SegmenterNoise::segment(const LabelImage& instances, const LabelImage& semantics,
                                      int frame_index, const std::map<int32_t, InstanceInfo>& infos,
                                      SegmenterTrace* trace) {
  const int width = instances.width();
  const int height = instances.height();
  const bool has_semantics = !semantics.empty();
  if (has_semantics && (semantics.width() != width || semantics.height() != height)) {
    throw Error("segmenter noise: semantics image is " + std::to_string(semantics.width()) + "x" +
                std::to_string(semantics.height()) + ", instances " + std::to_string(width) + "x" +
                std::to_string(height));
  }
  const SegmenterNoiseConfig& c = config_;
  const FrameContext ctx(c, seed_, frame_index);
  const size_t n = instances.size();

  // 1. Compact labels: unit 0 = nothing, one unit per thing instance, one per stuff class.
  std::vector<Unit> units(1);
  std::vector<int32_t> stuff_unit(kMaxNyu40Class + 1, -1);
  std::unordered_map<int32_t, int32_t> unit_of_instance;
  auto stuffUnit = [&](int32_t cls) {
    if (stuff_unit[cls] < 0) {
      stuff_unit[cls] = static_cast<int32_t>(units.size());
      Unit unit;
      unit.cls = cls;
      unit.stuff = true;
      units.push_back(unit);
    }
    return stuff_unit[cls];
  };
  auto lookup = [&](int32_t id, int32_t sem) -> int32_t {
    if (id == 0) return sem > 0 && sem <= kMaxNyu40Class && isStuffClass(sem) ? stuffUnit(sem) : 0;
    const auto known = unit_of_instance.find(id);
    if (known != unit_of_instance.end()) return known->second;
    const auto it = infos.find(id);
    if (it == infos.end()) {
      throw Error("segmenter noise: instance " + std::to_string(id) + " has no InstanceInfo");
    }
    const InstanceInfo& info = it->second;
    int32_t index = 0;
    if (info.is_stuff || isStuffClass(info.semantic)) {
      if (!isStuffClass(info.semantic)) {
        throw Error("segmenter noise: instance " + std::to_string(id) + " is_stuff but semantic " +
                    std::to_string(info.semantic) + " is not a stuff class");
      }
      index = stuffUnit(info.semantic);
      units[index].stuff_instances.push_back(id);
    } else if (info.semantic != kUnknownClass) {
      index = static_cast<int32_t>(units.size());
      Unit unit;
      unit.instance = id;
      unit.cls = info.semantic;
      unit.category = info.semantic;
      unit.extent_m = info.extent_m;
      unit.occluded = info.occluded_fraction;
      units.push_back(unit);
    }
    unit_of_instance.emplace(id, index);
    return index;
  };
  std::vector<int32_t> gt(n);
  {
    const int32_t* ids = instances.data();
    const int32_t* sems = has_semantics ? semantics.data() : nullptr;
    int32_t last_id = std::numeric_limits<int32_t>::min();
    int32_t last_sem = 0;
    int32_t last_unit = 0;
    for (size_t i = 0; i < n; ++i) {
      const int32_t id = ids[i];
      const int32_t sem = id == 0 && sems ? sems[i] : 0;
      // Label images are long runs: look up only where the label changes.
      if (id != last_id || sem != last_sem) {
        last_unit = lookup(id, sem);
        last_id = id;
        last_sem = sem;
      }
      gt[i] = last_unit;
      ++units[last_unit].gt_px;
    }
  }
  const int32_t unit_count = static_cast<int32_t>(units.size());
  std::vector<uint8_t> is_thing(unit_count, 0);
  for (int32_t k = 1; k < unit_count; ++k) is_thing[k] = !units[k].stuff;

  // 2. Boundary error.
  std::vector<int32_t> warped_storage;
  const bool warp = c.boundary_mean_px > 0.0;
  if (warp) warpLabels(c, seed_, frame_index, width, height, gt, warped_storage);
  const std::vector<int32_t>& warped = warp ? warped_storage : gt;

  // 3. Outlines, the area between true and warped outlines, and same-class contacts.
  std::map<std::pair<int32_t, int32_t>, int> contacts;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const int32_t a = gt[i];
      if (warp) {
        const int32_t b = warped[i];
        if (a != b) {
          units[a].diff_px += is_thing[a];
          units[b].diff_px += is_thing[b];
        }
      }
      if (!is_thing[a]) continue;
      bool outline = false;
      if (u + 1 < width) {
        const int32_t b = gt[i + 1];
        if (b != a) {
          outline = true;
          if (is_thing[b] && units[b].cls == units[a].cls) ++contacts[std::minmax(a, b)];
        }
      }
      if (v + 1 < height) {
        const int32_t b = gt[i + width];
        if (b != a) {
          outline = true;
          if (is_thing[b] && units[b].cls == units[a].cls) ++contacts[std::minmax(a, b)];
        }
      }
      outline = outline || (u > 0 && gt[i - 1] != a) || (v > 0 && gt[i - width] != a);
      units[a].outline_px += outline;
    }
  }

  // 4. Per-instance decisions: miss, then class confusion.
  for (int32_t k = 1; k < unit_count; ++k) {
    Unit& unit = units[k];
    unit.parent = k;
    if (unit.stuff) continue;
    const uint64_t subject = key(unit.instance);
    unit.missed = ctx.draw(subject, kMiss) < missProbability(c, unit.gt_px, unit.occluded);
    if (unit.missed) continue;
    const bool confusable =
        unit.cls > 0 && unit.cls <= kMaxNyu40Class && !confusable_[unit.cls].empty();
    if (confusable && ctx.draw(subject, kConfuse) < c.confusion_probability) {
      const auto& others = confusable_[unit.cls];
      unit.category = others[ctx.windowHash(subject, kConfuse, kConfuseClass) % others.size()];
    }
  }

  // 5. Merges of touching same-class instances, decided per pair.
  std::vector<std::pair<std::pair<int32_t, int32_t>, bool>> pairs;  // both detected
  for (const auto& [pair, edges] : contacts) {
    if (edges < c.merge_min_contact_px) continue;
    const Unit& a = units[pair.first];
    const Unit& b = units[pair.second];
    if (a.missed || b.missed) continue;
    const uint64_t subject =
        hashOf({key(std::min(a.instance, b.instance)), key(std::max(a.instance, b.instance))});
    const bool merge = ctx.draw(subject, kMerge) < c.merge_probability;
    if (merge) units[findRoot(units, pair.first)].parent = findRoot(units, pair.second);
    pairs.push_back({pair, merge});
  }

  // 6. Segments: stuff by class, then thing groups by their largest member's instance id.
  std::vector<Draft> drafts;
  auto newDraft = [&](int32_t category, bool is_thing_segment, uint64_t score_key) {
    Draft d;
    d.segment.id = static_cast<int32_t>(drafts.size()) + 1;
    d.segment.category = category;
    d.segment.source_category = category;
    d.segment.is_thing = is_thing_segment;
    d.score_key = score_key;
    drafts.push_back(d);
    return d.segment.id;
  };
  std::vector<int32_t> lut(unit_count, 0);
  for (int32_t cls = 1; cls <= kMaxNyu40Class; ++cls) {
    const int32_t k = stuff_unit[cls];
    if (k < 0) continue;
    lut[k] = units[k].seg = newDraft(cls, false, hashOf({0, key(cls)}));
    auto& members = drafts.back().origin.instances;
    members = units[k].stuff_instances;
    std::sort(members.begin(), members.end());
  }
  std::map<int32_t, std::vector<int32_t>> groups;  // root -> member units
  for (int32_t k = 1; k < unit_count; ++k) {
    if (is_thing[k] && !units[k].missed) groups[findRoot(units, k)].push_back(k);
  }
  std::vector<std::pair<int32_t, std::vector<int32_t>>> ordered;  // representative, members
  for (auto& [root, members] : groups) {
    int32_t rep = members.front();
    for (int32_t k : members) {
      const Unit& a = units[k];
      const Unit& r = units[rep];
      if (a.gt_px > r.gt_px || (a.gt_px == r.gt_px && a.instance < r.instance)) rep = k;
    }
    ordered.push_back({rep, std::move(members)});
  }
  std::sort(ordered.begin(), ordered.end(), [&](const auto& a, const auto& b) {
    return units[a.first].instance < units[b.first].instance;
  });
  std::vector<uint8_t> split_unit(unit_count, 0);
  for (const auto& [rep, members] : ordered) {
    Unit& r = units[rep];
    const int32_t id = newDraft(r.category, true, hashOf({1, key(r.instance)}));
    Draft& d = drafts.back();
    for (int32_t k : members) {
      lut[k] = units[k].seg = id;
      d.origin.instances.push_back(units[k].instance);
    }
    std::sort(d.origin.instances.begin(), d.origin.instances.end());
    d.origin.merged = members.size() > 1;
    d.origin.confused = r.category != r.cls;
    if (members.size() == 1 && r.extent_m > c.split_min_extent_m &&
        ctx.draw(key(r.instance), kSplit) < c.split_probability) {
      r.split = true;
      split_unit[rep] = 1;
    }
  }
  std::vector<int32_t> lut2(unit_count, 0);
  bool any_split = false;
  for (const auto& [rep, members] : ordered) {
    Unit& r = units[rep];
    if (!r.split) continue;
    any_split = true;
    lut2[rep] = r.seg2 = newDraft(r.category, true, hashOf({2, key(r.instance)}));
    Draft& d = drafts.back();
    d.origin = drafts[r.seg - 1].origin;
  }

  // 7. Split lines: through the warped mask's centroid, across its major axis (a long sofa seen
  // as two), tilted by a random angle that holds over the window.
  if (any_split) {
    std::vector<std::array<double, 6>> moments(unit_count, {0, 0, 0, 0, 0, 0});
    for (int v = 0; v < height; ++v) {
      const int32_t* row = warped.data() + static_cast<size_t>(v) * width;
      for (int u = 0; u < width; ++u) {
        if (!split_unit[row[u]]) continue;
        auto& m = moments[row[u]];
        m[0] += 1.0;
        m[1] += u;
        m[2] += v;
        m[3] += static_cast<double>(u) * u;
        m[4] += static_cast<double>(u) * v;
        m[5] += static_cast<double>(v) * v;
      }
    }
    for (int32_t k = 1; k < unit_count; ++k) {
      if (!split_unit[k]) continue;
      Unit& r = units[k];
      const auto& m = moments[k];
      if (m[0] <= 0.0) continue;
      r.cx = m[1] / m[0];
      r.cy = m[2] / m[0];
      const double cuu = m[3] / m[0] - r.cx * r.cx;
      const double cuv = m[4] / m[0] - r.cx * r.cy;
      const double cvv = m[5] / m[0] - r.cy * r.cy;
      const double jitter =
          (toUnit(ctx.windowHash(key(r.instance), kSplit, kSplitAngle)) - 0.5) * 0.6;
      const double angle = 0.5 * std::atan2(2.0 * cuv, cuu - cvv) + jitter;
      r.ax = std::cos(angle);
      r.ay = std::sin(angle);
    }
  }

  // 8. The segment-id image.
  PanopticFrame frame;
  frame.frame_id = frame_index;
  frame.segment_ids = LabelImage(width, height, 0);
  int32_t* out = frame.segment_ids.data();
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = 0; u < width; ++u) {
      const int32_t k = warped[row + u];
      int32_t id = lut[k];
      if (split_unit[k]) {
        const Unit& r = units[k];
        if ((u - r.cx) * r.ax + (v - r.cy) * r.ay > 0.0) id = lut2[k];
      }
      out[row + u] = id;
      ++units[k].warped_px;
    }
  }

  // 9. False positives: each slot is on for a whole window, at a place and shape fixed for it,
  // painted over stuff only (a network hallucinates objects on walls and floors).
  std::vector<uint8_t> stuff_segment(drafts.size() + 1, 0);
  for (int32_t k = 1; k < unit_count; ++k) {
    if (units[k].stuff) stuff_segment[units[k].seg] = 1;
  }
  auto onStuff = [&](int u, int v) {
    const int32_t id = out[static_cast<size_t>(v) * width + u];
    return id > 0 && id < static_cast<int32_t>(stuff_segment.size()) && stuff_segment[id];
  };
  const double slot_probability =
      c.false_positives_per_frame / SegmenterNoiseConfig::kFalsePositiveSlots;
  const auto& thing_classes = evaluatedClasses();
  for (int slot = 0; slot < SegmenterNoiseConfig::kFalsePositiveSlots; ++slot) {
    const uint64_t subject = key(slot);
    if (slot_probability <= 0.0 || ctx.draw(subject, kFalsePositive) >= slot_probability) continue;
    Rng rng(ctx.windowHash(subject, kFalsePositive, kFalsePositiveShape));
    const double area =
        c.false_positive_min_area_px +
        rng.uniform() * (c.false_positive_max_area_px - c.false_positive_min_area_px);
    const int32_t category = thing_classes[rng.next() % thing_classes.size()];
    Blob blob;
    blob.r0 = std::sqrt(area / kPi);
    const double a2 = 0.25 * rng.uniform(), p2 = 2.0 * kPi * rng.uniform();
    const double a3 = 0.12 * rng.uniform(), p3 = 2.0 * kPi * rng.uniform();
    blob.c2 = a2 * std::cos(2.0 * p2);
    blob.s2 = a2 * std::sin(2.0 * p2);
    blob.c3 = a3 * std::cos(3.0 * p3);
    blob.s3 = a3 * std::sin(3.0 * p3);
    for (int attempt = 0; attempt < 8; ++attempt) {
      blob.cx = rng.uniform() * width;
      blob.cy = rng.uniform() * height;
      const int cu = std::min(width - 1, static_cast<int>(blob.cx));
      const int cv = std::min(height - 1, static_cast<int>(blob.cy));
      if (!onStuff(cu, cv)) continue;
      const double reach = blob.reach();
      const int u0 = std::max(0, static_cast<int>(blob.cx - reach));
      const int u1 = std::min(width - 1, static_cast<int>(blob.cx + reach));
      const int v0 = std::max(0, static_cast<int>(blob.cy - reach));
      const int v1 = std::min(height - 1, static_cast<int>(blob.cy + reach));
      int64_t inside = 0;
      int64_t on_stuff = 0;
      for (int v = v0; v <= v1; ++v) {
        for (int u = u0; u <= u1; ++u) {
          if (!blob.contains(u, v)) continue;
          ++inside;
          on_stuff += onStuff(u, v);
        }
      }
      // Mostly on stuff, or it would be a thing-on-thing confusion rather than a hallucination.
      if (on_stuff * 2 < std::max<int64_t>(1, static_cast<int64_t>(area))) continue;
      const int32_t id = newDraft(category, true, hashOf({3, key(slot)}));
      drafts.back().origin.false_positive = true;
      for (int v = v0; v <= v1; ++v) {
        for (int u = u0; u <= u1; ++u) {
          if (blob.contains(u, v) && onStuff(u, v)) out[static_cast<size_t>(v) * width + u] = id;
        }
      }
      break;
    }
  }

  // 10. Segment list: exactly the ids present in the image.
  for (size_t i = 0; i < n; ++i) {
    if (out[i] > 0) ++drafts[out[i] - 1].px;
  }
  for (int32_t k = 1; k < unit_count; ++k) {
    const Unit& r = units[k];
    if (!r.split) continue;
    const bool both = drafts[r.seg - 1].px > 0 && drafts[r.seg2 - 1].px > 0;
    drafts[r.seg - 1].origin.split = both;
    drafts[r.seg2 - 1].origin.split = both;
  }
  if (trace) *trace = SegmenterTrace();
  for (Draft& d : drafts) {
    if (d.px == 0) continue;
    const SegmentOrigin& o = d.origin;
    const bool wrong = o.confused || o.merged || o.split || o.false_positive;
    if (c.sample_scores) {
      Rng rng(hashOf({seed_, kScore, key(frame_index), d.score_key}));
      const double score = wrong ? rng.beta(c.wrong_score_alpha, c.wrong_score_beta)
                                 : rng.beta(c.true_score_alpha, c.true_score_beta);
      d.segment.score = static_cast<float>(std::min(1.0, std::max(0.0, score)));
    } else {
      d.segment.score = 1.0f;
    }
    frame.segments.push_back(d.segment);
    if (trace) trace->origins.push_back(o);
  }

  // 11. Statistics over things big enough to matter.
  SegmenterNoiseStats& s = stats_;
  ++s.frames;
  for (int32_t k = 1; k < unit_count; ++k) {
    const Unit& r = units[k];
    if (!is_thing[k]) continue;
    const bool detected = !r.missed && r.warped_px > 0;
    if (!detected && trace) trace->missed.push_back(r.instance);
    if (r.gt_px < c.stats_min_px) continue;
    ++s.things_seen;
    s.missed += !detected;
    if (r.gt_px <= c.miss_small_px) {
      ++s.small_seen;
      s.small_missed += !detected;
    }
    if (r.gt_px >= c.miss_large_px) {
      ++s.large_seen;
      s.large_missed += !detected;
    }
    if (warp) {
      s.boundary_error_area_px += r.diff_px;
      s.boundary_length_px += r.outline_px;
    }
    if (!detected) continue;
    const Draft& d = drafts[r.seg - 1];
    if (r.cls > 0 && r.cls <= kMaxNyu40Class && !confusable_[r.cls].empty()) {
      ++s.confusable_seen;
      s.confused += d.segment.category != r.cls;
    }
    if (!d.origin.merged && r.extent_m > c.split_min_extent_m) {
      ++s.split_candidates;
      s.split += d.origin.split;
    }
  }
  for (const auto& [pair, merged] : pairs) {
    const Unit& a = units[pair.first];
    const Unit& b = units[pair.second];
    if (a.gt_px < c.stats_min_px || b.gt_px < c.stats_min_px) continue;
    if (a.warped_px == 0 || b.warped_px == 0) continue;
    ++s.touching_pairs;
    s.merged_pairs += merged;
  }
  for (const Draft& d : drafts) s.false_positives += d.origin.false_positive && d.px > 0;
  if (trace) std::sort(trace->missed.begin(), trace->missed.end());
  return frame;
}

}  // namespace panmap
