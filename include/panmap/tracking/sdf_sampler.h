#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "panmap/map/tsdf_map.h"

namespace panmap {

/// Trilinear TSDF interpolation with gradient, bit-identical to interpolateSdf() but faster
/// for the many nearby queries of a tracking iteration: the 8 voxels come straight from one
/// block when they share it (2 in 3 queries at 8 voxels per side), and block lookups go
/// through a small direct-mapped cache that also remembers unallocated blocks. The map must
/// not change while a sampler is in use. One per thread.
class SdfSampler {
 public:
  /// The 8 voxels around the last position of one query point. An optimiser moves each point
  /// by less than a voxel per iteration, so most evaluations find their voxels here and never
  /// touch the map (whose voxels, scattered over megabytes, made up most of the time).
  struct Cell {
    enum State : int8_t { kUnknown, kObserved, kUnobserved };
    Eigen::Vector3i corner = Eigen::Vector3i::Zero();  ///< global index of the lowest voxel
    State state = kUnknown;
    float c[8] = {};  ///< sdf_m, x fastest
    /// Position of voxel corner + (dx, dy, dz) in c.
    static int index(int dx, int dy, int dz) { return dx + 2 * dy + 4 * dz; }
  };

  /// @param map the TSDF read (not owned; must outlive the sampler)
  explicit SdfSampler(const TsdfMap& map);

  /// Interpolated distance (metres) and, if gradient_W is not null, its world-frame gradient
  /// at p_W; false when any of the 8 surrounding voxels is unobserved or unallocated.
  /// @param cell if not null, the query point's cell: reused when p_W is still in it,
  ///        refilled otherwise (the result is the same bits either way)
  bool sample(const Eigen::Vector3f& p_W, float* sdf_m, Eigen::Vector3f* gradient_W,
              Cell* cell = nullptr);

 private:
  const Block* block(int bx, int by, int bz);
  bool gather(int ix, int iy, int iz, float* c);  // false when a voxel is unobserved

  struct CacheEntry {
    uint64_t key = 0;
    const Block* block = nullptr;
    bool valid = false;
  };
  static constexpr int kCacheBits = 10;  // 24 KiB: 1 in 10 lookups misses on a room frame

  const TsdfMap& map_;
  float voxel_m_;
  std::array<CacheEntry, 1 << kCacheBits> cache_{};
};

}  // namespace panmap
