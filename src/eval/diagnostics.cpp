#include "panmap/eval/diagnostics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <memory>
#include <unordered_map>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/core/nearest_point.h"
#include "panmap/eval/instance_matching.h"

namespace panmap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What a GT vertex belongs to for purity: a thing instance, or a stuff class as a whole (the
// annotation cuts walls into pieces where they meet; a super-point may span them).
std::pair<int32_t, int32_t> identity(int32_t cls, int32_t instance) {
  return {cls, isStuffClass(cls) ? 0 : instance};
}

double stuffIoU(const LabelledMesh& gt, const TransferredLabels& pred, int32_t c) {
  int64_t tp = 0, fp = 0, fn = 0;
  for (size_t v = 0; v < gt.numVertices(); ++v) {
    if (gt.semantic[v] <= 0) continue;
    if (gt.semantic[v] == c) {
      (pred.semantic[v] == c ? tp : fn) += 1;
    } else if (pred.semantic[v] == c) {
      ++fp;
    }
  }
  return tp + fp + fn > 0 ? static_cast<double>(tp) / static_cast<double>(tp + fp + fn) : kNaN;
}

// Share of class c's annotated GT vertices that found a predicted vertex (NaN: none of class c).
double observedShare(const LabelledMesh& gt, const TransferredLabels& pred, int32_t c) {
  int64_t total = 0, reached = 0;
  for (size_t v = 0; v < gt.numVertices(); ++v) {
    if (gt.semantic[v] != c) continue;
    ++total;
    reached += pred.reached.empty() || pred.reached[v];
  }
  return total > 0 ? static_cast<double>(reached) / static_cast<double>(total) : kNaN;
}

// Annotated GT vertices with no annotated vertex of another class within band_m: where the
// class is certain at the map's resolution. A hash grid of band_m cells; the 27 cells around a
// vertex hold every vertex within band_m of it.
std::vector<bool> awayFromClassBoundaries(const LabelledMesh& gt, double band_m) {
  const size_t n = gt.numVertices();
  std::vector<bool> away(n, false);
  for (size_t v = 0; v < n; ++v) away[v] = gt.semantic[v] > 0;
  if (!(band_m > 0.0)) return away;
  auto cell = [band_m](float x) { return static_cast<int64_t>(std::floor(x / band_m)); };
  auto key = [](int64_t x, int64_t y, int64_t z) {
    return ((x & 0x1FFFFF) << 42) | ((y & 0x1FFFFF) << 21) | (z & 0x1FFFFF);
  };
  std::unordered_map<int64_t, std::vector<uint32_t>> grid;
  for (size_t v = 0; v < n; ++v) {
    if (gt.semantic[v] <= 0) continue;
    const Eigen::Vector3f& p = gt.vertices[v];
    grid[key(cell(p.x()), cell(p.y()), cell(p.z()))].push_back(static_cast<uint32_t>(v));
  }
  const double band2 = band_m * band_m;
  for (size_t v = 0; v < n; ++v) {
    if (!away[v]) continue;
    const Eigen::Vector3f& p = gt.vertices[v];
    const int64_t cx = cell(p.x()), cy = cell(p.y()), cz = cell(p.z());
    for (int64_t dx = -1; dx <= 1 && away[v]; ++dx) {
      for (int64_t dy = -1; dy <= 1 && away[v]; ++dy) {
        for (int64_t dz = -1; dz <= 1 && away[v]; ++dz) {
          const auto it = grid.find(key(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (const uint32_t w : it->second) {
            if (gt.semantic[w] != gt.semantic[v] &&
                (gt.vertices[w] - p).cast<double>().squaredNorm() <= band2) {
              away[v] = false;
              break;
            }
          }
        }
      }
    }
  }
  return away;
}

// Class mix of one super-point, largest first, and its vertex count.
std::pair<std::vector<std::pair<int32_t, double>>, int64_t> classMix(
    const std::map<int32_t, int64_t>& classes) {
  std::vector<std::pair<int32_t, int64_t>> counts(classes.begin(), classes.end());
  std::stable_sort(counts.begin(), counts.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  int64_t sum = 0;
  for (const auto& c : counts) sum += c.second;
  std::vector<std::pair<int32_t, double>> mix;
  for (const auto& [cls, count] : counts) {
    mix.emplace_back(cls, static_cast<double>(count) / static_cast<double>(sum));
  }
  return {mix, sum};
}

// A bridge's GT objects by vertex count, most first (ties: smaller class, then instance).
std::vector<SceneDiagnostics::Bridge::Part> bridgeParts(
    const std::map<std::pair<int32_t, int32_t>, int64_t>& identities) {
  std::vector<SceneDiagnostics::Bridge::Part> parts;
  for (const auto& [id, count] : identities) parts.push_back({id.first, id.second, count});
  std::stable_sort(parts.begin(), parts.end(),
                   [](const auto& a, const auto& b) { return a.vertices > b.vertices; });
  if (parts.size() > SceneDiagnostics::kBridgeInstances) {
    parts.resize(SceneDiagnostics::kBridgeInstances);
  }
  return parts;
}

// Bridge::reach_m of every bridge: one pass over the GT vertices collects each bridge's
// two classes' points, a k-d tree per class involved answers the distances.
void measureReach(const LabelledMesh& gt, const TransferredLabels& pred,
                  const std::vector<bool>& away, std::vector<SceneDiagnostics::Bridge>* bridges) {
  if (bridges->empty()) return;
  std::map<int32_t, size_t> bridge_of;  // super-point -> index in bridges
  std::map<int32_t, std::vector<Eigen::Vector3f>> class_points;
  for (size_t b = 0; b < bridges->size(); ++b) {
    const auto& bridge = (*bridges)[b];
    bridge_of[bridge.superpoint] = b;
    class_points[bridge.class_mix[0].first];
    class_points[bridge.class_mix[1].first];
  }
  const size_t n = gt.numVertices();
  for (size_t v = 0; v < n; ++v) {
    const auto it = class_points.find(gt.semantic[v]);
    if (it != class_points.end()) it->second.push_back(gt.vertices[v]);
  }
  // The map's nodes stay where they are, so each tree's pointer to its points stays valid.
  std::map<int32_t, std::unique_ptr<NearestPointIndex>> trees;
  for (const auto& [cls, points] : class_points) {
    trees[cls] = std::make_unique<NearestPointIndex>(&points);
  }
  std::vector<std::array<double, 2>> farthest(bridges->size(), {0.0, 0.0});
  // Per bridge and side: its vertices' distances to the map (when the transfer kept them).
  std::vector<std::array<std::vector<float>, 2>> to_map(bridges->size());
  const bool distances = pred.distance_m.size() == n;
  for (size_t v = 0; v < n; ++v) {
    if (!away[v]) continue;
    const auto it = bridge_of.find(pred.superpoint[v]);
    if (it == bridge_of.end()) continue;
    const auto& mix = (*bridges)[it->second].class_mix;
    const int side = gt.semantic[v] == mix[0].first ? 0 : gt.semantic[v] == mix[1].first ? 1 : -1;
    if (side < 0) continue;
    if (distances) to_map[it->second][side].push_back(pred.distance_m[v]);
    const auto& other = class_points.at(mix[1 - side].first);
    const int64_t w = trees.at(mix[1 - side].first)->nearest(gt.vertices[v]);
    if (w < 0) continue;
    const double dist = (other[static_cast<size_t>(w)] - gt.vertices[v]).cast<double>().norm();
    farthest[it->second][side] = std::max(farthest[it->second][side], dist);
  }
  for (size_t b = 0; b < bridges->size(); ++b) {
    (*bridges)[b].reach_m = std::min(farthest[b][0], farthest[b][1]);
    for (int side = 0; side < 2; ++side) {
      std::vector<float>& d = to_map[b][side];
      if (d.empty()) continue;
      // The lower median: a distance some vertex has.
      const auto mid = d.begin() + static_cast<std::ptrdiff_t>((d.size() - 1) / 2);
      std::nth_element(d.begin(), mid, d.end());
      (*bridges)[b].map_distance_m[side] = *mid;
    }
  }
}

}  // namespace

SceneDiagnostics diagnose(const LabelledMesh& gt, const TransferredLabels& pred,
                          const std::map<int32_t, double>& objects, int num_bins,
                          double boundary_band_m) {
  const size_t n = gt.numVertices();
  if (gt.semantic.size() != n || gt.instance.size() != n) {
    throw Error("diagnose: ground-truth mesh lacks semantic or instance labels");
  }
  if (pred.semantic.size() != n || pred.instance.size() != n || pred.superpoint.size() != n ||
      (!pred.reached.empty() && pred.reached.size() != n) ||
      (!pred.distance_m.empty() && pred.distance_m.size() != n)) {
    throw Error("diagnose: transferred labels do not match the ground-truth vertex count");
  }
  if (num_bins < 1) throw Error("diagnose: num_bins must be >= 1");
  if (!(boundary_band_m >= 0.0) || !std::isfinite(boundary_band_m)) {
    throw Error("diagnose: boundary_band_m must be finite and >= 0, got " +
                std::to_string(boundary_band_m));
  }
  SceneDiagnostics d;
  d.boundary_band_m = boundary_band_m;
  const std::vector<bool> away = awayFromClassBoundaries(gt, boundary_band_m);

  // Super-points: identities and classes of their annotated vertices.
  std::map<int32_t, std::map<std::pair<int32_t, int32_t>, int64_t>> sp_identities;
  std::map<int32_t, std::map<std::pair<int32_t, int32_t>, int64_t>> sp_identities_away;
  std::map<int32_t, std::map<int32_t, int64_t>> sp_classes, sp_classes_away;
  std::map<int32_t, std::pair<int64_t, int64_t>> sp_size;  // all, unannotated
  for (size_t v = 0; v < n; ++v) {
    const int32_t s = pred.superpoint[v];
    if (s == 0) continue;
    auto& size = sp_size[s];
    ++size.first;
    if (gt.semantic[v] <= 0) {
      ++size.second;
      continue;
    }
    ++sp_identities[s][identity(gt.semantic[v], gt.instance[v])];
    ++sp_classes[s][gt.semantic[v]];
    if (away[v]) {
      ++sp_classes_away[s][gt.semantic[v]];
      ++sp_identities_away[s][identity(gt.semantic[v], gt.instance[v])];
    }
  }
  int64_t total = 0, majority = 0, class_majority = 0;
  for (const auto& [s, ids] : sp_identities) {
    int64_t sum = 0, best = 0;
    for (const auto& [id, count] : ids) sum += count, best = std::max(best, count);
    total += sum;
    majority += best;
    int64_t top_class = 0;
    for (const auto& [cls, count] : sp_classes[s]) top_class = std::max(top_class, count);
    class_majority += top_class;
    const auto [mix_all, sum_all] = classMix(sp_classes[s]);
    if (sum_all >= d.min_superpoint_vertices && mix_all.size() > 1 &&
        mix_all[1].second > d.bridge_share) {
      ++d.num_bridging_superpoints_with_boundaries;
    }
    const auto [mix, sum_away] = classMix(sp_classes_away[s]);
    if (sum_away >= d.min_superpoint_vertices && mix.size() > 1) {
      d.worst_second_class_share = std::max(d.worst_second_class_share, mix[1].second);
      if (mix[1].second > d.bridge_share) {
        ++d.num_bridging_superpoints;
        d.bridges.push_back({s, sum_away, mix, 0.0, bridgeParts(sp_identities_away[s])});
      }
    }
  }
  std::stable_sort(d.bridges.begin(), d.bridges.end(),
                   [](const auto& a, const auto& b) { return a.vertices > b.vertices; });
  measureReach(gt, pred, away, &d.bridges);
  d.num_superpoints = static_cast<int64_t>(sp_identities.size());
  d.superpoint_purity = total ? static_cast<double>(majority) / static_cast<double>(total) : kNaN;
  d.superpoint_class_purity =
      total ? static_cast<double>(class_majority) / static_cast<double>(total) : kNaN;

  for (const auto& [s, size] : sp_size) {
    if (size.first > d.largest_vertices) {
      d.largest_superpoint = s;
      d.largest_vertices = size.first;
      d.largest_unannotated_vertices = size.second;
    }
  }
  if (d.largest_superpoint != 0) {
    const int64_t annotated = d.largest_vertices - d.largest_unannotated_vertices;
    for (const auto& [cls, count] : sp_classes[d.largest_superpoint]) {
      d.largest_class_mix.emplace_back(cls, static_cast<double>(count) / annotated);
    }
    std::stable_sort(d.largest_class_mix.begin(), d.largest_class_mix.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    for (const auto& [id, count] : sp_identities[d.largest_superpoint]) {
      d.largest_gt_instances += 100 * count >= annotated;
    }
  }

  d.wall_iou = stuffIoU(gt, pred, 1);
  d.floor_iou = stuffIoU(gt, pred, 2);
  d.ceiling_iou = stuffIoU(gt, pred, 22);
  d.wall_observed = observedShare(gt, pred, 1);
  d.floor_observed = observedShare(gt, pred, 2);
  d.ceiling_observed = observedShare(gt, pred, 22);

  // GT things of at least ScanNet's minimum region size.
  std::map<std::pair<int32_t, int32_t>, int64_t> thing_size;
  for (size_t v = 0; v < n; ++v) {
    const int32_t c = gt.semantic[v];
    if (c > 0 && gt.instance[v] > 0 && !isStuffClass(c)) ++thing_size[{c, gt.instance[v]}];
  }
  std::map<std::pair<int32_t, int32_t>, int> thing_index;
  for (const auto& [key, count] : thing_size) {
    if (count < kScanNetMinRegionSize) continue;
    thing_index[key] = static_cast<int>(d.gt_things.size());
    SceneDiagnostics::GtThing thing;
    thing.class_id = key.first;
    thing.instance_id = key.second;
    thing.vertices = count;
    d.gt_things.push_back(thing);
  }
  std::vector<int64_t> thing_reached(d.gt_things.size(), 0), thing_class(d.gt_things.size(), 0),
      thing_other(d.gt_things.size(), 0);
  for (size_t v = 0; v < n; ++v) {
    const auto it = thing_index.find({gt.semantic[v], gt.instance[v]});
    if (it == thing_index.end()) continue;
    thing_reached[it->second] += pred.reached.empty() || pred.reached[v];
    thing_class[it->second] += pred.semantic[v] == gt.semantic[v];
    thing_other[it->second] += pred.semantic[v] > 0 && pred.semantic[v] != gt.semantic[v];
  }

  // Predicted objects: their vertices, classes, void share and overlaps with GT things.
  std::map<int32_t, std::map<int32_t, int64_t>> pred_classes;
  std::map<int32_t, std::map<int, int64_t>> overlaps;
  std::map<int32_t, std::pair<int64_t, int64_t>> pred_size;  // all, on unannotated GT
  for (size_t v = 0; v < n; ++v) {
    const int32_t p = pred.instance[v];
    if (p <= 0) continue;
    auto& size = pred_size[p];
    ++size.first;
    ++pred_classes[p][pred.semantic[v]];
    if (gt.semantic[v] <= 0) {
      ++size.second;
      continue;
    }
    const auto it = thing_index.find({gt.semantic[v], gt.instance[v]});
    if (it != thing_index.end()) ++overlaps[p][it->second];
  }
  for (const auto& [p, by_gt] : overlaps) {
    int32_t cls = 0;
    int64_t best = -1;
    for (const auto& [c, count] : pred_classes[p]) {
      if (count > best) cls = c, best = count;
    }
    for (const auto& [g, inter] : by_gt) {
      SceneDiagnostics::GtThing& t = d.gt_things[g];
      const double iou =
          static_cast<double>(inter) / static_cast<double>(t.vertices + pred_size[p].first - inter);
      if (iou > t.best_iou) t.best_iou = iou, t.best_object = p, t.best_object_class = cls;
      if (cls == t.class_id) {
        t.best_same_class_iou = std::max(t.best_same_class_iou, iou);
        t.best_same_class_cover = std::max(
            t.best_same_class_cover, static_cast<double>(inter) / static_cast<double>(t.vertices));
      }
    }
  }
  for (size_t g = 0; g < d.gt_things.size(); ++g) {
    SceneDiagnostics::GtThing& t = d.gt_things[g];
    t.observed_share = static_cast<double>(thing_reached[g]) / static_cast<double>(t.vertices);
    t.class_share = static_cast<double>(thing_class[g]) / static_cast<double>(t.vertices);
    t.other_class_share = static_cast<double>(thing_other[g]) / static_cast<double>(t.vertices);
    // Reached vertices without a class: what neither its class nor another holds.
    const double unlabelled = t.observed_share - t.class_share - t.other_class_share;
    using Cause = SceneDiagnostics::MissCause;
    if (t.best_same_class_iou > 0.5) {
      t.cause = Cause::kMatched;
    } else if (t.observed_share <= 0.5) {
      t.cause = Cause::kUnobserved;
    } else if (t.best_same_class_iou > 0.5 * t.observed_share) {
      // The part never seen, mapped as the part seen was, adds to the overlap and to the
      // object alike: IoU / observed_share.
      t.cause = Cause::kPartlyObserved;
    } else if (t.class_share <= 0.5) {
      t.cause = t.other_class_share >= unlabelled ? Cause::kWrongClass : Cause::kUnlabelled;
    } else {
      t.cause = t.best_same_class_cover > 0.5 ? Cause::kMerged : Cause::kSplit;
    }
  }
  std::map<int32_t, double> listed = objects;
  if (listed.empty()) {
    for (const auto& [p, size] : pred_size) listed[p] = 1.0;
  }
  for (const auto& [id, confidence] : listed) {
    SceneDiagnostics::ObjectMatch o;
    o.id = id;
    o.confidence = confidence;
    const auto size = pred_size.find(id);
    if (size != pred_size.end()) {
      o.vertices = size->second.first;
      o.void_vertices = size->second.second;
      int64_t best = -1;
      for (const auto& [cls, count] : pred_classes[id]) {
        if (count > best) o.class_id = cls, best = count;  // ties: the smaller class id
      }
      for (const auto& [g, inter] : overlaps[id]) {
        const SceneDiagnostics::GtThing& t = d.gt_things[g];
        if (t.class_id != o.class_id) continue;
        const double iou =
            static_cast<double>(inter) / static_cast<double>(t.vertices + o.vertices - inter);
        if (iou > o.best_iou) o.best_iou = iou, o.best_gt = g;
      }
    }
    o.matched = o.best_iou > 0.5;
    o.unverifiable = o.vertices > 0 && 2 * o.void_vertices > o.vertices;
    d.objects.push_back(o);
  }
  d.num_objects = static_cast<int>(d.objects.size());
  d.num_checkable_objects = static_cast<int>(
      std::count_if(d.objects.begin(), d.objects.end(),
                    [](const SceneDiagnostics::ObjectMatch& o) { return !o.unverifiable; }));
  const auto perThing = [&d](int n) {
    return d.gt_things.empty() ? kNaN : static_cast<double>(n) / d.gt_things.size();
  };
  d.objects_per_gt_instance = perThing(d.num_objects);
  d.checkable_objects_per_gt_instance = perThing(d.num_checkable_objects);

  d.reliability.resize(num_bins);
  for (int b = 0; b < num_bins; ++b) {
    d.reliability[b].low = static_cast<double>(b) / num_bins;
    d.reliability[b].high = static_cast<double>(b + 1) / num_bins;
  }
  std::vector<bool> covered(d.gt_things.size(), false);
  int confident_matched = 0;
  for (const SceneDiagnostics::ObjectMatch& o : d.objects) {
    if (o.unverifiable) continue;
    const double c = std::min(1.0, std::max(0.0, o.confidence));
    const int b = std::min(num_bins - 1, static_cast<int>(c * num_bins));
    SceneDiagnostics::ReliabilityBin& bin = d.reliability[b];
    ++bin.count;
    bin.matched += o.matched;
    bin.mean_confidence += c;
    if (c >= 0.5) {
      ++d.confident_objects;
      confident_matched += o.matched;
      if (o.matched) covered[o.best_gt] = true;
    }
  }
  for (SceneDiagnostics::ReliabilityBin& bin : d.reliability) {
    if (bin.count > 0) bin.mean_confidence /= bin.count;
  }
  d.confident_precision =
      d.confident_objects > 0 ? static_cast<double>(confident_matched) / d.confident_objects : kNaN;
  d.confident_recall = d.gt_things.empty()
                           ? kNaN
                           : static_cast<double>(std::count(covered.begin(), covered.end(), true)) /
                                 static_cast<double>(d.gt_things.size());
  return d;
}

const char* missCauseName(SceneDiagnostics::MissCause cause) {
  switch (cause) {
    case SceneDiagnostics::MissCause::kMatched:
      return "matched";
    case SceneDiagnostics::MissCause::kUnobserved:
      return "unobserved";
    case SceneDiagnostics::MissCause::kWrongClass:
      return "wrong class";
    case SceneDiagnostics::MissCause::kUnlabelled:
      return "unlabelled";
    case SceneDiagnostics::MissCause::kMerged:
      return "merged";
    case SceneDiagnostics::MissCause::kSplit:
      return "split";
    case SceneDiagnostics::MissCause::kPartlyObserved:
      return "partly observed";
  }
  return "?";
}

std::string formatDiagnostics(const SceneDiagnostics& d) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line),
                "super-points: purity %.3f (by class %.3f) over %lld; %d span two classes by "
                "> %.0f %% each beyond %.1f cm of a class boundary (worst second class %.2f), "
                "%d counting the boundaries\n",
                d.superpoint_purity, d.superpoint_class_purity,
                static_cast<long long>(d.num_superpoints), d.num_bridging_superpoints,
                100 * d.bridge_share, 100 * d.boundary_band_m, d.worst_second_class_share,
                d.num_bridging_superpoints_with_boundaries);
  out += line;
  for (size_t b = 0; b < d.bridges.size() && b < 3; ++b) {
    const auto& bridge = d.bridges[b];
    std::snprintf(line, sizeof(line),
                  "  spanning super-point %d: %lld vertices, %s %.0f %%, %s %.0f %%, reaching "
                  "%.1f cm past their boundary",
                  bridge.superpoint, static_cast<long long>(bridge.vertices),
                  nyu40Name(bridge.class_mix[0].first).c_str(), 100 * bridge.class_mix[0].second,
                  nyu40Name(bridge.class_mix[1].first).c_str(), 100 * bridge.class_mix[1].second,
                  100 * bridge.reach_m);
    out += line;
    if (!std::isnan(bridge.map_distance_m[0]) && !std::isnan(bridge.map_distance_m[1])) {
      std::snprintf(line, sizeof(line), "; median distance to the map %.1f / %.1f cm",
                    100 * bridge.map_distance_m[0], 100 * bridge.map_distance_m[1]);
      out += line;
    }
    out += "\n";
  }
  std::string mix;
  for (size_t k = 0; k < d.largest_class_mix.size() && k < 5; ++k) {
    char part[64];
    std::snprintf(part, sizeof(part), "%s%s %.0f %%", k ? ", " : "",
                  nyu40Name(d.largest_class_mix[k].first).c_str(),
                  100 * d.largest_class_mix[k].second);
    mix += part;
  }
  std::snprintf(line, sizeof(line),
                "largest super-point %d: %lld GT vertices (%lld unannotated), %d GT objects, "
                "classes %s\n",
                d.largest_superpoint, static_cast<long long>(d.largest_vertices),
                static_cast<long long>(d.largest_unannotated_vertices), d.largest_gt_instances,
                mix.c_str());
  out += line;
  std::snprintf(line, sizeof(line),
                "objects: %d for %zu GT thing instances (%.2f each; %d on annotated GT, %.2f "
                "each); confidence >= 0.5: %d, %.2f of them match, covering %.2f of the GT "
                "things\n",
                d.num_objects, d.gt_things.size(), d.objects_per_gt_instance,
                d.num_checkable_objects, d.checkable_objects_per_gt_instance, d.confident_objects,
                d.confident_precision, d.confident_recall);
  out += line;
  int causes[7] = {0, 0, 0, 0, 0, 0, 0};
  for (const SceneDiagnostics::GtThing& t : d.gt_things) ++causes[static_cast<int>(t.cause)];
  std::snprintf(line, sizeof(line),
                "GT things at IoU 0.5: %d matched; missed: %d unobserved, %d partly observed, %d "
                "wrong class, %d unlabelled, %d merged, %d split\n",
                causes[0], causes[1], causes[6], causes[2], causes[3], causes[4], causes[5]);
  out += line;
  // A NaN share means the ground truth has no vertex of the class: said in words, not as "nan".
  auto stuff = [&line](const char* name, double iou, double observed) {
    if (std::isnan(observed)) {
      std::snprintf(line, sizeof(line), "%s none in GT", name);
    } else {
      std::snprintf(line, sizeof(line), "%s %.3f (%.3f)", name, iou, observed);
    }
    return std::string(line);
  };
  out += "stuff IoU (share observed): " + stuff("wall", d.wall_iou, d.wall_observed) + ", " +
         stuff("floor", d.floor_iou, d.floor_observed) + ", " +
         stuff("ceiling", d.ceiling_iou, d.ceiling_observed) + "\n";
  out += "reliability:";
  for (const SceneDiagnostics::ReliabilityBin& b : d.reliability) {
    std::snprintf(line, sizeof(line), " [%.1f,%.1f) %d/%d", b.low, b.high, b.matched, b.count);
    out += line;
  }
  out += "\n";
  return out;
}

}  // namespace panmap
