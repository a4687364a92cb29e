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
  return computeWith(map, resolve, band_voxels, nullptr);
}

SurfaceAdjacency SurfaceAdjacency::compute(const TsdfMap& map,
                                           const std::function<int32_t(int32_t)>& resolve,
                                           float band_voxels, OwnerTotals* totals) {
  return computeWith(map, resolve, band_voxels, totals);
}

SurfaceAdjacency SurfaceAdjacency::compute(const TsdfMap& map, const std::vector<int32_t>& roots,
                                           float band_voxels, OwnerTotals* totals) {
  const auto size = static_cast<int32_t>(roots.size());
  return computeWith(
      map, [&roots, size](int32_t l) { return l > 0 && l < size ? roots[l] : 0; }, band_voxels,
      totals);
}

template <typename Resolve>
SurfaceAdjacency SurfaceAdjacency::computeWith(const TsdfMap& map, const Resolve& resolve,
                                               float band_voxels, OwnerTotals* totals) {
  if (!(band_voxels > 0.0f)) throw Error("surface adjacency band_voxels must be > 0");
  if (totals && totals->centre_sum.size() != totals->voxels.size()) {
    throw Error("surface adjacency totals: voxels and centre_sum differ in size");
  }
  const size_t num_totals = totals ? totals->voxels.size() : 0;
  const float band_m = band_voxels * map.voxelSize();
  SurfaceAdjacency out;
  // Owner of every surface voxel, for the blocks that have one (others stay out: at building
  // scale this scratch is about a tenth of the map).
  absl::flat_hash_map<uint64_t, std::vector<int32_t>> owners;
  for (const auto& block : map.blocks()) {
    std::vector<int32_t> labels;
    for (int i = 0; i < kBlockVoxels; ++i) {
      const Voxel& voxel = block->voxels[i];
      const bool on_surface = voxel.weight > 0.0f && std::fabs(voxel.sdf_m) <= band_m;
      if (!on_surface && !totals) continue;
      const int32_t label = argmaxLabel(voxel, resolve);
      if (label <= 0) continue;
      if (static_cast<size_t>(label) < num_totals) {
        ++totals->voxels[label];
        totals->centre_sum[label] +=
            map.voxelCentre(block->index, i % kBlockSide, (i / kBlockSide) % kBlockSide,
                            i / (kBlockSide * kBlockSide))
                .cast<double>();
      }
      if (!on_surface) continue;
      if (labels.empty()) labels.assign(kBlockVoxels, 0);
      labels[static_cast<size_t>(i)] = label;
      ++out.surface_voxels_[label];
    }
    if (!labels.empty()) owners.emplace(TsdfMap::key(block->index), std::move(labels));
  }
  for (const auto& block : map.blocks()) {
    const auto own = owners.find(TsdfMap::key(block->index));
    if (own == owners.end()) continue;
    // The owner arrays of the block and its 26 neighbours, looked up once per block rather than
    // per voxel on its border: near[dx + 1][dy + 1][dz + 1], null where nothing owns surface.
    const std::vector<int32_t>* near[3][3][3];
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const BlockIndex nb = block->index + BlockIndex(dx, dy, dz);
          const auto it = owners.find(TsdfMap::key(nb));
          near[dx + 1][dy + 1][dz + 1] = it == owners.end() ? nullptr : &it->second;
        }
      }
    }
    const std::vector<int32_t>& labels = own->second;
    for (int z = 0; z < kBlockSide; ++z) {
      for (int y = 0; y < kBlockSide; ++y) {
        for (int x = 0; x < kBlockSide; ++x) {
          const int32_t label = labels[static_cast<size_t>(x + kBlockSide * (y + kBlockSide * z))];
          if (label <= 0) continue;
          for (const auto& d : kForward) {
            int nx = x + d[0], ny = y + d[1], nz = z + d[2];
            // Which neighbour block (-1, 0, 1 per axis) and the voxel inside it.
            const int bx = nx < 0 ? -1 : (nx >= kBlockSide ? 1 : 0);
            const int by = ny < 0 ? -1 : (ny >= kBlockSide ? 1 : 0);
            const int bz = nz < 0 ? -1 : (nz >= kBlockSide ? 1 : 0);
            const std::vector<int32_t>* other = near[bx + 1][by + 1][bz + 1];
            if (!other) continue;
            nx -= bx * kBlockSide;
            ny -= by * kBlockSide;
            nz -= bz * kBlockSide;
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
