#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <absl/container/flat_hash_map.h>

#include "panmap/core/labelled_mesh.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/mesh/marching_cubes.h"

namespace panmap {

namespace internal {
class VertexLabeller;
}  // namespace internal

/// Appends block meshes to one mesh as they come, welding the vertices neighbouring blocks
/// share (one vertex per edge of the voxel grid) and labelling each vertex from the map's
/// current voxels. Blocks arrive in blockIndexLess order, so a grid edge is never needed again
/// once the block its lower voxel lies in has been added: only the seam between the blocks
/// added and those to come is remembered, and no block mesh has to be kept after add(). That
/// is what lets a whole map be meshed and welded block by block (marchingCubes).
class MeshWelder {
 public:
  /// @param map the map whose voxels label the vertices; must outlive this and not change
  /// @param labeller how voxels are labelled (no superpoint function: no label arrays)
  /// @param out receives the mesh (appended to; reserve its arrays to avoid regrowth)
  MeshWelder(const TsdfMap& map, const MeshLabeller& labeller, LabelledMesh* out);
  ~MeshWelder();
  MeshWelder(const MeshWelder&) = delete;
  MeshWelder& operator=(const MeshWelder&) = delete;

  /// Appends one block's mesh. Blocks must come in blockIndexLess order, each at most once;
  /// a vertex shared with an earlier block reuses that block's vertex.
  void add(const BlockMesh& mesh);

  /// Starts loading a block mesh that add() will take next, so that its arrays are in cache
  /// by then (the block meshes kept for live updates are cold, each array its own allocation).
  void prefetch(const BlockMesh& mesh) const;

  /// Grid edges on the seam remembered now (for tests: it stays a front, not the whole map).
  size_t seamEdges() const { return seam_.size(); }

 private:
  // A grid edge anywhere in the map: its lower voxel's block key and its id within that block.
  using EdgeKey = std::pair<uint64_t, uint16_t>;

  int32_t emit(const BlockMesh& mesh, size_t i);

  LabelledMesh* out_;
  std::unique_ptr<internal::VertexLabeller> label_vertex_;  // null: nothing labelled
  absl::flat_hash_map<EdgeKey, int32_t> seam_;  // edge -> vertex, for edges a later block shares
  std::vector<int32_t> local_;                  // this block's vertex -> the mesh's
};

}  // namespace panmap
