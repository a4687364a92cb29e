#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "panmap/core/image.h"
#include "panmap/core/labelled_mesh.h"
#include "panmap/core/thread_pool.h"
#include "panmap/map/tsdf_map.h"

namespace panmap {

/// Parameters of marching cubes over a TsdfMap. A cube joins 8 neighbouring voxel centres.
struct MarchingCubesConfig {
  /// A voxel counts as observed when its weight is above this. A cube is meshed only when all
  /// 8 corners are observed, so no face is invented across unobserved space (e.g. the
  /// truncation border of a band, or the gap between two scans).
  float min_weight = 0.0f;
  /// A sign change along a cube edge is taken as a surface only when the two samples differ
  /// by less than this many voxels; otherwise the cube is skipped. A true distance field
  /// changes by at most one voxel per voxel step, a projective one by 1 / cos(incidence), and
  /// a sample clamped at the truncation only bounds the distance. Set it to the integrator's
  /// truncation (default 4 voxels): then a clamped sample never pairs with one of the other
  /// sign (the false "skirts" at depth discontinuities when free space is carved), while
  /// surfaces seen up to 75 degrees from their normal are still meshed.
  float max_sdf_jump_voxels = 4.0f;
  /// Throws Error naming the bad field.
  void check() const;
};

/// Per-vertex labels computed when a mesh is assembled, never stored with the geometry: they
/// change (super-points merge, the optimiser relabels) without the surface changing.
struct MeshLabeller {
  /// Super-point label of a voxel's votes (e.g. argmaxLabel with the current merges). Empty:
  /// the mesh gets no label arrays. A vertex takes the label of the nearer voxel of its edge.
  /// Called only for voxels with votes: a voxel without any has label 0.
  std::function<int32_t(const VoxelVotes&)> superpoint;
  /// NYU40 class of a super-point label; empty: 0 (unlabelled).
  std::function<int32_t(int32_t)> semantic;
  /// Instance of a super-point label; empty: 0 (none).
  std::function<int32_t(int32_t)> instance;
  /// A vertex whose voxel has no label (no pixel's point ever fell in it: pixels on edges
  /// and in tiny segments do not vote, so thin parts keep many such voxels) takes the class
  /// and instance of the label most of the voxel's 26 neighbours carry (ties: more votes,
  /// then the smaller label); its super-point stays 0 (it belongs to none).
  bool fill_from_neighbours = false;
};

/// The mesh of the cubes whose lower corner lies in one block. Its vertices sit on the block's
/// edges of the voxel grid, including edges whose lower voxel is in an upper neighbour block
/// (x, y or z local coordinate 8); assembly welds those with the neighbour's own vertices.
struct BlockMesh {
  BlockIndex index = BlockIndex::Zero();  ///< the block the cubes start in
  std::vector<Eigen::Vector3f> vertices;  ///< world frame, metres
  std::vector<Rgb8> colors;               ///< interpolated along the edge
  /// Grid edge of each vertex: axis + 3 * (x + 9 * (y + 9 * z)), (x, y, z) in [0, 8] the edge's
  /// lower voxel relative to the block.
  std::vector<uint16_t> edges;
  /// Nearer voxel of each vertex's edge: (neighbour slot dx + 2 dy + 4 dz) << 9 | voxel index
  /// within that block. Labels are looked up through it at assembly time.
  std::vector<uint16_t> sources;
  std::vector<Eigen::Vector3i> faces;  ///< indices into `vertices`, outward (toward sdf > 0)

  /// Removes everything but the index.
  void clear();
};

/// Local edge id of a grid edge (see BlockMesh::edges).
inline uint16_t blockEdgeId(int x, int y, int z, int axis) {
  return static_cast<uint16_t>(axis + 3 * (x + 9 * (y + 9 * z)));
}

/// The blocks whose voxels the cubes of one block read: the block (slot 0) and its upper
/// neighbours at (slot & 1, slot >> 1 & 1, slot >> 2), null where the map has none.
struct BlockGrid {
  const Block* blocks[8] = {};
};

/// Looks up the 8 blocks of `block`'s grid in `map` (7 hash look-ups).
BlockGrid blockGrid(const TsdfMap& map, const Block& block);

/// Starts loading into the L2 cache the voxels meshBlock() reads from `grid` (the block and
/// one layer of its upper neighbours, 9^3 voxels on about 160 cache lines), so that meshing
/// one block overlaps the memory reads of the next.
void prefetchBlockGrid(const BlockGrid& grid);

/// Marching cubes over the cubes whose lower corner lies in `block` (cubes on its upper
/// faces read the up to 7 upper neighbour blocks; missing neighbours count as unobserved).
/// Vertices are welded within the block; faces wind counter-clockwise seen from sdf > 0.
/// @param mesh receives the result (cleared first)
void meshBlock(const TsdfMap& map, const Block& block, const MarchingCubesConfig& config,
               BlockMesh* mesh);
/// meshBlock() of grid.blocks[0], its neighbours already looked up in `map` (blockGrid()).
void meshBlock(const TsdfMap& map, const BlockGrid& grid, const MarchingCubesConfig& config,
               BlockMesh* mesh);

/// meshBlock() of blocks[0 .. n) in order, each into `*target(i)`, then `done(i)` (may be
/// empty): while one block is meshed and `done` runs, the next block's grid is prefetched.
/// Blocks in z, y, x order (x fastest) gain most: the next block is then often the neighbour
/// across x whose voxels the block before has just read.
void meshBlocks(const TsdfMap& map, const Block* const* blocks, size_t n,
                const MarchingCubesConfig& config, const std::function<BlockMesh*(size_t)>& target,
                const std::function<void(size_t)>& done = {});

/// Concatenates block meshes into one mesh, welding the vertices they share on block
/// borders (one vertex per edge of the voxel grid), and labels every vertex through
/// `labeller` from the map's current voxels (MeshWelder). Blocks must come in blockIndexLess
/// order, each once. Blocks missing from `map` give label 0.
LabelledMesh assembleBlockMeshes(const TsdfMap& map, const std::vector<const BlockMesh*>& blocks,
                                 const MeshLabeller& labeller = {});

/// One block's mesh on its own, labelled through `labeller` from the map's current voxels:
/// its vertices on the upper borders are not welded with the neighbours' (a viewer draws
/// blocks side by side and replaces a block when it changes).
LabelledMesh labelBlockMesh(const TsdfMap& map, const BlockMesh& mesh,
                            const MeshLabeller& labeller = {});

namespace internal {
class VertexLabeller;
}  // namespace internal

/// Per vertex of a BlockMesh: its super-point, class and instance (empty when nothing is
/// labelled).
struct BlockLabels {
  std::vector<int32_t> superpoint;
  std::vector<int32_t> semantic;
  std::vector<int32_t> instance;
};

/// labelBlockMesh for one block after another, keeping its scratch memory (the labels of the
/// voxels around a block) between blocks: one per thread. The map must not change while it
/// is in use.
class BlockMeshLabeller {
 public:
  /// @param map the map whose voxels label the vertices; must outlive this
  /// @param labeller how voxels are labelled; must outlive this
  BlockMeshLabeller(const TsdfMap& map, const MeshLabeller& labeller);
  ~BlockMeshLabeller();
  BlockMeshLabeller(const BlockMeshLabeller&) = delete;
  BlockMeshLabeller& operator=(const BlockMeshLabeller&) = delete;

  /// The same as labelBlockMesh(map, mesh, labeller).
  LabelledMesh label(const BlockMesh& mesh);
  /// The labels label() gives the vertices of `mesh`, without a copy of its geometry.
  BlockLabels labels(const BlockMesh& mesh);

 private:
  std::unique_ptr<internal::VertexLabeller> vertex_;  // null when nothing is labelled
};

/// Orders block indices by x, then y, then z: the order of every assembled mesh.
inline bool blockIndexLess(const BlockIndex& a, const BlockIndex& b) {
  if (a.x() != b.x()) return a.x() < b.x();
  if (a.y() != b.y()) return a.y() < b.y();
  return a.z() < b.z();
}

/// Marching cubes over every allocated block of `map`, from scratch: a watertight mesh for a
/// closed, fully observed surface, with per-vertex colour and (through `labeller`) labels.
/// The same mesh as assembleBlockMeshes() of every block's meshBlock() in blockIndexLess
/// order, but no block mesh is kept: blocks are meshed twice (a count, then a batch at a time
/// welded into the reserved mesh), so the memory is the mesh's own. Does not touch the
/// blocks' `updated` flags (IncrementalMesher does).
/// @param pool threads to mesh blocks with (not owned), or null for the calling thread;
/// the labeller is only called on the calling thread
LabelledMesh marchingCubes(const TsdfMap& map, const MarchingCubesConfig& config = {},
                           const MeshLabeller& labeller = {}, ThreadPool* pool = nullptr);

}  // namespace panmap
