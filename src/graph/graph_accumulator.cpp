#include "panmap/graph/graph_accumulator.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "panmap/core/classes.h"
#include "panmap/core/container_memory.h"
#include "panmap/core/error.h"
#include "panmap/core/known_segments.h"
#include "panmap/map/voxel.h"

namespace panmap {

namespace {

// Image rows a thread takes at a time when sampling a frame's masks.
constexpr size_t kRowsPerChunk = 8;
// Edge pairs between fetching a pair's slot and updating it.
constexpr size_t kPrefetchPairs = 16;
// Stored pairs from which the final graph's edges are built on every thread.
constexpr size_t kParallelEdges = 1024;

}  // namespace

void GraphConfig::check() const {
  if (!(spatial_scale_m > 0.0)) throw Error("graph spatial_scale_m must be > 0");
  if (sample_stride_px < 1) throw Error("graph sample_stride_px must be >= 1");
  if (!(separation_radius_m >= 0.0)) throw Error("graph separation_radius_m must be >= 0");
  if (!(edge_min_share >= 0.0 && edge_min_share <= 1.0)) {
    throw Error("graph edge_min_share must be in [0, 1]");
  }
  if (!(surface_band_voxels > 0.0f)) throw Error("graph surface_band_voxels must be > 0");
  if (pair_interior_px < 0) throw Error("graph pair_interior_px must be >= 0");
}

GraphAccumulator::GraphAccumulator(const GraphConfig& config, ThreadPool* pool)
    : config_(config), pool_(pool) {
  config_.check();
}

const std::map<int32_t, double>& GraphAccumulator::scores(int32_t label) const {
  static const std::map<int32_t, double> kEmpty;
  const auto it = scores_.find(label);
  return it == scores_.end() ? kEmpty : it->second;
}

std::map<int32_t, double> GraphAccumulator::confidences(int32_t a, int32_t b) const {
  const auto [lo, hi] = std::minmax(a, b);
  const EdgeTable::Classes* classes = edges_.find(lo, hi);
  std::map<int32_t, double> out;
  if (classes) {
    for (const auto& [cls, value] : *classes) {
      if (cls > 0) out[cls] = value;
    }
  }
  return out;
}

double GraphAccumulator::apart(int32_t a, int32_t b) const {
  const auto [lo, hi] = std::minmax(a, b);
  const EdgeTable::Classes* classes = edges_.find(lo, hi);
  if (classes) {
    for (const auto& [cls, value] : *classes) {
      if (cls == 0) return value;
    }
  }
  return 0.0;
}

std::map<int32_t, double> GraphAccumulator::separations(int32_t a, int32_t b) const {
  const auto [lo, hi] = std::minmax(a, b);
  const EdgeTable::Classes* classes = edges_.find(lo, hi);
  std::map<int32_t, double> out;
  if (classes) {
    for (const auto& [cls, value] : *classes) {
      if (cls < 0) out[-cls] = value;
    }
  }
  return out;
}

void GraphAccumulator::applyMerges(const SuperpointTracker& tracker) {
  const auto& merges = tracker.merges();
  const size_t first_merge = merges_applied_;
  for (; merges_applied_ < merges.size(); ++merges_applied_) {
    const int32_t kept = merges[merges_applied_].kept, gone = merges[merges_applied_].removed;
    // Scores of merged super-points add up.
    const auto it = scores_.find(gone);
    if (it != scores_.end()) {
      auto& target = scores_[kept];
      for (const auto& [cls, score] : it->second) target[cls] += score;
      scores_.erase(it);
    }
  }
  // Edges of the removed ones move to the survivors; the edge between the two disappears.
  edges_.applyMerges(merges, first_merge, merges.size());
}

void GraphAccumulator::renumberSuperpoints(const SuperpointTracker& tracker,
                                           const std::vector<int32_t>& to) {
  applyMerges(tracker);
  const auto renamed = [&to](int32_t label) {
    return label > 0 && static_cast<size_t>(label) < to.size() ? to[label] : 0;
  };
  std::map<int32_t, std::map<int32_t, double>> scores;
  for (auto& [label, classes] : scores_) {
    const int32_t id = renamed(label);
    if (id <= 0) continue;
    for (const auto& [cls, score] : classes) scores[id][cls] += score;
  }
  scores_ = std::move(scores);
  edges_.rename(renamed);
  surface_scan_ = SurfaceScan();
}

void GraphAccumulator::applySplits(const std::vector<SuperpointSplit>& splits,
                                   const SuperpointTracker& tracker) {
  applyMerges(tracker);
  for (const SuperpointSplit& split : splits) {
    const int32_t from = tracker.labels().resolve(split.from);
    const int32_t to = tracker.labels().resolve(split.to);
    const auto it = scores_.find(from);
    if (from == to || it == scores_.end()) continue;
    const double share = std::clamp(split.share, 0.0, 1.0);
    // Eq. 6's P_s, as update() computes it from the two parts' centroids.
    const double p_s =
        split.distance_m >= 0.0 ? 1.0 / (1.0 + split.distance_m / config_.spatial_scale_m) : 0.0;
    auto& target = scores_[to];  // std::map: `it` stays valid
    for (auto& [cls, score] : it->second) {
      const double moved = share * score;
      target[cls] += moved;
      if (cls > 0)
        edges_.add(std::min(from, to), std::max(from, to), cls,
                   p_s * std::min(share, 1.0 - share) * score);
      score -= moved;
    }
  }
}

void GraphAccumulator::update(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                              const PanopticFrame& panoptic, const TsdfMap& map,
                              const SuperpointTracker& tracker, float stuff_confidence) {
  applyMerges(tracker);
  const PinholeCamera& cam = frame.camera;
  if (panoptic.segment_ids.width() != cam.width || panoptic.segment_ids.height() != cam.height) {
    throw Error("graph update: panoptic mask size differs from the frame's");
  }
  // Masks with a known class and their confidence P_o (Eq. 1).
  std::map<int32_t, std::pair<int32_t, float>> masks;  // id -> (class, P_o)
  std::map<int32_t, int> things_per_class;
  for (const PanopticSegment& s : panoptic.segments) {
    if (s.category <= 0) continue;
    if (s.id > internal::kMaxMaskHitId) {
      throw Error("graph update: panoptic segment id " + std::to_string(s.id) + " is above " +
                  std::to_string(internal::kMaxMaskHitId));
    }
    masks[s.id] = {s.category, s.is_thing ? s.score : stuff_confidence};
    if (s.is_thing) ++things_per_class[s.category];
  }
  std::map<int32_t, bool> is_thing_mask;  // thing masks of a class with two or more things
  for (const PanopticSegment& s : panoptic.segments) {
    if (s.category > 0 && s.is_thing && things_per_class[s.category] > 1)
      is_thing_mask[s.id] = true;
  }
  mask_groups_.clear();
  if (masks.empty()) return;
  // The same segments as `masks`, tested per pixel without a tree lookup.
  const KnownSegments known(panoptic);
  auto isKnown = [&known](int32_t id) { return known.contains(id); };

  // Voxels reached by each mask's rays: (mask, voxel key, super-point) per sampled pixel. Rows
  // are split between threads; concatenated in row order they are what one thread would find.
  const Eigen::Isometry3f T = T_W_C.cast<float>();
  const float scale = static_cast<float>(frame.depth_scale_m);
  const LabelRegistry& registry = tracker.labels();
  registry.flatten();  // resolve() only reads from here on: safe on every thread
  auto resolve = [&registry](int32_t l) { return registry.resolve(l); };
  const int stride = config_.sample_stride_px;
  const size_t rows = static_cast<size_t>((cam.height + stride - 1) / stride);
  const bool all_interior = config_.pair_interior_px == 0;
  if (!all_interior)
    internal::maskInterior(panoptic.segment_ids, config_.pair_interior_px, &interior_);
  // Rows go to whichever thread is free (rows with masks cost far more than rows without).
  // Each thread sorts and dedupes its own hits; merged, they are what one sort of all hits
  // would give, whichever rows each thread took (equal hits are identical: one voxel has one
  // super-point here).
  auto collect = [&](size_t r0, size_t r1, ThreadScratch* scratch) {
    std::vector<Hit>& out = scratch->hits;
    VoxelLabelSampler sampler(map, T, cam, resolve);
    for (size_t r = r0; r < r1; ++r) {
      const int v = static_cast<int>(r) * stride;
      scratch->samples.clear();
      scratch->masks.clear();
      for (int u = 0; u < cam.width; u += stride) {
        const int32_t id = panoptic.segment_ids(u, v);
        if (id <= 0 || !isKnown(id)) continue;
        const float d = frame.depth(u, v) * scale;
        if (d <= 0.0f) continue;
        scratch->samples.push_back({u, d});
        scratch->masks.push_back(id);
      }
      const size_t n = scratch->samples.size();
      scratch->labels.resize(n);
      scratch->voxels.resize(n);
      sampler.labelRow(v, scratch->samples, scratch->labels.data(), scratch->voxels.data());
      for (size_t k = 0; k < n; ++k) {
        const int32_t label = scratch->labels[k];
        if (label <= 0) continue;
        const int32_t id = scratch->masks[k];
        const Eigen::Vector3i& g = scratch->voxels[k];
        const uint64_t key = internal::maskHitVoxelKey(g.x(), g.y(), g.z());
        // A pixel near its mask's outline is a boundary hit (even key), any other an interior
        // one (odd key): a mask's two kinds sort next to each other.
        const bool inside = all_interior || interior_(scratch->samples[k].u, v) != 0;
        const int32_t hit_mask = internal::maskHitKey(id, inside);
        // Neighbouring pixels often repeat the last hit: keep the sort below small.
        if (!out.empty() && out.back().mask == hit_mask && out.back().voxel == key) continue;
        out.push_back({key, hit_mask, label});
      }
    }
  };
  auto sortHits = [](ThreadScratch* scratch) {
    internal::sortUniqueHits(&scratch->hits, &scratch->sort_scratch);
  };
  const int threads = pool_ ? pool_->size() : 1;
  thread_scratch_.resize(static_cast<size_t>(threads));
  for (ThreadScratch& scratch : thread_scratch_) scratch.hits.clear();
  if (pool_) {
    pool_->parallelForDynamic(rows, kRowsPerChunk, [&](size_t r0, size_t r1, int t) {
      collect(r0, r1, &thread_scratch_[static_cast<size_t>(t)]);
    });
    pool_->parallelFor(thread_scratch_.size(), [&](size_t t0, size_t t1, int) {
      for (size_t t = t0; t < t1; ++t) sortHits(&thread_scratch_[t]);
    });
  } else {
    collect(0, rows, &thread_scratch_[0]);
    sortHits(&thread_scratch_[0]);
  }
  // N^S_o counts unique voxels: many pixels see the same voxel up close.
  std::vector<Hit>& hits = hits_;
  hits.clear();
  for (ThreadScratch& scratch : thread_scratch_) {
    std::vector<Hit>& part = scratch.hits;
    merged_.resize(hits.size() + part.size());
    std::merge(hits.begin(), hits.end(), part.begin(), part.end(), merged_.begin());
    merged_.erase(std::unique(merged_.begin(), merged_.end()), merged_.end());
    hits.swap(merged_);
    part.clear();
  }

  const float voxel = map.voxelSize();
  auto centre = [voxel](uint64_t key) {
    auto field = [](uint64_t x) {
      const int v = static_cast<int>(x & 0x1FFFFF);
      return v >= (1 << 20) ? v - (1 << 21) : v;
    };
    return Eigen::Vector3d((field(key >> 42) + 0.5) * voxel, (field(key >> 21) + 0.5) * voxel,
                           (field(key) + 0.5) * voxel);
  };
  for (size_t begin = 0; begin < hits.size();) {
    const int32_t mask = internal::maskOfHitKey(hits[begin].mask);
    size_t mid = begin;  // [begin, mid): boundary hits, [mid, end): interior hits
    while (mid < hits.size() && hits[mid].mask == internal::maskHitKey(mask, false)) ++mid;
    size_t end = mid;
    while (end < hits.size() && hits[end].mask == internal::maskHitKey(mask, true)) ++end;
    const auto [cls, p_o] = masks.at(mask);
    // N^S_o (unique voxels, either kind), its interior part and the centroid of those voxels,
    // per super-point, in label order. Both kinds are sorted by voxel: one merge walk.
    groups_.clear();
    group_index_.clear();
    auto count = [&](const Hit& h, bool interior) {
      const auto [it, added] = group_index_.try_emplace(h.label, groups_.size());
      if (added) groups_.push_back({h.label, 0, 0, Eigen::Vector3d::Zero(), {}});
      Group& g = groups_[it->second];
      ++g.count;
      if (interior) ++g.interior;
      g.sum += centre(h.voxel);
    };
    for (size_t b = begin, i = mid; b < mid || i < end;) {
      if (i == end || (b < mid && hits[b].voxel < hits[i].voxel)) {
        count(hits[b++], false);
      } else {
        if (b < mid && hits[b].voxel == hits[i].voxel) ++b;
        count(hits[i++], true);
      }
    }
    std::sort(groups_.begin(), groups_.end(),
              [](const Group& x, const Group& y) { return x.label < y.label; });
    for (Group& g : groups_) g.centroid = g.sum / g.count;
    // Eq. 5: P_nu^C(L_S) += P_o * N^S_o.
    for (const Group& g : groups_) scores_[g.label][cls] += p_o * g.count;
    // Eq. 6: P_eps^C(S1, S2) += P_o * P_s * min(N^S1_o, N^S2_o), for every pair under o. On a
    // long run the table is far larger than the cache: each pair's slot is fetched a few pairs
    // ahead.
    const size_t n = groups_.size();
    for (size_t i = 0; i < n; ++i) {
      const Group& gi = groups_[i];
      for (size_t j = i + 1; j < std::min(n, i + 1 + kPrefetchPairs); ++j) {
        edges_.prefetch(gi.label, groups_[j].label);
      }
      for (size_t j = i + 1; j < n; ++j) {
        if (j + kPrefetchPairs < n) edges_.prefetch(gi.label, groups_[j + kPrefetchPairs].label);
        const Group& gj = groups_[j];
        const double distance = (gi.centroid - gj.centroid).norm();
        const double p_s = 1.0 / (1.0 + distance / config_.spatial_scale_m);
        const int n_pair = std::min(gi.interior, gj.interior);
        if (n_pair > 0) edges_.add(gi.label, gj.label, cls, p_o * p_s * n_pair);
      }
    }
    mask_groups_.push_back({cls, p_o, is_thing_mask.count(mask) > 0, groups_});
    begin = end;
  }

  // Evidence of two segments: S1 under mask o1 and S2 under another mask o2 of the frame.
  // P_apart(S1, S2) += min(P_o1, P_o2) * min(N^S1_o1, N^S2_o2) for pairs already co-observed
  // under one mask (only those have a P_eps to weigh it against; the table does not grow),
  // stored under class 0. For two masks of one thing class C also P_sep^C, the same sum times
  // P_s, for every pair within separation_radius_m (two chairs seen apart for a hundred frames
  // before a mask first merges them must not look like one chair), stored under class -C.
  // Masks in id order, groups in label order: the same sums every run.
  for (size_t m1 = 0; m1 < mask_groups_.size(); ++m1) {
    for (size_t m2 = m1 + 1; m2 < mask_groups_.size(); ++m2) {
      const MaskGroups& o1 = mask_groups_[m1];
      const MaskGroups& o2 = mask_groups_[m2];
      const double p_o = std::min(o1.p_o, o2.p_o);
      const bool same_thing_class = o1.thing && o2.thing && o1.cls == o2.cls;
      for (const Group& g1 : o1.groups) {
        for (const Group& g2 : o2.groups) {
          if (g1.label == g2.label) continue;
          const auto [lo, hi] = std::minmax(g1.label, g2.label);
          const double n = std::min(g1.interior, g2.interior);
          if (n <= 0.0) continue;
          if (same_thing_class) {
            const double distance = (g1.centroid - g2.centroid).norm();
            if (distance <= config_.separation_radius_m) {
              const double p_s = 1.0 / (1.0 + distance / config_.spatial_scale_m);
              edges_.add(lo, hi, -o1.cls, p_o * p_s * n);
            }
          }
          const EdgeTable::Classes* known = edges_.find(lo, hi);
          // Classes are sorted: a co-observation under one mask is a positive last key.
          if (known && !known->empty() && known->back().first > 0) {
            edges_.add(lo, hi, 0, p_o * n);
          }
        }
      }
    }
  }
}

size_t GraphAccumulator::memoryBytes() const {
  size_t bytes = mapNodesBytes(scores_) + edges_.memoryBytes() + surface_scan_.memoryBytes();
  for (const auto& [label, by_class] : scores_) bytes += mapNodesBytes(by_class);
  for (const ThreadScratch& scratch : thread_scratch_) {
    bytes += vectorBytes(scratch.hits) + vectorBytes(scratch.sort_scratch) +
             vectorBytes(scratch.samples) + vectorBytes(scratch.masks) +
             vectorBytes(scratch.labels) + vectorBytes(scratch.voxels);
  }
  bytes += static_cast<size_t>(interior_.width()) * interior_.height();
  bytes += vectorBytes(groups_) +
           group_index_.capacity() * (sizeof(std::pair<const int32_t, size_t>) + 1);
  return bytes + vectorBytes(hits_) + vectorBytes(merged_);
}

void GraphAccumulator::forgetUnvoted(const std::vector<uint8_t>& has_votes,
                                     const LabelRegistry& registry) {
  auto voted = [&](int32_t label) {
    const int32_t root = registry.resolve(label);
    return root > 0 && static_cast<size_t>(root) < has_votes.size() && has_votes[root] != 0;
  };
  for (auto it = scores_.begin(); it != scores_.end();) {
    it = voted(it->first) ? std::next(it) : scores_.erase(it);
  }
  edges_.keepIf(voted);
}

double GraphAccumulator::scoreTotal(int32_t label) const {
  double sum = 0.0;
  const auto it = scores_.find(label);
  if (it != scores_.end()) {
    for (const auto& [cls, value] : it->second) sum += value;
  }
  return sum;
}

std::vector<double> GraphAccumulator::scoreTotals(size_t size) const {
  std::vector<double> totals(size, 0.0);
  for (const auto& [label, by_class] : scores_) {
    if (label < 0 || static_cast<size_t>(label) >= size) continue;
    double sum = 0.0;  // in class order, as scoreTotal() adds them
    for (const auto& [cls, value] : by_class) sum += value;
    totals[static_cast<size_t>(label)] = sum;
  }
  return totals;
}

template <typename Total>
bool GraphAccumulator::keepEdgeWith(int32_t a, int32_t b, double strongest,
                                    const SurfaceAdjacency& surface, const Total& total) const {
  if (!config_.prune_edges) return true;
  if (a == b || surface.surfaceVoxels(a) == 0 || surface.surfaceVoxels(b) == 0) return false;
  if (surface.touching(a, b)) return true;
  return strongest > 0.0 && strongest >= config_.edge_min_share * std::min(total(a), total(b));
}

bool GraphAccumulator::keepEdge(int32_t a, int32_t b, double strongest,
                                const SurfaceAdjacency& surface) const {
  return keepEdgeWith(a, b, strongest, surface, [this](int32_t l) { return scoreTotal(l); });
}

size_t GraphAccumulator::pruneEdges(const SurfaceAdjacency& surface,
                                    const LabelRegistry& registry) {
  if (!config_.prune_edges) return 0;
  const std::vector<double> totals = scoreTotals(static_cast<size_t>(registry.size()) + 1);
  auto total = [&](int32_t l) {
    return l >= 0 && static_cast<size_t>(l) < totals.size() ? totals[l] : scoreTotal(l);
  };
  return edges_.keepPairsIf([&](int32_t a, int32_t b, const EdgeTable::Classes& classes) {
    // P_eps^C (C > 0) or P_sep^C (C < 0); P_apart (0) only weighs them.
    double strongest = 0.0;
    for (const auto& [cls, value] : classes) {
      if (cls != 0) strongest = std::max(strongest, value);
    }
    return keepEdgeWith(registry.resolve(a), registry.resolve(b), strongest, surface, total);
  });
}

const SurfaceScan& GraphAccumulator::surfaceScan(const TsdfMap& map,
                                                 const LabelRegistry& registry) const {
  surface_scan_.refresh(map, registry, config_.surface_band_voxels, pool_);
  return surface_scan_;
}

SuperpointGraph GraphAccumulator::graph(const TsdfMap& map,
                                        const SuperpointTracker& tracker) const {
  SuperpointGraph g;
  g.voxel_size_m = map.voxelSize();
  for (int32_t c = 1; c <= kMaxNyu40Class; ++c) g.classes.push_back(c);
  for (int32_t c = 1; c <= kMaxNyu40Class; ++c) {
    if (isStuffClass(c)) g.background.push_back(c);
  }
  // Voxel counts and centroids of the live super-points, indexed by label (labels are dense),
  // from the scan that finds who owns the surface: the map is read once.
  const size_t num_labels = static_cast<size_t>(std::max(0, tracker.labels().size())) + 1;
  SurfaceAdjacency::OwnerTotals totals;
  totals.voxels.assign(num_labels, 0);
  totals.centre_sum.assign(num_labels, Eigen::Vector3d::Zero());
  const SurfaceScan& scan = surfaceScan(map, tracker.labels());  // flattens the registry
  auto resolve = [&tracker](int32_t l) { return tracker.labels().resolve(l); };
  scan.addTotals(&totals);
  const SurfaceAdjacency adjacency = scan.adjacency();
  // Without pruning the adjacency is not used (its scan still counts the voxels).
  const SurfaceAdjacency* surface = config_.prune_edges ? &adjacency : nullptr;
  for (const auto& [label, state] : tracker.states()) {
    if (surface && surface->surfaceVoxels(label) == 0) continue;
    GraphVertex vertex;
    vertex.id = label;
    if (label > 0 && static_cast<size_t>(label) < num_labels && totals.voxels[label] > 0) {
      vertex.num_voxels = totals.voxels[label];
      vertex.centroid = totals.centre_sum[label] / totals.voxels[label];
    }
    vertex.instance = state.instance();
    vertex.semantic = state.semanticClass();
    vertex.void_share = state.voidShare();
    const auto s = scores_.find(label);
    if (s != scores_.end()) {
      vertex.scores.insert(boost::container::ordered_unique_range, s->second.begin(),
                           s->second.end());
    }
    g.vertices.push_back(vertex);
  }
  // Stored pairs between live super-points (merges are folded in at the next update), in pair
  // order, so that equal pairs below are summed in the same order on every run.
  struct Stored {
    int32_t a, b;
    const EdgeTable::Classes* classes;
  };
  std::vector<Stored> stored;
  stored.reserve(edges_.size());
  edges_.forEachSorted([&](int32_t first, int32_t second, const EdgeTable::Classes& classes) {
    const int32_t a = resolve(first), b = resolve(second);
    if (a == b || a == 0 || b == 0) return;
    stored.push_back({std::min(a, b), std::max(a, b), &classes});
  });
  // Sorting these small records gives the permutation sorting the edges themselves gave (it
  // depends on the comparisons alone), so equal pairs are summed in the same order as before.
  std::sort(stored.begin(), stored.end(), [](const Stored& x, const Stored& y) {
    return std::tie(x.a, x.b) < std::tie(y.a, y.b);
  });
  auto toEdge = [](const Stored& s) {
    GraphEdge e;
    e.a = s.a;
    e.b = s.b;
    for (const auto& [cls, value] : *s.classes) {
      if (cls > 0) {
        e.confidences[cls] = value;
      } else if (cls < 0) {
        e.separations[-cls] = value;
      } else {
        e.apart = value;
      }
    }
    return e;
  };
  const std::vector<double> totals_by_label = scoreTotals(num_labels);
  auto total = [&](int32_t l) {
    return l >= 0 && static_cast<size_t>(l) < num_labels ? totals_by_label[l] : scoreTotal(l);
  };
  // The pairs' classes sit in the table's slots, in hash order, and those of a pair with more
  // than one class behind a pointer in the slot: visited in pair order each is two cache misses,
  // so the slots are asked for kPrefetchAhead pairs ahead, and what they point to half as far.
  constexpr size_t kPrefetchAhead = 16;
  constexpr size_t kPrefetchDataAhead = kPrefetchAhead / 2;
  // Edges of stored[begin, end), which starts and ends at a pair boundary, written from `out`
  // on (at most end - begin of them); returns how many.
  auto edgesOf = [&](size_t begin, size_t end, GraphEdge* out) {
    GraphEdge* const first = out;
    for (size_t k = begin; k < std::min(begin + kPrefetchAhead, end); ++k) {
      __builtin_prefetch(stored[k].classes);
    }
    for (size_t i = begin; i < end;) {
      if (i + kPrefetchAhead < end) __builtin_prefetch(stored[i + kPrefetchAhead].classes);
      if (i + kPrefetchDataAhead < end) {
        __builtin_prefetch(stored[i + kPrefetchDataAhead].classes->data());
      }
      size_t j = i + 1;
      while (j < end && stored[j].a == stored[i].a && stored[j].b == stored[i].b) ++j;
      // P_eps^C (C > 0) and P_sep^C (C < 0); P_apart (0) only weighs them.
      double strongest = 0.0;
      if (j == i + 1) {
        for (const auto& [cls, value] : *stored[i].classes) {
          if (cls != 0) strongest = std::max(strongest, value);
        }
        // After the sums: a pair's evidence is judged whole.
        if (!surface || keepEdgeWith(stored[i].a, stored[i].b, strongest, *surface, total)) {
          *out++ = toEdge(stored[i]);
        }
        i = j;
        continue;
      }
      // Pending merges can map two stored edges onto one pair: add them up.
      GraphEdge sum = toEdge(stored[i]);
      for (size_t k = i + 1; k < j; ++k) {
        const GraphEdge e = toEdge(stored[k]);
        for (const auto& [cls, c] : e.confidences) sum.confidences[cls] += c;
        for (const auto& [cls, c] : e.separations) sum.separations[cls] += c;
        sum.apart += e.apart;
      }
      for (const auto& [cls, c] : sum.confidences) strongest = std::max(strongest, c);
      for (const auto& [cls, c] : sum.separations) strongest = std::max(strongest, c);
      if (!surface || keepEdgeWith(sum.a, sum.b, strongest, *surface, total)) {
        *out++ = std::move(sum);
      }
      i = j;
    }
    return static_cast<size_t>(out - first);
  };
  // Building the edges (two small maps each) is most of the graph's time on a building: the
  // threads take consecutive slices, cut between pairs, and the slices are joined in order,
  // so the edges are those of one pass. Each slice is written where its stored pairs start and
  // the slices are then moved down, closing the gaps: one array of edges, not one per slice
  // and their join (20 MB less fresh memory for the building's 300k edges).
  const size_t parts = pool_ && stored.size() >= kParallelEdges ? pool_->size() : 1;
  std::vector<size_t> cuts(parts + 1, stored.size());
  cuts[0] = 0;
  for (size_t p = 1; p < parts; ++p) {
    size_t c = std::max(cuts[p - 1], stored.size() * p / parts);
    while (c > cuts[p - 1] && c < stored.size() && stored[c].a == stored[c - 1].a &&
           stored[c].b == stored[c - 1].b) {
      ++c;
    }
    cuts[p] = c;
  }
  g.edges.resize(stored.size());
  std::vector<size_t> written(parts, 0);
  if (parts == 1) {
    written[0] = edgesOf(0, stored.size(), g.edges.data());
  } else {
    pool_->parallelFor(parts, [&](size_t p0, size_t p1, int) {
      for (size_t p = p0; p < p1; ++p) {
        written[p] = edgesOf(cuts[p], cuts[p + 1], g.edges.data() + cuts[p]);
      }
    });
  }
  size_t count = written[0];
  for (size_t p = 1; p < parts; ++p) {
    // Downwards, and never onto itself (a self-move may empty a map).
    if (count != cuts[p]) {
      const auto from = g.edges.begin() + static_cast<std::ptrdiff_t>(cuts[p]);
      std::move(from, from + static_cast<std::ptrdiff_t>(written[p]),
                g.edges.begin() + static_cast<std::ptrdiff_t>(count));
    }
    count += written[p];
  }
  g.edges.erase(g.edges.begin() + static_cast<std::ptrdiff_t>(count), g.edges.end());
  return g;
}

}  // namespace panmap
