#include "panmap/sim/segmenter_noise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/sim/internal/boundary_warp.h"
#include "panmap/sim/internal/false_positive_blob.h"
#include "panmap/sim/internal/segmenter_random.h"

namespace panmap {
namespace {

using internal::segmenter::Blob;
using internal::segmenter::FrameContext;
using internal::segmenter::hashOf;
using internal::segmenter::kClutter;
using internal::segmenter::kClutterClass;
using internal::segmenter::kConfuse;
using internal::segmenter::kConfuseClass;
using internal::segmenter::key;
using internal::segmenter::kFalsePositive;
using internal::segmenter::kFalsePositiveShape;
using internal::segmenter::kMerge;
using internal::segmenter::kMiss;
using internal::segmenter::kPi;
using internal::segmenter::kScore;
using internal::segmenter::kSplit;
using internal::segmenter::kSplitAngle;
using internal::segmenter::SegmenterRng;
using internal::segmenter::toUnit;
using internal::segmenter::warpLabels;

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
  bool clutter = false;      // class 0 with an instance id: unannotated clutter
  int32_t paint_stuff = 0;   // clutter painted into this stuff unit (0 = not)
  int32_t paint_class = 0;   // clutter painted as a thing of this class (0 = not)
};

int32_t findRoot(std::vector<Unit>& units, int32_t k) {
  while (units[k].parent != k) {
    units[k].parent = units[units[k].parent].parent;
    k = units[k].parent;
  }
  return k;
}

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

struct Draft {
  PanopticSegment segment;
  SegmentOrigin origin;
  uint64_t score_key = 0;
  int64_t px = 0;
};

}  // namespace

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

  const bool paint_clutter = c.clutter_stuff_probability + c.clutter_thing_probability > 0.0;
  // 1. Compact labels: unit 0 = nothing, one unit per thing instance, one per stuff class, one
  // per clutter instance.
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
    } else if (info.semantic == kUnknownClass) {
      if (paint_clutter) {
        index = static_cast<int32_t>(units.size());
        Unit unit;
        unit.instance = id;
        unit.clutter = true;
        units.push_back(unit);
      }
    } else {
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
  bool any_clutter = false;
  for (int32_t k = 1; k < unit_count; ++k) {
    is_thing[k] = !units[k].stuff && !units[k].clutter;
    any_clutter = any_clutter || units[k].clutter;
  }

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

  // 3b. Which stuff each clutter instance touches in the image, to be painted into.
  std::map<std::pair<int32_t, int32_t>, int> clutter_contacts;  // (clutter, stuff) -> pixel edges
  if (any_clutter) {
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const size_t i = static_cast<size_t>(v) * width + u;
        const int32_t a = gt[i];
        const int32_t right = u + 1 < width ? gt[i + 1] : 0;
        const int32_t down = v + 1 < height ? gt[i + width] : 0;
        for (const int32_t b : {right, down}) {
          if (units[a].clutter && units[b].stuff) ++clutter_contacts[{a, b}];
          if (units[b].clutter && units[a].stuff) ++clutter_contacts[{b, a}];
        }
      }
    }
  }

  // 4. Per-instance decisions: miss, then class confusion; clutter: how it is painted.
  double clutter_weight_sum = 0.0;
  for (double w : c.clutter_thing_weights) clutter_weight_sum += w;
  for (int32_t k = 1; k < unit_count; ++k) {
    Unit& unit = units[k];
    unit.parent = k;
    if (unit.stuff) continue;
    if (unit.clutter) {
      const uint64_t subject = key(unit.instance);
      const double draw = ctx.draw(subject, kClutter);
      if (draw < c.clutter_stuff_probability) {
        int best = 0;
        for (auto it = clutter_contacts.lower_bound({k, 0});
             it != clutter_contacts.end() && it->first.first == k; ++it) {
          if (it->second > best) best = it->second, unit.paint_stuff = it->first.second;
        }
      } else if (draw < c.clutter_stuff_probability + c.clutter_thing_probability) {
        double pick = toUnit(ctx.windowHash(subject, kClutter, kClutterClass)) * clutter_weight_sum;
        unit.paint_class = c.clutter_thing_classes.back();
        for (size_t j = 0; j < c.clutter_thing_classes.size(); ++j) {
          if (pick < c.clutter_thing_weights[j]) {
            unit.paint_class = c.clutter_thing_classes[j];
            break;
          }
          pick -= c.clutter_thing_weights[j];
        }
      }
      continue;
    }
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
  // Clutter painted into stuff takes that stuff's segment; painted as a thing, its own.
  for (int32_t k = 1; k < unit_count; ++k) {
    Unit& r = units[k];
    if (!r.clutter) continue;
    if (r.paint_stuff > 0) {
      lut[k] = units[r.paint_stuff].seg;
    } else if (r.paint_class > 0) {
      lut[k] = r.seg = newDraft(r.paint_class, true, hashOf({4, key(r.instance)}));
      drafts.back().origin.clutter = true;
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
    SegmenterRng rng(ctx.windowHash(subject, kFalsePositive, kFalsePositiveShape));
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
    const bool wrong = o.confused || o.merged || o.split || o.false_positive || o.clutter;
    if (c.sample_scores) {
      SegmenterRng rng(hashOf({seed_, kScore, key(frame_index), d.score_key}));
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
    if (r.clutter && r.gt_px >= c.stats_min_px) {
      ++s.clutter_seen;
      s.clutter_stuff += r.paint_stuff > 0;
      s.clutter_thing += r.paint_class > 0;
    }
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
