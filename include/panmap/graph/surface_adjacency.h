#pragma once

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include <absl/container/flat_hash_map.h>
#include <absl/container/flat_hash_set.h>

#include "panmap/core/thread_pool.h"
#include "panmap/map/tsdf_map.h"

namespace panmap {

/// Which super-points own the observed surface and which of them touch there: the neighbourhood
/// structure the super-point graph keeps its edges to (issue 23: edges bounded by the surface,
/// not by the history of masks).
class SurfaceAdjacency {
 public:
  /// Scans the map once. A voxel is on the surface when observed (weight > 0) and
  /// |sdf| <= band_voxels voxels; its owner is its Eq. 2 label (argmaxLabel through `resolve`).
  /// Two super-points touch when two surface voxels they own are 26-neighbours.
  /// @param map the label-TSDF
  /// @param resolve maps a stored label to its live (root) super-point
  /// @param band_voxels surface band half-width, in voxels (> 0)
  /// @param pool threads to scan the blocks with (null: the caller's thread); the result does
  ///        not depend on the number of threads
  static SurfaceAdjacency compute(const TsdfMap& map,
                                  const std::function<int32_t(int32_t)>& resolve, float band_voxels,
                                  ThreadPool* pool = nullptr);

  /// Voxel counts of the live super-points over the whole map (not only the surface band),
  /// indexed by label, and the sums of their voxels' centres (from exact sums of voxel
  /// indices, so in no particular order). Sized by the caller: labels beyond the size are not
  /// counted.
  struct OwnerTotals {
    std::vector<int> voxels;
    std::vector<Eigen::Vector3d> centre_sum;
  };

  /// compute() that also fills `totals` in the same scan: the super-point graph needs both,
  /// and reading the map once instead of twice saves a pass over every voxel.
  static SurfaceAdjacency compute(const TsdfMap& map,
                                  const std::function<int32_t(int32_t)>& resolve, float band_voxels,
                                  OwnerTotals* totals, ThreadPool* pool = nullptr);

  /// The same with labels resolved through a table: roots[label] is the live super-point of a
  /// stored label (LabelRegistry::parents() after flatten()); labels outside it resolve to 0.
  /// Every voxel's votes are resolved, so a table lookup instead of a call matters.
  static SurfaceAdjacency compute(const TsdfMap& map, const std::vector<int32_t>& roots,
                                  float band_voxels, OwnerTotals* totals,
                                  ThreadPool* pool = nullptr);

  /// Surface voxels owned by a live super-point (0 when it owns none).
  int surfaceVoxels(int32_t label) const;
  /// True when the two super-points own touching surface voxels (either order; false for a == b).
  bool touching(int32_t a, int32_t b) const;
  /// Number of super-points owning surface voxels.
  size_t numOwners() const { return surface_voxels_.size(); }
  /// Number of touching pairs.
  size_t numPairs() const { return pairs_.size(); }

 private:
  friend class SurfaceScan;  // builds one from its per-block results
  static uint64_t key(int32_t a, int32_t b);
  template <typename Resolve>
  static SurfaceAdjacency computeWith(const TsdfMap& map, const Resolve& resolve, float band_voxels,
                                      OwnerTotals* totals, ThreadPool* pool);

  absl::flat_hash_map<int32_t, int> surface_voxels_;
  absl::flat_hash_set<uint64_t> pairs_;  // (min << 32) | max
};

}  // namespace panmap
