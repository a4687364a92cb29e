#include "panmap/tracking/sdf_sampler.h"

#include <cmath>

namespace panmap {

SdfSampler::SdfSampler(const TsdfMap& map) : map_(map), voxel_m_(map.voxelSize()) {}

const Block* SdfSampler::block(int bx, int by, int bz) {
  const BlockIndex index(bx, by, bz);
  const uint64_t key = TsdfMap::key(index);
  CacheEntry& entry = cache_[(key * 0x9E3779B97F4A7C15ull) >> (64 - kCacheBits)];
  if (!entry.valid || entry.key != key) {
    entry.key = key;
    entry.block = map_.findBlock(index);
    entry.valid = true;
  }
  return entry.block;
}

bool SdfSampler::gather(int ix, int iy, int iz, float* c) {
  static_assert(kBlockSide == 8, "shifts assume 8 voxels per block side");
  const int lx = ix & 7, ly = iy & 7, lz = iz & 7;
  if (lx < 7 && ly < 7 && lz < 7) {  // all eight in one block
    const Block* b = block(ix >> 3, iy >> 3, iz >> 3);
    if (!b) return false;
    for (int dz = 0; dz < 2; ++dz) {
      for (int dy = 0; dy < 2; ++dy) {
        const Voxel* row = &b->at(lx, ly + dy, lz + dz);
        if (row[0].weight <= 0.0f || row[1].weight <= 0.0f) return false;
        c[Cell::index(0, dy, dz)] = row[0].sdf_m;
        c[Cell::index(1, dy, dz)] = row[1].sdf_m;
      }
    }
    return true;
  }
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const int x = ix + dx, y = iy + dy, z = iz + dz;
        const Block* b = block(x >> 3, y >> 3, z >> 3);
        if (!b) return false;
        const Voxel& voxel = b->at(x & 7, y & 7, z & 7);
        if (voxel.weight <= 0.0f) return false;
        c[Cell::index(dx, dy, dz)] = voxel.sdf_m;
      }
    }
  }
  return true;
}

bool SdfSampler::sample(const Eigen::Vector3f& p_W, float* sdf_m, Eigen::Vector3f* gradient_W,
                        Cell* cell) {
  // The arithmetic below repeats interpolateSdf() operation for operation, so that both give
  // the same bits: voxel centres sit at (i + 0.5) v.
  const float v = voxel_m_;
  const Eigen::Vector3f g = p_W / v - Eigen::Vector3f::Constant(0.5f);
  const Eigen::Vector3f base = g.array().floor();
  const Eigen::Vector3f t = g - base;
  const Eigen::Vector3i corner = base.cast<int>();
  Cell local;
  if (!cell) cell = &local;
  if (cell->state == Cell::kUnknown || cell->corner != corner) {
    cell->corner = corner;
    cell->state =
        gather(corner.x(), corner.y(), corner.z(), cell->c) ? Cell::kObserved : Cell::kUnobserved;
  }
  if (cell->state != Cell::kObserved) return false;
  const float* c = cell->c;
  auto at = [c](int dx, int dy, int dz) { return c[Cell::index(dx, dy, dz)]; };
  auto lerp = [](float a, float b, float s) { return a + s * (b - a); };
  const float c00 = lerp(at(0, 0, 0), at(1, 0, 0), t.x()),
              c10 = lerp(at(0, 1, 0), at(1, 1, 0), t.x());
  const float c01 = lerp(at(0, 0, 1), at(1, 0, 1), t.x()),
              c11 = lerp(at(0, 1, 1), at(1, 1, 1), t.x());
  const float c0 = lerp(c00, c10, t.y()), c1 = lerp(c01, c11, t.y());
  *sdf_m = lerp(c0, c1, t.z());
  if (gradient_W) {
    const float gx = lerp(lerp(at(1, 0, 0) - at(0, 0, 0), at(1, 1, 0) - at(0, 1, 0), t.y()),
                          lerp(at(1, 0, 1) - at(0, 0, 1), at(1, 1, 1) - at(0, 1, 1), t.y()), t.z());
    const float gy = lerp(lerp(at(0, 1, 0) - at(0, 0, 0), at(1, 1, 0) - at(1, 0, 0), t.x()),
                          lerp(at(0, 1, 1) - at(0, 0, 1), at(1, 1, 1) - at(1, 0, 1), t.x()), t.z());
    const float gz = c1 - c0;
    *gradient_W = Eigen::Vector3f(gx, gy, gz) / v;
  }
  return true;
}

}  // namespace panmap
