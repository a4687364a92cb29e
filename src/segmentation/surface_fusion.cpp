// Panoptic-geometric fusion: surfaces = geometric segments x panoptic masks (paper III-A).
#include <algorithm>
#include <string>

#include "panmap/core/error.h"
#include "panmap/segmentation/internal/surface_fusion.h"

namespace panmap {
namespace internal {

namespace {

constexpr uint64_t kEmptyKey = ~uint64_t{0};

uint64_t pairKey(int32_t geometric, int32_t segment_index) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(geometric)) << 32) |
         static_cast<uint32_t>(segment_index);
}

size_t slotOf(uint64_t key, size_t mask) {
  return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) & mask;
}

}  // namespace

void SurfaceFuser::indexSegments(const PanopticFrame& panoptic) {
  id_to_index_.clear();
  for (size_t k = 0; k < panoptic.segments.size(); ++k) {
    const PanopticSegment& segment = panoptic.segments[k];
    if (segment.id <= 0) {
      throw Error("panoptic segments[" + std::to_string(k) + "].id must be > 0, got " +
                  std::to_string(segment.id));
    }
    id_to_index_.emplace_back(segment.id, static_cast<int32_t>(k));
  }
  std::sort(id_to_index_.begin(), id_to_index_.end());
  for (size_t k = 1; k < id_to_index_.size(); ++k) {
    if (id_to_index_[k].first == id_to_index_[k - 1].first) {
      throw Error("panoptic segment id " + std::to_string(id_to_index_[k].first) +
                  " is listed twice");
    }
  }
}

int32_t SurfaceFuser::segmentIndex(int32_t panoptic_id) const {
  const auto it = std::lower_bound(id_to_index_.begin(), id_to_index_.end(),
                                   std::make_pair(panoptic_id, int32_t{-1}));
  return it != id_to_index_.end() && it->first == panoptic_id ? it->second : -1;
}

int32_t SurfaceFuser::findOrAddPair(int32_t geometric, int32_t segment_index, int32_t panoptic_id) {
  if (2 * (pairs_.size() + 1) > table_keys_.size()) {
    // Grow and rehash: happens in the first frames only, the table keeps its size after.
    const size_t capacity = std::max<size_t>(1024, 2 * table_keys_.size());
    table_keys_.assign(capacity, kEmptyKey);
    table_values_.assign(capacity, -1);
    for (size_t p = 0; p < pairs_.size(); ++p) {
      const uint64_t key = pairKey(pairs_[p].geometric, pairs_[p].segment_index);
      size_t slot = slotOf(key, capacity - 1);
      while (table_keys_[slot] != kEmptyKey) slot = (slot + 1) & (capacity - 1);
      table_keys_[slot] = key;
      table_values_[slot] = static_cast<int32_t>(p);
    }
  }
  const size_t mask = table_keys_.size() - 1;
  const uint64_t key = pairKey(geometric, segment_index);
  size_t slot = slotOf(key, mask);
  while (table_keys_[slot] != kEmptyKey) {
    if (table_keys_[slot] == key) return table_values_[slot];
    slot = (slot + 1) & mask;
  }
  table_keys_[slot] = key;
  table_values_[slot] = static_cast<int32_t>(pairs_.size());
  pairs_.push_back(Pair{geometric, segment_index, panoptic_id, 0});
  return table_values_[slot];
}

void SurfaceFuser::fuse(const PanopticFrame* panoptic, const SurfaceFusionConfig& config,
                        FrameSegmentation* out, ThreadPool* pool) {
  const bool use_masks = panoptic != nullptr && !config.geometry_only;
  if (use_masks) {
    indexSegments(*panoptic);
  } else {
    id_to_index_.clear();
  }
  pairs_.clear();
  std::fill(table_keys_.begin(), table_keys_.end(), kEmptyKey);

  // Pass 1: the (geometric segment, panoptic segment) pair of every pixel, counted. Labels
  // change only at segment borders, so the last lookups are cached.
  const LabelImage& geometric = out->geometric;
  LabelImage& surfaces = out->surfaces;
  const int32_t* geo = geometric.data();
  const int32_t* ids = use_masks ? panoptic->segment_ids.data() : nullptr;
  int32_t* pair_of = surfaces.data();
  int32_t last_id = 0, last_index = -1, last_geo = 0, last_pair = -1;
  for (size_t i = 0; i < geometric.size(); ++i) {
    const int32_t g = geo[i];
    if (g == 0) {
      pair_of[i] = 0;
      continue;
    }
    const int32_t id = ids ? ids[i] : 0;
    if (id != last_id) {
      last_id = id;
      int32_t index = id > 0 ? segmentIndex(id) : -1;
      // An unknown class is no semantic evidence: such pixels count as background.
      if (index >= 0 && panoptic->segments[index].category == 0) index = -1;
      if (index != last_index) last_pair = -1;
      last_index = index;
    }
    if (g != last_geo || last_pair < 0) {
      last_geo = g;
      const int32_t pid = last_index >= 0 ? panoptic->segments[last_index].id : 0;
      last_pair = findOrAddPair(g, last_index, pid);
    }
    ++pairs_[last_pair].num_pixels;
    pair_of[i] = last_pair + 1;
  }

  // Surfaces in order of (geometric segment, panoptic id): deterministic whatever the scan.
  order_.resize(pairs_.size());
  for (size_t p = 0; p < pairs_.size(); ++p) order_[p] = static_cast<int32_t>(p);
  std::sort(order_.begin(), order_.end(), [this](int32_t a, int32_t b) {
    return std::make_pair(pairs_[a].geometric, pairs_[a].panoptic_id) <
           std::make_pair(pairs_[b].geometric, pairs_[b].panoptic_id);
  });
  pair_to_surface_.assign(pairs_.size(), 0);
  out->surface_list.clear();
  for (const int32_t p : order_) {
    const Pair& pair = pairs_[p];
    if (pair.num_pixels < config.min_surface_px) continue;
    Surface surface;
    surface.id = static_cast<int32_t>(out->surface_list.size()) + 1;
    surface.geometric_segment = pair.geometric;
    surface.num_pixels = pair.num_pixels;
    if (pair.segment_index >= 0) {
      const PanopticSegment& segment = panoptic->segments[pair.segment_index];
      surface.panoptic_segment = segment.id;
      surface.category = segment.category;
      surface.is_thing = segment.is_thing;
      surface.confidence = panopticConfidence(segment, config.stuff_confidence);
    } else {
      // Background: no mask, no class; scored like stuff so its geometry still votes.
      surface.confidence = config.stuff_confidence;
    }
    pair_to_surface_[p] = surface.id;
    out->surface_list.push_back(surface);
  }

  // Pass 2: pair -> surface id (0 for dropped pairs).
  const int32_t* surface_of = pair_to_surface_.data();
  auto relabel = [pair_of, surface_of](size_t begin, size_t end, int) {
    for (size_t i = begin; i < end; ++i) {
      pair_of[i] = pair_of[i] > 0 ? surface_of[pair_of[i] - 1] : 0;
    }
  };
  if (pool) {
    pool->parallelFor(surfaces.size(), relabel);
  } else {
    relabel(0, surfaces.size(), 0);
  }
}

}  // namespace internal
}  // namespace panmap
