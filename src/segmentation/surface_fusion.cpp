// Panoptic-geometric fusion: surfaces = geometric segments x panoptic masks (paper III-A).
#include <algorithm>
#include <cmath>
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
                        FrameSegmentation* out, ThreadPool* pool, const DepthImage* depth) {
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
  if (use_masks && config.mask_only_surfaces && depth != nullptr) {
    addMaskOnlySurfaces(*panoptic, *depth, config, out);
  }
}

void SurfaceFuser::addMaskOnlySurfaces(const PanopticFrame& panoptic, const DepthImage& depth,
                                       const SurfaceFusionConfig& config, FrameSegmentation* out) {
  LabelImage& surfaces = out->surfaces;
  const int w = surfaces.width(), h = surfaces.height();
  if (depth.width() != w || depth.height() != h) {
    throw Error("surface fusion: depth image size differs from the segmentation's");
  }
  // Thing masks of a known class without a surface: only these are grouped, so an object
  // the geometric segmentation resolves keeps exactly the surfaces it had.
  segment_has_surface_.assign(panoptic.segments.size(), 0);
  for (const Surface& s : out->surface_list) {
    if (s.panoptic_segment > 0) segment_has_surface_[segmentIndex(s.panoptic_segment)] = 1;
  }
  bool any = false;
  for (size_t k = 0; k < panoptic.segments.size(); ++k) {
    const PanopticSegment& segment = panoptic.segments[k];
    if (segment.is_thing && segment.category > 0 && !segment_has_surface_[k]) any = true;
  }
  if (!any) return;
  const size_t n = surfaces.size();
  const int32_t* ids = panoptic.segment_ids.data();
  const int32_t* geo = out->geometric.data();
  const uint16_t* d = depth.data();
  open_.assign(n, 0);
  int32_t last_id = 0;
  bool last_open = false;
  for (size_t i = 0; i < n; ++i) {
    const int32_t id = ids[i];
    if (id <= 0 || geo[i] != 0 || d[i] == 0) continue;
    if (id != last_id) {
      last_id = id;
      const int32_t k = segmentIndex(id);
      last_open = k >= 0 && panoptic.segments[k].is_thing && panoptic.segments[k].category > 0 &&
                  !segment_has_surface_[k];
    }
    if (last_open) open_[i] = id;
  }
  // Parts grown from their first pixel in raster order, so surface ids are the same every run.
  const float step = config.mask_only_depth_step;
  int32_t* label = surfaces.data();
  for (size_t seed = 0; seed < n; ++seed) {
    const int32_t id = open_[seed];
    if (id == 0) continue;
    queue_.clear();
    queue_.push_back(static_cast<int32_t>(seed));
    open_[seed] = 0;
    for (size_t head = 0; head < queue_.size(); ++head) {
      const int32_t i = queue_[head];
      const int u = i % w, v = i / w;
      const float di = static_cast<float>(d[i]);
      auto reach = [&](int32_t j) {
        if (open_[j] != id) return;
        const float dj = static_cast<float>(d[j]);
        if (std::fabs(dj - di) > step * std::min(di, dj)) return;
        open_[j] = 0;
        queue_.push_back(j);
      };
      if (u > 0) reach(i - 1);
      if (u + 1 < w) reach(i + 1);
      if (v > 0) reach(i - w);
      if (v + 1 < h) reach(i + w);
    }
    if (static_cast<int>(queue_.size()) < config.min_surface_px) continue;
    const PanopticSegment& segment = panoptic.segments[segmentIndex(id)];
    Surface surface;
    surface.id = static_cast<int32_t>(out->surface_list.size()) + 1;
    surface.geometric_segment = 0;
    surface.panoptic_segment = segment.id;
    surface.category = segment.category;
    surface.is_thing = true;
    surface.confidence = panopticConfidence(segment, config.stuff_confidence);
    surface.num_pixels = static_cast<int32_t>(queue_.size());
    out->surface_list.push_back(surface);
    for (const int32_t i : queue_) label[i] = surface.id;
  }
}

}  // namespace internal
}  // namespace panmap
