#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <absl/container/flat_hash_map.h>
#include <absl/container/flat_hash_set.h>

#include "panmap/core/labelled_mesh.h"
#include "panmap/core/thread_pool.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/mesh/marching_cubes.h"

namespace panmap {

/// Keeps one BlockMesh per block and re-meshes only what changed. A block's cubes read its
/// voxels and those of its 7 upper neighbours, so a changed block invalidates itself and its
/// 7 lower neighbours. Labels are not stored: assemble() reads them from the map through a
/// MeshLabeller, so super-point merges and optimised labels need no re-meshing. The
/// assembled mesh is identical to marchingCubes() of the same map.
class IncrementalMesher {
 public:
  /// @param pool threads to mesh blocks with (not owned), or null for the calling thread
  explicit IncrementalMesher(const MarchingCubesConfig& config = {}, ThreadPool* pool = nullptr);

  /// Called on the meshing thread (0 .. pool size - 1) right after a block is re-meshed, while
  /// its voxels are still in cache (e.g. to label its vertices).
  using BlockMeshedFn = std::function<void(const BlockMesh& mesh, int thread)>;

  /// Re-meshes every block whose `updated` flag is set, their lower neighbours, and blocks
  /// (with their lower neighbours) this mesher has not seen yet; then clears the flags.
  /// Deterministic whatever the thread count. Returns the number of blocks re-meshed.
  size_t update(TsdfMap* map, const BlockMeshedFn& on_meshed = {});

  /// Re-meshes every allocated block, whatever its flag (flags are left as they are).
  void rebuild(const TsdfMap& map);

  /// The whole mesh: block meshes in blockIndexLess order, border vertices welded, labels
  /// read from `map`'s current voxels through `labeller`.
  LabelledMesh assemble(const TsdfMap& map, const MeshLabeller& labeller = {}) const;

  /// Blocks re-meshed since the last call, in blockIndexLess order (each once), and forgets
  /// them: what a live viewer has to replace. update() and rebuild() add to the list whoever
  /// triggered them (an export between two calls loses nothing).
  std::vector<BlockIndex> takeChangedBlocks();

  /// The stored mesh of a block, or null when the block was never meshed (or was dropped by
  /// invalidateAll() and not meshed since).
  const BlockMesh* find(const BlockIndex& index) const;
  /// find() as shared ownership: the mesh stays as it is for as long as the caller holds it,
  /// since re-meshing a block whose mesh is held elsewhere makes a new one.
  std::shared_ptr<const BlockMesh> share(const BlockIndex& index) const;

  /// Blocks re-meshed by the last update() or rebuild().
  size_t lastRemeshedBlocks() const { return last_remeshed_; }
  /// Blocks re-meshed since construction or clear().
  uint64_t totalRemeshedBlocks() const { return total_remeshed_; }
  /// Blocks with a stored mesh (possibly empty).
  size_t numBlockMeshes() const { return meshes_.size(); }
  /// Forgets every block mesh: the next update() meshes the whole map.
  void clear();
  /// Forgets every block mesh, for a map that was rebuilt: the next update() meshes the whole
  /// map, and takeChangedBlocks() also lists the blocks meshed before (those the new map does
  /// not mesh come back with an empty mesh), so a viewer drops what moved away.
  void invalidateAll();
  /// The threads to mesh with from now on (null: the calling thread only), for a mapper
  /// whose pool was replaced.
  void setPool(ThreadPool* pool) { pool_ = pool; }
  /// The config in use.
  const MarchingCubesConfig& config() const { return config_; }

 private:
  void remesh(const TsdfMap& map, std::vector<const Block*>* blocks,
              const BlockMeshedFn& on_meshed = {});

  MarchingCubesConfig config_;
  ThreadPool* pool_;
  // By TsdfMap::key of the block; never null. Shared with the callers of share().
  absl::flat_hash_map<uint64_t, std::shared_ptr<BlockMesh>> meshes_;
  absl::flat_hash_set<uint64_t> changed_;              // re-meshed since takeChangedBlocks()
  absl::flat_hash_map<uint64_t, BlockIndex> dropped_;  // meshed before invalidateAll()
  size_t last_remeshed_ = 0;
  uint64_t total_remeshed_ = 0;
};

}  // namespace panmap
