#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/sim/segmenter_noise.h"

namespace panmap {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr int32_t kWall = 1;
constexpr int32_t kFloor = 2;

enum class SizeClass { kSmall, kMedium, kLarge };

struct Thing {
  int32_t id = 0;
  int32_t cls = 0;
  cv::Rect box;
  float extent_m = 0.0f;
  SizeClass size = SizeClass::kSmall;
  int32_t partner = 0;  // touching same-class instance, 0 = none
};

struct Scene {
  LabelImage instances;
  LabelImage semantics;
  std::map<int32_t, InstanceInfo> infos;
  std::vector<Thing> things;
};

// Draws a rectangle or the ellipse inscribed in it.
void draw(Scene& scene, const Thing& t, bool ellipse) {
  const double cx = t.box.x + 0.5 * t.box.width, cy = t.box.y + 0.5 * t.box.height;
  for (int v = t.box.y; v < t.box.y + t.box.height; ++v) {
    for (int u = t.box.x; u < t.box.x + t.box.width; ++u) {
      const double x = (u + 0.5 - cx) / (0.5 * t.box.width),
                   y = (v + 0.5 - cy) / (0.5 * t.box.height);
      if (ellipse && x * x + y * y > 1.0) continue;
      scene.instances(u, v) = t.id;
      scene.semantics(u, v) = t.cls;
    }
  }
  InstanceInfo info;
  info.semantic = t.cls;
  info.extent_m = t.extent_m;
  scene.infos[t.id] = info;
  scene.things.push_back(t);
}

// A 640x480 view of a wall (top) and floor (bottom) with 43 things: 3 rows of 6 cells holding
// one large object (> 5000 px), a touching same-class pair (2880 px each) or four small objects
// (< 1000 px), a 2 m bed on an open floor, and a corner without depth.
Scene makeScene() {
  Scene s;
  s.instances = LabelImage(kWidth, kHeight, 0);
  s.semantics = LabelImage(kWidth, kHeight, 0);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      if (u >= 590 && v >= 430) continue;  // no depth
      const bool wall = v < 200;
      s.instances(u, v) = wall ? 1 : 2;
      s.semantics(u, v) = wall ? kWall : kFloor;
    }
  }
  s.infos[1] = InstanceInfo{kWall, 6.0f, true};
  s.infos[2] = InstanceInfo{kFloor, 6.0f, true};
  const int32_t large_classes[] = {6, 7, 3, 10, 24, 36};
  const int32_t pair_classes[] = {5, 5, 11, 3, 7, 33};
  const int32_t small_classes[] = {11, 34, 5,  9,  33, 28, 16, 39, 3, 10, 6, 7,
                                   14, 12, 24, 36, 8,  4,  5,  11, 9, 34, 3, 39};
  const cv::Size small_sizes[] = {{24, 24}, {32, 34}, {20, 30}, {26, 26}};
  int32_t next = 10;
  int large = 0, pair = 0, small = 0;
  for (int cell = 0; cell < 18; ++cell) {
    const int x0 = 10 + 105 * (cell % 6), y0 = 10 + 115 * (cell / 6);
    if (cell % 3 == 0) {
      const int32_t cls = pair_classes[pair++];
      Thing a{next++, cls, cv::Rect(x0 + 2, y0 + 25, 48, 60), 0.8f, SizeClass::kMedium};
      Thing b{next++, cls, cv::Rect(x0 + 50, y0 + 25, 48, 60), 0.8f, SizeClass::kMedium};
      a.partner = b.id;
      b.partner = a.id;
      draw(s, a, false);
      draw(s, b, false);
    } else if (cell % 3 == 1) {
      Thing t{next++, large_classes[large], cv::Rect(x0 + 3, y0 + 5, 94, 100),
              large < 4 ? 2.0f : 1.0f, SizeClass::kLarge};
      draw(s, t, large % 2 == 1);
      ++large;
    } else {
      for (int q = 0; q < 4; ++q) {
        const cv::Size size = small_sizes[(small + q) % 4];
        const int sx = x0 + 50 * (q % 2) + (50 - size.width) / 2;
        const int sy = y0 + 55 * (q / 2) + (55 - size.height) / 2;
        Thing t{next++, small_classes[small % 24], cv::Rect(sx, sy, size.width, size.height), 0.3f,
                SizeClass::kSmall};
        draw(s, t, q % 2 == 1);
        ++small;
      }
    }
  }
  draw(s, Thing{next++, 4, cv::Rect(20, 370, 170, 80), 2.0f, SizeClass::kLarge}, false);
  return s;
}

// Classes a thing of class `cls` may be confused with under the default groups.
std::set<int32_t> confusable(int32_t cls) {
  std::set<int32_t> out;
  for (const auto& group : SegmenterNoiseConfig().confusion_groups) {
    if (std::find(group.begin(), group.end(), cls) == group.end()) continue;
    for (int32_t c : group) {
      if (c != cls) out.insert(c);
    }
  }
  return out;
}

void expectConsistent(const PanopticFrame& frame) {
  std::map<int32_t, const PanopticSegment*> by_id;
  for (const auto& seg : frame.segments) {
    ASSERT_GT(seg.id, 0);
    ASSERT_TRUE(by_id.emplace(seg.id, &seg).second) << "duplicate id " << seg.id;
    EXPECT_EQ(seg.category, seg.source_category);
    EXPECT_GE(seg.score, 0.0f);
    EXPECT_LE(seg.score, 1.0f);
    EXPECT_EQ(isStuffClass(seg.category), !seg.is_thing) << "segment " << seg.id;
  }
  std::set<int32_t> present;
  for (int32_t id : frame.segment_ids.pixels()) {
    if (id != 0) present.insert(id);
  }
  for (int32_t id : present) EXPECT_TRUE(by_id.count(id)) << "segment " << id << " not listed";
  for (const auto& [id, seg] : by_id)
    EXPECT_TRUE(present.count(id)) << "segment " << id << " empty";
}

// Pixel counts of (instance, segment) pairs over one frame.
class Overlap {
 public:
  Overlap(const Scene& scene, const PanopticFrame& frame) {
    for (const auto& seg : frame.segments) max_seg_ = std::max(max_seg_, seg.id);
    counts_.assign(static_cast<size_t>(kMaxId) * (max_seg_ + 1), 0);
    const auto& ids = scene.instances.pixels();
    const auto& segs = frame.segment_ids.pixels();
    for (size_t i = 0; i < ids.size(); ++i) ++counts_[ids[i] * (max_seg_ + 1) + segs[i]];
  }
  int count(int32_t instance, int32_t segment) const {
    return counts_[instance * (max_seg_ + 1) + segment];
  }
  // Segments covering the instance, largest share first.
  std::vector<std::pair<int, int32_t>> cover(int32_t instance) const {
    std::vector<std::pair<int, int32_t>> out;
    for (int32_t s = 1; s <= max_seg_; ++s) {
      if (count(instance, s) > 0) out.push_back({count(instance, s), s});
    }
    std::sort(out.rbegin(), out.rend());
    return out;
  }
  static constexpr int kMaxId = 128;

 private:
  int32_t max_seg_ = 0;
  std::vector<int> counts_;
};

const PanopticSegment* findSegment(const PanopticFrame& frame, int32_t id) {
  for (const auto& seg : frame.segments) {
    if (seg.id == id) return &seg;
  }
  return nullptr;
}

// Outline pixels of a mask: inside, with a 4-neighbour inside the image that is outside.
cv::Mat outline(const cv::Mat& mask, const cv::Rect& roi, const cv::Size& image) {
  cv::Mat out(roi.size(), CV_8U, cv::Scalar(0));
  for (int v = roi.y; v < roi.y + roi.height; ++v) {
    for (int u = roi.x; u < roi.x + roi.width; ++u) {
      if (!mask.at<uint8_t>(v, u)) continue;
      const bool edge = (u > 0 && !mask.at<uint8_t>(v, u - 1)) ||
                        (u + 1 < image.width && !mask.at<uint8_t>(v, u + 1)) ||
                        (v > 0 && !mask.at<uint8_t>(v - 1, u)) ||
                        (v + 1 < image.height && !mask.at<uint8_t>(v + 1, u));
      out.at<uint8_t>(v - roi.y, u - roi.x) = edge ? 255 : 0;
    }
  }
  return out;
}

// Adds the distances from the true outline of `instance` to the nearest outline pixel of
// `segment` (the predicted mask of the same object).
void addOutlineDistances(const Scene& scene, const PanopticFrame& frame, const Thing& thing,
                         int32_t segment, double* sum, int64_t* count) {
  const cv::Size image(kWidth, kHeight);
  const cv::Rect roi =
      cv::Rect(thing.box.x - 20, thing.box.y - 20, thing.box.width + 40, thing.box.height + 40) &
      cv::Rect(0, 0, kWidth, kHeight);
  cv::Mat gt(image, CV_8U, cv::Scalar(0)), pred(image, CV_8U, cv::Scalar(0));
  for (int v = roi.y; v < roi.y + roi.height; ++v) {
    for (int u = roi.x; u < roi.x + roi.width; ++u) {
      gt.at<uint8_t>(v, u) = scene.instances(u, v) == thing.id;
      pred.at<uint8_t>(v, u) = frame.segment_ids(u, v) == segment;
    }
  }
  const cv::Mat gt_outline = outline(gt, roi, image);
  const cv::Mat pred_outline = outline(pred, roi, image);
  cv::Mat dist;
  cv::distanceTransform(255 - pred_outline, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  for (int v = 0; v < roi.height; ++v) {
    for (int u = 0; u < roi.width; ++u) {
      if (!gt_outline.at<uint8_t>(v, u)) continue;
      *sum += dist.at<float>(v, u);
      ++*count;
    }
  }
}

double linearMiss(const SegmenterNoiseConfig& c, double px) {
  const double t = (px - c.miss_small_px) / (c.miss_large_px - c.miss_small_px);
  return c.miss_probability_small + t * (c.miss_probability_large - c.miss_probability_small);
}

TEST(SegmenterNoise, CleanReturnsTheGroundTruthPartition) {
  const Scene scene = makeScene();
  SegmenterNoise noise(SegmenterNoiseConfig::fromPreset("clean"), 3);
  SegmenterTrace trace;
  const PanopticFrame frame =
      noise.segment(scene.instances, scene.semantics, 5, scene.infos, &trace);
  expectConsistent(frame);
  EXPECT_EQ(frame.frame_id, 5);
  ASSERT_EQ(frame.segments.size(), 2 + scene.things.size());
  // Ground-truth key per pixel: thing id, or -class for stuff (merged per class), 0 = none.
  std::map<int32_t, int32_t> seg_of_key, key_of_seg;
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const int32_t id = scene.instances(u, v);
      const int32_t key = id == 0 ? 0 : scene.infos.at(id).is_stuff ? -scene.semantics(u, v) : id;
      const int32_t seg = frame.segment_ids(u, v);
      ASSERT_EQ(key == 0, seg == 0) << "pixel " << u << "," << v;
      if (key == 0) continue;
      ASSERT_EQ(seg_of_key.emplace(key, seg).first->second, seg) << "instance split at " << u;
      ASSERT_EQ(key_of_seg.emplace(seg, key).first->second, key) << "segments merged at " << u;
    }
  }
  for (const auto& seg : frame.segments) {
    const int32_t key = key_of_seg.at(seg.id);
    EXPECT_EQ(seg.score, 1.0f);
    EXPECT_EQ(seg.is_thing, key > 0);
    EXPECT_EQ(seg.category, key > 0 ? scene.infos.at(key).semantic : -key);
  }
  EXPECT_TRUE(trace.missed.empty());
  const SegmenterNoiseStats& stats = noise.stats();
  EXPECT_EQ(stats.things_seen, static_cast<int64_t>(scene.things.size()));
  EXPECT_EQ(
      stats.missed + stats.confused + stats.merged_pairs + stats.split + stats.false_positives, 0);
  EXPECT_EQ(stats.meanBoundaryErrorPx(), 0.0);
}

TEST(SegmenterNoise, SameSeedSameOutputOtherSeedDiffers) {
  const Scene scene = makeScene();
  const auto config = SegmenterNoiseConfig::fromPreset("m2f");
  SegmenterNoise a(config, 42), b(config, 42), c(config, 43);
  bool differs = false;
  for (int t = 0; t < 10; ++t) {
    const PanopticFrame fa = a.segment(scene.instances, scene.semantics, t, scene.infos);
    const PanopticFrame fb = b.segment(scene.instances, scene.semantics, t, scene.infos);
    const PanopticFrame fc = c.segment(scene.instances, scene.semantics, t, scene.infos);
    EXPECT_TRUE(fa.segment_ids == fb.segment_ids) << "frame " << t;
    EXPECT_TRUE(fa.segments == fb.segments) << "frame " << t;
    differs = differs || !(fa.segment_ids == fc.segment_ids) || !(fa.segments == fc.segments);
  }
  EXPECT_TRUE(differs);
}

TEST(SegmenterNoise, OutputIsAConsistentPanopticFrame) {
  const Scene scene = makeScene();
  for (const std::string preset : {"m2f", "hard"}) {
    SegmenterNoise noise(SegmenterNoiseConfig::fromPreset(preset), 11);
    for (int t = 0; t < 40; t += 3) {
      SegmenterTrace trace;
      const PanopticFrame frame =
          noise.segment(scene.instances, scene.semantics, t, scene.infos, &trace);
      SCOPED_TRACE(preset + " frame " + std::to_string(t));
      expectConsistent(frame);
      ASSERT_EQ(trace.origins.size(), frame.segments.size());
      // Pixels without depth stay without segment unless the boundary warp moved a label in.
      EXPECT_EQ(frame.segment_ids(kWidth - 1, kHeight - 1), 0);
    }
  }
}

// Every rate of the m2f preset, measured on the output against the ground truth. Windows of one
// frame make the frames independent samples; persistence is tested below with the real window.
TEST(SegmenterNoise, M2fRatesMatchThePreset) {
  const Scene scene = makeScene();
  SegmenterNoiseConfig config = SegmenterNoiseConfig::fromPreset("m2f");
  config.window_frames = 1;
  SegmenterNoise noise(config, 2024);
  std::map<SizeClass, std::pair<int, int>> miss;  // size -> (missed, seen)
  int confusable_seen = 0, confused = 0, pairs_seen = 0, merged = 0, split_seen = 0, split = 0;
  int false_positives = 0, trace_disagreements = 0;
  double outline_sum = 0.0;
  int64_t outline_count = 0;
  double true_score_sum = 0.0, wrong_score_sum = 0.0;
  int true_scores = 0, wrong_scores = 0;
  const int frames = 300;
  for (int t = 0; t < frames; ++t) {
    SegmenterTrace trace;
    const PanopticFrame frame =
        noise.segment(scene.instances, scene.semantics, t, scene.infos, &trace);
    const Overlap overlap(scene, frame);
    // False positives: thing segments lying mostly on wall and floor.
    std::set<int32_t> hallucinated;
    for (const auto& seg : frame.segments) {
      if (!seg.is_thing) continue;
      const int on_stuff = overlap.count(1, seg.id) + overlap.count(2, seg.id);
      int total = 0;
      for (int32_t id = 0; id < Overlap::kMaxId; ++id) total += overlap.count(id, seg.id);
      if (on_stuff * 10 >= total * 7) hallucinated.insert(seg.id);
    }
    false_positives += static_cast<int>(hallucinated.size());
    auto isObject = [&](int32_t seg) {
      return findSegment(frame, seg)->is_thing && !hallucinated.count(seg);
    };
    std::map<int32_t, int32_t> main_segment;  // instance -> segment covering most of it
    for (const Thing& thing : scene.things) {
      const auto cover = overlap.cover(thing.id);
      int thing_px = 0, total_px = overlap.count(thing.id, 0);
      for (const auto& [px, seg] : cover) {
        total_px += px;
        thing_px += isObject(seg) ? px : 0;
      }
      const bool detected = thing_px * 10 >= total_px * 3;
      const bool traced_missed =
          std::binary_search(trace.missed.begin(), trace.missed.end(), thing.id);
      trace_disagreements += detected == traced_missed;
      ++miss[thing.size].second;
      if (!detected) {
        ++miss[thing.size].first;
        continue;
      }
      int32_t seg = 0;  // the thing segment covering most of it
      for (const auto& [px, s] : cover) {
        if (seg == 0 && isObject(s)) seg = s;
      }
      main_segment[thing.id] = seg;
      const PanopticSegment* segment = findSegment(frame, seg);
      const std::set<int32_t> group = confusable(thing.cls);
      if (!group.empty()) {
        ++confusable_seen;
        if (segment->category != thing.cls) {
          ++confused;
          EXPECT_TRUE(group.count(segment->category))
              << "class " << thing.cls << " confused with " << segment->category;
        }
      } else {
        EXPECT_EQ(segment->category, thing.cls);
      }
      if (thing.extent_m > config.split_min_extent_m) {
        ++split_seen;
        split += cover.size() >= 2 && cover[1].first * 5 >= total_px;
      }
    }
    for (const Thing& thing : scene.things) {
      if (thing.partner < thing.id || !main_segment.count(thing.id) ||
          !main_segment.count(thing.partner)) {
        continue;
      }
      ++pairs_seen;
      merged += main_segment[thing.id] == main_segment[thing.partner];
    }
    // Boundary error of objects predicted whole (not merged or split).
    if (t % 10 == 0) {
      std::map<int32_t, int> uses;
      for (const auto& [instance, seg] : main_segment) ++uses[seg];
      for (const Thing& thing : scene.things) {
        if (!main_segment.count(thing.id) || uses[main_segment[thing.id]] > 1) continue;
        if (overlap.cover(thing.id).size() > 1 && thing.extent_m > config.split_min_extent_m) {
          continue;
        }
        addOutlineDistances(scene, frame, thing, main_segment[thing.id], &outline_sum,
                            &outline_count);
      }
    }
    for (size_t i = 0; i < frame.segments.size(); ++i) {
      const SegmentOrigin& o = trace.origins[i];
      if (!frame.segments[i].is_thing) continue;
      const bool wrong = o.confused || o.merged || o.split || o.false_positive;
      (wrong ? wrong_score_sum : true_score_sum) += frame.segments[i].score;
      ++(wrong ? wrong_scores : true_scores);
    }
  }
  const SegmenterNoiseStats& stats = noise.stats();
  auto rate = [](int a, int b) { return b > 0 ? static_cast<double>(a) / b : -1.0; };
  const double large = rate(miss[SizeClass::kLarge].first, miss[SizeClass::kLarge].second);
  const double medium = rate(miss[SizeClass::kMedium].first, miss[SizeClass::kMedium].second);
  const double small = rate(miss[SizeClass::kSmall].first, miss[SizeClass::kSmall].second);
  const double outline_error = outline_sum / outline_count;
  std::printf(
      "stats: miss large %.3f small %.3f | confusion %.3f | merge %.3f (%lld pairs) | split %.3f "
      "(%lld) | fp/frame %.3f\n",
      stats.largeMissRate(), stats.smallMissRate(), stats.confusionRate(), stats.mergeRate(),
      static_cast<long long>(stats.touching_pairs), stats.splitRate(),
      static_cast<long long>(stats.split_candidates), stats.falsePositivesPerFrame());
  std::printf(
      "miss large %.3f medium %.3f small %.3f | confusion %.3f | merge %.3f | split %.3f | "
      "fp/frame "
      "%.3f | outline %.2f px (stats %.2f) | score true %.3f wrong %.3f\n",
      large, medium, small, rate(confused, confusable_seen), rate(merged, pairs_seen),
      rate(split, split_seen), static_cast<double>(false_positives) / frames, outline_error,
      stats.meanBoundaryErrorPx(), true_score_sum / true_scores, wrong_score_sum / wrong_scores);

  // +-30 % relative: several hundred to thousands of independent samples each.
  const double tol = 0.3;
  EXPECT_NEAR(large, config.miss_probability_large, tol * config.miss_probability_large);
  EXPECT_NEAR(small, config.miss_probability_small, tol * config.miss_probability_small);
  const double medium_expected = linearMiss(config, 48 * 60);
  EXPECT_NEAR(medium, medium_expected, tol * medium_expected);
  EXPECT_NEAR(rate(confused, confusable_seen), config.confusion_probability,
              tol * config.confusion_probability);
  EXPECT_NEAR(rate(merged, pairs_seen), config.merge_probability, tol * config.merge_probability);
  EXPECT_NEAR(rate(split, split_seen), config.split_probability, tol * config.split_probability);
  EXPECT_NEAR(static_cast<double>(false_positives) / frames, config.false_positives_per_frame,
              tol * config.false_positives_per_frame);
  EXPECT_NEAR(outline_error, config.boundary_mean_px, tol * config.boundary_mean_px);
  EXPECT_GT(true_score_sum / true_scores - wrong_score_sum / wrong_scores, 0.2);
  // The trace agrees with what the image shows, and the stats with the measurements.
  EXPECT_LE(trace_disagreements, frames * static_cast<int>(scene.things.size()) / 200);
  EXPECT_EQ(stats.frames, frames);
  EXPECT_EQ(stats.things_seen, frames * static_cast<int64_t>(scene.things.size()));
  EXPECT_NEAR(stats.largeMissRate(), large, 0.02);
  EXPECT_NEAR(stats.smallMissRate(), small, 0.02);
  EXPECT_NEAR(stats.confusionRate(), rate(confused, confusable_seen), 0.02);
  EXPECT_NEAR(stats.mergeRate(), rate(merged, pairs_seen), 0.03);
  EXPECT_NEAR(stats.splitRate(), rate(split, split_seen), 0.03);
  EXPECT_NEAR(stats.falsePositivesPerFrame(), static_cast<double>(false_positives) / frames, 0.05);
  EXPECT_NEAR(stats.meanBoundaryErrorPx(), config.boundary_mean_px, tol * config.boundary_mean_px);
}

TEST(SegmenterNoise, ErrorsPersistOverNeighbouringFrames) {
  const Scene scene = makeScene();
  const auto config = SegmenterNoiseConfig::fromPreset("m2f");
  SegmenterNoise noise(config, 77);
  std::map<int32_t, std::vector<bool>> missed, confused;  // per instance, per frame
  const int frames = 300;
  for (int t = 0; t < frames; ++t) {
    SegmenterTrace trace;
    const PanopticFrame frame =
        noise.segment(scene.instances, scene.semantics, t, scene.infos, &trace);
    std::map<int32_t, bool> is_confused;
    for (size_t i = 0; i < frame.segments.size(); ++i) {
      for (int32_t id : trace.origins[i].instances) is_confused[id] = trace.origins[i].confused;
    }
    for (const Thing& thing : scene.things) {
      missed[thing.id].push_back(
          std::binary_search(trace.missed.begin(), trace.missed.end(), thing.id));
      confused[thing.id].push_back(is_confused[thing.id]);
    }
  }
  auto persistence = [&](const std::map<int32_t, std::vector<bool>>& events, double* base) {
    int on = 0, total = 0, on_then_on = 0;
    for (const auto& [id, e] : events) {
      for (int t = 0; t + 1 < frames; ++t) {
        ++total;
        on += e[t];
        on_then_on += e[t] && e[t + 1];
      }
    }
    *base = static_cast<double>(on) / total;
    return static_cast<double>(on_then_on) / on;
  };
  double miss_base = 0.0, confusion_base = 0.0;
  const double miss_again = persistence(missed, &miss_base);
  const double confused_again = persistence(confused, &confusion_base);
  std::printf("miss %.3f, again next frame %.3f | confusion %.3f, again %.3f\n", miss_base,
              miss_again, confusion_base, confused_again);
  // A window of 15 frames keeps an error for the next frame 14 times in 15.
  EXPECT_GT(miss_again, 0.85);
  EXPECT_GT(miss_again, 2.5 * miss_base);
  EXPECT_GT(confused_again, 0.85);
  EXPECT_GT(confused_again, 5.0 * confusion_base);
  // The rates still follow the preset (fewer independent samples: 20 windows per instance).
  const double expected = (7 * config.miss_probability_large + 12 * linearMiss(config, 48 * 60) +
                           24 * config.miss_probability_small) /
                          43.0;
  EXPECT_NEAR(miss_base, expected, 0.3 * expected);
}

TEST(SegmenterNoise, OcclusionRaisesTheMissRate) {
  Scene scene;
  scene.instances = LabelImage(160, 120, 1);
  scene.semantics = LabelImage(160, 120, kWall);
  scene.infos[1] = InstanceInfo{kWall, 4.0f, true};
  for (int v = 20; v < 100; ++v) {
    for (int u = 10; u < 150; ++u) scene.instances(u, v) = u < 80 ? 5 : 6;  // 5600 px each
  }
  scene.infos[5] = InstanceInfo{7, 1.0f, false, 0.0f};
  scene.infos[6] = InstanceInfo{24, 1.0f, false, 0.8f};
  SegmenterNoiseConfig config = SegmenterNoiseConfig::fromPreset("m2f");
  config.window_frames = 1;
  SegmenterNoise noise(config, 5);
  int visible_missed = 0, occluded_missed = 0;
  const int frames = 400;
  for (int t = 0; t < frames; ++t) {
    SegmenterTrace trace;
    noise.segment(scene.instances, LabelImage(), t, scene.infos, &trace);
    visible_missed += std::count(trace.missed.begin(), trace.missed.end(), 5);
    occluded_missed += std::count(trace.missed.begin(), trace.missed.end(), 6);
  }
  EXPECT_NEAR(static_cast<double>(visible_missed) / frames, config.miss_probability_large, 0.04);
  EXPECT_NEAR(static_cast<double>(occluded_missed) / frames, config.miss_probability_occluded,
              0.08);
}

TEST(SegmenterNoise, PresetsAndInvalidConfigs) {
  EXPECT_EQ(SegmenterNoiseConfig::fromPreset("clean").boundary_mean_px,
            SegmenterNoiseConfig().boundary_mean_px);
  const auto m2f = SegmenterNoiseConfig::fromPreset("m2f");
  const auto hard = SegmenterNoiseConfig::fromPreset("hard");
  EXPECT_NO_THROW(m2f.check());
  EXPECT_NO_THROW(hard.check());
  EXPECT_DOUBLE_EQ(hard.boundary_mean_px, 1.5 * m2f.boundary_mean_px);
  EXPECT_GT(hard.miss_probability_large, 1.9 * m2f.miss_probability_large);
  EXPECT_GT(hard.false_positives_per_frame, 1.9 * m2f.false_positives_per_frame);
  EXPECT_THROW(SegmenterNoiseConfig::fromPreset("perfect"), Error);

  auto expectBad = [](const std::string& field, auto mutate) {
    SegmenterNoiseConfig c = SegmenterNoiseConfig::fromPreset("m2f");
    mutate(c);
    try {
      c.check();
      ADD_FAILURE() << field << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
    EXPECT_THROW(SegmenterNoise(c, 1), Error);
  };
  expectBad("miss_probability_small", [](auto& c) { c.miss_probability_small = -0.1; });
  expectBad("merge_probability", [](auto& c) { c.merge_probability = 1.5; });
  expectBad("confusion_probability", [](auto& c) { c.confusion_probability = std::nan(""); });
  expectBad("window_frames", [](auto& c) { c.window_frames = 0; });
  expectBad("miss_large_px", [](auto& c) { c.miss_large_px = 500; });
  expectBad("boundary_mean_px", [](auto& c) { c.boundary_mean_px = -1.0; });
  expectBad("false_positives_per_frame", [](auto& c) { c.false_positives_per_frame = -0.5; });
  expectBad("confusion_groups", [](auto& c) { c.confusion_groups = {{5, 2}}; });
  expectBad("wrong_score_beta", [](auto& c) { c.wrong_score_beta = 0.0; });

  // Inputs the caller got wrong.
  const Scene scene = makeScene();
  SegmenterNoise noise(m2f, 1);
  auto infos = scene.infos;
  infos.erase(10);
  EXPECT_THROW(noise.segment(scene.instances, scene.semantics, 0, infos), Error);
  EXPECT_THROW(noise.segment(scene.instances, LabelImage(10, 10), 0, scene.infos), Error);
}

}  // namespace
}  // namespace panmap
