#include "panmap/graph/surface_adjacency.h"

#include <algorithm>
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/graph/internal/touching_voxels.h"
#include "panmap/map/voxel.h"

namespace panmap {

uint64_t SurfaceAdjacency::key(int32_t a, int32_t b) {
  const auto [lo, hi] = std::minmax(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(lo)) << 32) | static_cast<uint32_t>(hi);
}

SurfaceAdjacency SurfaceAdjacency::compute(const TsdfMap& map,
                                           const std::function<int32_t(int32_t)>& resolve,
                                           float band_voxels, ThreadPool* pool) {
  return computeWith(map, resolve, band_voxels, nullptr, pool);
}

SurfaceAdjacency SurfaceAdjacency::compute(const TsdfMap& map,
                                           const std::function<int32_t(int32_t)>& resolve,
                                           float band_voxels, OwnerTotals* totals,
                                           ThreadPool* pool) {
  return computeWith(map, resolve, band_voxels, totals, pool);
}

SurfaceAdjacency SurfaceAdjacency::compute(const TsdfMap& map, const std::vector<int32_t>& roots,
                                           float band_voxels, OwnerTotals* totals,
                                           ThreadPool* pool) {
  const auto size = static_cast<int32_t>(roots.size());
  return computeWith(
      map, [&roots, size](int32_t l) { return l > 0 && l < size ? roots[l] : 0; }, band_voxels,
      totals, pool);
}

namespace {

using Index3 = Eigen::Matrix<int64_t, 3, 1>;

/// What one thread gathers; combined by sums and unions, so the result does not depend on
/// which thread scanned which block.
struct ThreadScan {
  std::vector<int> voxels;        // per label
  std::vector<Index3> index_sum;  // per label: sum of global voxel indices
  absl::flat_hash_map<int32_t, int> surface_voxels;
  absl::flat_hash_set<uint64_t> pairs;
};

/// Runs fn(begin, end, thread) over [0, n) on the pool (blocks cost unevenly), or inline.
void forBlocks(ThreadPool* pool, size_t n, const std::function<void(size_t, size_t, int)>& fn) {
  if (pool && pool->size() > 1) {
    pool->parallelForDynamic(n, 64, fn);
  } else {
    fn(0, n, 0);
  }
}

}  // namespace

template <typename Resolve>
SurfaceAdjacency SurfaceAdjacency::computeWith(const TsdfMap& map, const Resolve& resolve,
                                               float band_voxels, OwnerTotals* totals,
                                               ThreadPool* pool) {
  if (!(band_voxels > 0.0f)) throw Error("surface adjacency band_voxels must be > 0");
  if (totals && totals->centre_sum.size() != totals->voxels.size()) {
    throw Error("surface adjacency totals: voxels and centre_sum differ in size");
  }
  const size_t num_totals = totals ? totals->voxels.size() : 0;
  const float band_m = band_voxels * map.voxelSize();
  const auto& blocks = map.blocks();
  std::vector<ThreadScan> scans(pool ? static_cast<size_t>(pool->size()) : 1);
  for (ThreadScan& scan : scans) {
    scan.voxels.assign(num_totals, 0);
    scan.index_sum.assign(num_totals, Index3::Zero());
  }
  // Owner of every surface voxel, for the blocks that have one (others stay empty: at building
  // scale this scratch is about a tenth of the map).
  std::vector<std::vector<int32_t>> owners(blocks.size());
  forBlocks(pool, blocks.size(), [&](size_t begin, size_t end, int t) {
    ThreadScan& scan = scans[static_cast<size_t>(t)];
    for (size_t b = begin; b < end; ++b) {
      const Block& block = *blocks[b];
      const Index3 origin = block.index.cast<int64_t>() * kBlockSide;
      std::vector<int32_t>& labels = owners[b];
      for (int i = 0; i < kBlockVoxels; ++i) {
        const Voxel& voxel = block.voxels[i];
        const bool on_surface = voxel.weight > 0.0f && std::fabs(voxel.sdf_m) <= band_m;
        if (!on_surface && !totals) continue;
        const int32_t label = argmaxLabel(block.votes(i), resolve);
        if (label <= 0) continue;
        if (static_cast<size_t>(label) < num_totals) {
          ++scan.voxels[label];
          scan.index_sum[label] += origin + Index3(i % kBlockSide, (i / kBlockSide) % kBlockSide,
                                                   i / (kBlockSide * kBlockSide));
        }
        if (!on_surface) continue;
        if (labels.empty()) labels.assign(kBlockVoxels, 0);
        labels[static_cast<size_t>(i)] = label;
        ++scan.surface_voxels[label];
      }
    }
  });
  absl::flat_hash_map<uint64_t, size_t> owner_block;  // block key -> index, blocks with owners
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (!owners[b].empty()) owner_block.emplace(TsdfMap::key(blocks[b]->index), b);
  }
  forBlocks(pool, blocks.size(), [&](size_t begin, size_t end, int t) {
    ThreadScan& scan = scans[static_cast<size_t>(t)];
    for (size_t b = begin; b < end; ++b) {
      if (owners[b].empty()) continue;
      const BlockIndex index = blocks[b]->index;
      // The owner arrays of the block and its 26 neighbours, looked up once per block rather
      // than per voxel on its border.
      internal::NearOwners near;
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const auto it = owner_block.find(TsdfMap::key(index + BlockIndex(dx, dy, dz)));
            near[dx + 1][dy + 1][dz + 1] = it == owner_block.end() ? nullptr : &owners[it->second];
          }
        }
      }
      internal::forEachTouchingPair(
          near, [&scan](int32_t a, int32_t b) { scan.pairs.insert(key(a, b)); });
    }
  });
  SurfaceAdjacency out;
  out.surface_voxels_ = std::move(scans[0].surface_voxels);
  out.pairs_ = std::move(scans[0].pairs);
  for (size_t t = 1; t < scans.size(); ++t) {
    for (const auto& [label, count] : scans[t].surface_voxels) out.surface_voxels_[label] += count;
    out.pairs_.insert(scans[t].pairs.begin(), scans[t].pairs.end());
  }
  if (totals) {
    const double voxel_m = map.voxelSize();
    for (size_t label = 0; label < num_totals; ++label) {
      int count = 0;
      Index3 sum = Index3::Zero();
      for (const ThreadScan& scan : scans) {
        count += scan.voxels[label];
        sum += scan.index_sum[label];
      }
      if (count == 0) continue;
      totals->voxels[label] += count;
      // Voxel centres are (index + 0.5) x voxel size (TsdfMap::voxelCentre).
      totals->centre_sum[label] +=
          (sum.cast<double>() + Eigen::Vector3d::Constant(0.5 * count)) * voxel_m;
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
