#include "panmap/graph/surface_adjacency.h"

#include <algorithm>
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/map/voxel.h"

namespace panmap {

namespace {

// The 13 "forward" offsets of the 26-neighbourhood: each touching voxel pair is visited once.
constexpr int kForward[13][3] = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1},  {1, 1, 0},  {1, -1, 0},
                                 {1, 0, 1},  {1, 0, -1}, {0, 1, 1},  {0, 1, -1}, {1, 1, 1},
                                 {1, 1, -1}, {1, -1, 1}, {1, -1, -1}};

}  // namespace

uint64_t SurfaceAdjacency::key(int32_t a, int32_t b) {
  const auto [lo, hi] = std::minmax(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(lo)) << 32) | static_cast<uint32_t>(hi);
}

SurfaceAdjacency SurfaceAdjacency::compute(const TsdfMap& map,
                                           const std::function<int32_t(int32_t)>& resolve,
                                           float band_voxels) {
  if (!(band_voxels > 0.0f)) throw Error("surface adjacency band_voxels must be > 0");
  const float band_m = band_voxels * map.voxelSize();
  SurfaceAdjacency out;
  // Owner of every surface voxel, for the blocks that have one (others stay out: at building
  // scale this scratch is about a tenth of the map).
  absl::flat_hash_map<uint64_t, std::vector<int32_t>> owners;
  for (const auto& block : map.blocks()) {
    std::vector<int32_t> labels;
    for (int i = 0; i < kBlockVoxels; ++i) {
      const Voxel& voxel = block->voxels[i];
      if (!(voxel.weight > 0.0f) || !(std::fabs(voxel.sdf_m) <= band_m)) continue;
      const int32_t label = argmaxLabel(voxel, resolve);
      if (label <= 0) continue;
      if (labels.empty()) labels.assign(kBlockVoxels, 0);
      labels[static_cast<size_t>(i)] = label;
      ++out.surface_voxels_[label];
    }
    if (!labels.empty()) owners.emplace(TsdfMap::key(block->index), std::move(labels));
  }
  for (const auto& block : map.blocks()) {
    const auto own = owners.find(TsdfMap::key(block->index));
    if (own == owners.end()) continue;
    const std::vector<int32_t>& labels = own->second;
    for (int z = 0; z < kBlockSide; ++z) {
      for (int y = 0; y < kBlockSide; ++y) {
        for (int x = 0; x < kBlockSide; ++x) {
          const int32_t label = labels[static_cast<size_t>(x + kBlockSide * (y + kBlockSide * z))];
          if (label <= 0) continue;
          for (const auto& d : kForward) {
            int nx = x + d[0], ny = y + d[1], nz = z + d[2];
            BlockIndex nb = block->index;
            const std::vector<int32_t>* other = &labels;
            if (nx < 0 || nx >= kBlockSide || ny < 0 || ny >= kBlockSide || nz < 0 ||
                nz >= kBlockSide) {
              auto wrap = [](int* v, int* b) {
                if (*v < 0) *v += kBlockSide, --*b;
                if (*v >= kBlockSide) *v -= kBlockSide, ++*b;
              };
              wrap(&nx, &nb.x());
              wrap(&ny, &nb.y());
              wrap(&nz, &nb.z());
              const auto it = owners.find(TsdfMap::key(nb));
              if (it == owners.end()) continue;
              other = &it->second;
            }
            const int32_t neighbour =
                (*other)[static_cast<size_t>(nx + kBlockSide * (ny + kBlockSide * nz))];
            if (neighbour > 0 && neighbour != label) out.pairs_.insert(key(label, neighbour));
          }
        }
      }
    }
  }
  return out;
}

int SurfaceAdjacency::surfaceVoxels(int32_t label) const {
  const auto it = surface_voxels_.find(label);
  return it == surface_voxels_.end() ? 0 : it->second;
}

bool SurfaceAdjacency::touching(int32_t a, int32_t b) const {
  return a != b && pairs_.count(key(a, b)) > 0;
}

}  // namespace panmap
