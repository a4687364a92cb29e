#include "panmap/mesh/marching_cubes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <numeric>
#include <utility>

#include "panmap/core/error.h"
#include "panmap/mesh/internal/marching_cubes_tables.h"
#include "panmap/mesh/internal/vertex_labeller.h"
#include "panmap/mesh/mesh_welder.h"

namespace panmap {

using internal::kMcCornerOffset;
using internal::kMcEdgeCorners;
using internal::kMcTriangles;

void MarchingCubesConfig::check() const {
  if (!(min_weight >= 0.0f) || !std::isfinite(min_weight)) {
    throw Error("marching cubes min_weight must be finite and >= 0");
  }
  if (!(max_sdf_jump_voxels > 0.0f)) {
    throw Error("marching cubes max_sdf_jump_voxels must be > 0");
  }
}

void BlockMesh::clear() {
  vertices.clear();
  colors.clear();
  edges.clear();
  sources.clear();
  faces.clear();
}

namespace {

// A block's cubes read a 9^3 grid of voxels: the block plus one layer of its upper neighbours.
constexpr int kGrid = kBlockSide + 1;
constexpr int kGridVoxels = kGrid * kGrid * kGrid;
constexpr int kEdgeIds = 3 * kGridVoxels;
static_assert(kEdgeIds <= 65536, "edge ids must fit uint16_t");
static_assert(kBlockSide == 8, "neighbour slots and sources assume 8 voxels per block side");

constexpr int gridIndex(int x, int y, int z) { return x + kGrid * (y + kGrid * z); }

// Per cube edge: offset of its lower corner and its axis, derived from the corner table.
struct CubeEdge {
  int lower[3];
  int axis;
  int lower_corner, upper_corner;
};

std::array<CubeEdge, 12> makeCubeEdges() {
  std::array<CubeEdge, 12> edges{};
  for (int e = 0; e < 12; ++e) {
    int a = kMcEdgeCorners[e][0], b = kMcEdgeCorners[e][1];
    int axis = 0;
    while (kMcCornerOffset[a][axis] == kMcCornerOffset[b][axis]) ++axis;
    if (kMcCornerOffset[a][axis] > kMcCornerOffset[b][axis]) std::swap(a, b);
    edges[e] =
        CubeEdge{{kMcCornerOffset[a][0], kMcCornerOffset[a][1], kMcCornerOffset[a][2]}, axis, a, b};
  }
  return edges;
}

const std::array<CubeEdge, 12>& cubeEdges() {
  static const std::array<CubeEdge, 12> edges = makeCubeEdges();
  return edges;
}

// Crossed edges of each case: those whose corners lie on different sides.
const std::array<uint16_t, 256>& edgeMasks() {
  static const std::array<uint16_t, 256> masks = [] {
    std::array<uint16_t, 256> m{};
    for (int c = 0; c < 256; ++c) {
      for (int e = 0; e < 12; ++e) {
        if (((c >> kMcEdgeCorners[e][0]) ^ (c >> kMcEdgeCorners[e][1])) & 1) m[c] |= 1 << e;
      }
    }
    return m;
  }();
  return masks;
}

BlockIndex slotOffset(int slot) { return BlockIndex(slot & 1, (slot >> 1) & 1, (slot >> 2) & 1); }

}  // namespace

BlockGrid blockGrid(const TsdfMap& map, const Block& block) {
  BlockGrid grid;
  grid.blocks[0] = &block;
  for (int slot = 1; slot < 8; ++slot)
    grid.blocks[slot] = map.findBlock(block.index + slotOffset(slot));
  return grid;
}

void prefetchBlockGrid(const BlockGrid& grid) {
  // Into L2 (locality 2): the lines are read a block later, and L1 meanwhile serves the block
  // being meshed, its labels and its output.
  const char* p = reinterpret_cast<const char*>(grid.blocks[0]->voxels);
  for (size_t line = 0; line < sizeof(Block::voxels); line += 64)
    __builtin_prefetch(p + line, 0, 2);
  for (int slot = 1; slot < 8; ++slot) {
    const Block* b = grid.blocks[slot];
    if (!b) continue;
    // The layer the cubes read: x = 0 of the neighbour across x (slot & 1), y = 0 across y,
    // z = 0 across z. A row of 8 voxels along x is one cache line, so the neighbour across x
    // costs as many lines as the block itself.
    for (int z = 0; z < (slot & 4 ? 1 : kBlockSide); ++z) {
      for (int y = 0; y < (slot & 2 ? 1 : kBlockSide); ++y)
        __builtin_prefetch(&b->at(0, y, z), 0, 2);
    }
  }
}

void meshBlock(const TsdfMap& map, const Block& block, const MarchingCubesConfig& config,
               BlockMesh* mesh) {
  meshBlock(map, blockGrid(map, block), config, mesh);
}

void meshBlocks(const TsdfMap& map, const Block* const* blocks, size_t n,
                const MarchingCubesConfig& config, const std::function<BlockMesh*(size_t)>& target,
                const std::function<void(size_t)>& done) {
  if (n == 0) return;
  // Cold, a block took twice as long to mesh as when its voxels were cached (7-Scenes at 1 cm).
  BlockGrid next = blockGrid(map, *blocks[0]);
  for (size_t i = 0; i < n; ++i) {
    const BlockGrid grid = next;
    if (i + 1 < n) {
      next = blockGrid(map, *blocks[i + 1]);
      prefetchBlockGrid(next);
    }
    meshBlock(map, grid, config, target(i));
    if (done) done(i);
  }
}

void meshBlock(const TsdfMap& map, const BlockGrid& grid, const MarchingCubesConfig& config,
               BlockMesh* mesh) {
  const Block& block = *grid.blocks[0];
  mesh->clear();
  mesh->index = block.index;
  // One hash look-up per neighbour block (blockGrid()), none per voxel.
  const Block* const* neighbours = grid.blocks;

  // Per grid row (y, z): the sdf of its 9 voxels; bit x of inside[row] set when voxel x has
  // sdf < 0, of observed[row] when its weight is above min_weight. Missing blocks read as
  // unobserved with sdf 0.
  // Distances stay 2-byte floats (Voxel::sdf_m) here: classifying reads their bits, and only
  // the corners of crossed edges are converted.
  uint16_t sdf[kGridVoxels];
  uint16_t inside[kGrid * kGrid], observed[kGrid * kGrid];
  uint32_t any_inside = 0, any_outside = 0;
  // weight > min_weight (>= 0) as bits: non-negative binary16 values order as their bits, so
  // the observed weights are those from the smallest one above min_weight up to infinity.
  const Float16 rounded_min(config.min_weight);
  const uint16_t observed_from = static_cast<float>(rounded_min) > config.min_weight
                                     ? rounded_min.bits()
                                     : static_cast<uint16_t>(rounded_min.bits() + 1u);
  constexpr uint16_t kInfinityBits = 0x7C00u;
  // The rows are 256 bytes apart in their blocks and the upper neighbour's voxel of each row
  // in another block: asking for the next rows' memory early overlaps the cache misses.
  constexpr int kPrefetchRows = 2;
  auto prefetchRow = [&neighbours](int y, int z) {
    const int slot = ((y >> 3) << 1) | ((z >> 3) << 2);
    if (const Block* b = neighbours[slot]) {
      const char* p = reinterpret_cast<const char*>(&b->at(0, y & 7, z & 7));
      for (int offset = 0; offset < kBlockSide * static_cast<int>(sizeof(Voxel)); offset += 64) {
        __builtin_prefetch(p + offset);
      }
    }
    if (const Block* b = neighbours[slot | 1]) __builtin_prefetch(&b->at(0, y & 7, z & 7));
  };
  for (int r = 0; r < kPrefetchRows; ++r) prefetchRow(r, 0);
  for (int z = 0; z < kGrid; ++z) {
    for (int y = 0; y < kGrid; ++y) {
      const int row = y + kGrid * z;
      const int ahead = row + kPrefetchRows;
      if (ahead < kGrid * kGrid) prefetchRow(ahead % kGrid, ahead / kGrid);
      const int slot = ((y >> 3) << 1) | ((z >> 3) << 2);
      uint16_t* row_sdf = sdf + kGrid * row;
      uint32_t in = 0, obs = 0;
      for (int part = 0; part < 2; ++part) {
        const int begin = part * kBlockSide, count = part == 0 ? kBlockSide : 1;
        const Block* b = neighbours[slot | part];
        if (!b) {
          std::fill(row_sdf + begin, row_sdf + begin + count, uint16_t{0});
          continue;
        }
        const Voxel* v = &b->at(0, y & 7, z & 7);
        for (int i = 0; i < count; ++i) {
          const uint16_t bits = v[i].sdf_m.bits(), weight = v[i].weight.bits();
          row_sdf[begin + i] = bits;
          in |= static_cast<uint32_t>(Float16::bitsBelowZero(bits)) << (begin + i);
          obs |= static_cast<uint32_t>(weight >= observed_from && weight <= kInfinityBits)
                 << (begin + i);
        }
      }
      inside[row] = static_cast<uint16_t>(in);
      observed[row] = static_cast<uint16_t>(obs);
      any_inside |= in & obs;
      any_outside |= ~in & obs;
    }
  }
  if (!any_inside || !any_outside) return;  // no observed sign change: nothing to mesh

  auto valueOf = [](uint16_t bits) { return static_cast<float>(Float16::fromBits(bits)); };
  const float voxel_m = map.voxelSize();
  const float max_jump_m = config.max_sdf_jump_voxels * voxel_m;
  const std::array<CubeEdge, 12>& cube_edges = cubeEdges();
  const std::array<uint16_t, 256>& edge_masks = edgeMasks();
  int corner_offset[8];
  for (int i = 0; i < 8; ++i) {
    corner_offset[i] =
        gridIndex(kMcCornerOffset[i][0], kMcCornerOffset[i][1], kMcCornerOffset[i][2]);
  }
  constexpr int kAxisStride[3] = {1, kGrid, kGrid * kGrid};
  const Eigen::Vector3i block_origin = block.index * kBlockSide;

  // Welding within the block: one vertex per grid edge.
  int32_t edge_vertex[kEdgeIds];
  std::fill(edge_vertex, edge_vertex + kEdgeIds, -1);

  for (int z = 0; z < kBlockSide; ++z) {
    for (int y = 0; y < kBlockSide; ++y) {
      // The four rows holding this row of cubes' corners, by corner offset (dy, dz).
      const int rows[2][2] = {{y + kGrid * z, y + kGrid * (z + 1)},
                              {y + 1 + kGrid * z, y + 1 + kGrid * (z + 1)}};
      uint32_t all_observed =
          observed[rows[0][0]] & observed[rows[1][0]] & observed[rows[0][1]] & observed[rows[1][1]];
      uint32_t some_inside =
          inside[rows[0][0]] | inside[rows[1][0]] | inside[rows[0][1]] | inside[rows[1][1]];
      uint32_t all_inside =
          inside[rows[0][0]] & inside[rows[1][0]] & inside[rows[0][1]] & inside[rows[1][1]];
      // Cube x joins voxels x and x + 1 of each row: it is meshed when its 8 corners are
      // observed and not all on one side.
      all_observed &= all_observed >> 1;
      some_inside |= some_inside >> 1;
      all_inside &= all_inside >> 1;
      uint32_t cubes = all_observed & some_inside & ~all_inside & 0xFFu;
      while (cubes) {
        const int x = __builtin_ctz(cubes);
        cubes &= cubes - 1;
        const int g = gridIndex(x, y, z);
        int cube = 0;
        for (int i = 0; i < 8; ++i) {
          const int row = rows[kMcCornerOffset[i][1]][kMcCornerOffset[i][2]];
          cube |= ((inside[row] >> (x + kMcCornerOffset[i][0])) & 1) << i;
        }
        bool ok = true;
        const uint16_t crossed = edge_masks[cube];
        for (int e = 0; e < 12 && ok; ++e) {
          if (!(crossed >> e & 1)) continue;
          const CubeEdge& ce = cube_edges[e];
          ok = std::abs(valueOf(sdf[g + corner_offset[ce.lower_corner]]) -
                        valueOf(sdf[g + corner_offset[ce.upper_corner]])) < max_jump_m;
        }
        if (!ok) continue;

        int32_t cube_vertex[12];
        for (int e = 0; e < 12; ++e) {
          if (!(crossed >> e & 1)) continue;
          const CubeEdge& ce = cube_edges[e];
          const int lx = x + ce.lower[0], ly = y + ce.lower[1], lz = z + ce.lower[2];
          const uint16_t id = blockEdgeId(lx, ly, lz, ce.axis);
          if (edge_vertex[id] < 0) {
            const int ga = gridIndex(lx, ly, lz), gb = ga + kAxisStride[ce.axis];
            const float sa = valueOf(sdf[ga]), sb = valueOf(sdf[gb]);
            const float t = sa / (sa - sb);  // signs differ, so no division by zero
            // Computed from global integers only, so neighbour blocks that mesh the same
            // edge produce bit-identical vertices.
            const int global[3] = {block_origin.x() + lx, block_origin.y() + ly,
                                   block_origin.z() + lz};
            Eigen::Vector3f p;
            for (int k = 0; k < 3; ++k) {
              p[k] = (static_cast<float>(global[k]) + 0.5f + (k == ce.axis ? t : 0.0f)) * voxel_m;
            }
            const int ax = lx + (ce.axis == 0), ay = ly + (ce.axis == 1), az = lz + (ce.axis == 2);
            const Rgb8 ca = neighbours[(lx >> 3) | ((ly >> 3) << 1) | ((lz >> 3) << 2)]
                                ->at(lx & 7, ly & 7, lz & 7)
                                .color;
            const Rgb8 cb = neighbours[(ax >> 3) | ((ay >> 3) << 1) | ((az >> 3) << 2)]
                                ->at(ax & 7, ay & 7, az & 7)
                                .color;
            // Rounds half away from zero, as std::lround, without its library call: the
            // value is >= 0 and the sum exact in double.
            auto mix = [t](uint8_t a, uint8_t b) {
              const float v = a + t * (static_cast<float>(b) - a);
              return static_cast<uint8_t>(static_cast<int>(static_cast<double>(v) + 0.5));
            };
            // The label comes from the voxel whose cell holds the vertex (the nearer one).
            const bool upper = t >= 0.5f;
            const int sx = upper ? ax : lx, sy = upper ? ay : ly, sz = upper ? az : lz;
            const int slot = (sx >> 3) | ((sy >> 3) << 1) | ((sz >> 3) << 2);
            const int local = (sx & 7) + kBlockSide * ((sy & 7) + kBlockSide * (sz & 7));

            edge_vertex[id] = static_cast<int32_t>(mesh->vertices.size());
            mesh->vertices.push_back(p);
            mesh->colors.push_back(Rgb8{mix(ca.r, cb.r), mix(ca.g, cb.g), mix(ca.b, cb.b)});
            mesh->edges.push_back(id);
            mesh->sources.push_back(static_cast<uint16_t>(slot << 9 | local));
          }
          cube_vertex[e] = edge_vertex[id];
        }
        // Bourke's triples wind clockwise seen from outside (sdf > 0): reverse them.
        const int8_t* tri = kMcTriangles[cube];
        for (int k = 0; tri[k] >= 0; k += 3) {
          mesh->faces.emplace_back(cube_vertex[tri[k]], cube_vertex[tri[k + 2]],
                                   cube_vertex[tri[k + 1]]);
        }
      }
    }
  }
}

using internal::VertexLabeller;
using internal::VertexLabels;

namespace {

// Reserves `out`'s arrays for at most `vertices` vertices and exactly `faces` faces: growing
// by doubling would briefly hold 1.5x a building's mesh. Pages reserved and never written
// cost no memory, so the bound may be loose.
void reserveMesh(size_t vertices, size_t faces, bool labelled, LabelledMesh* out) {
  out->vertices.reserve(vertices);
  out->colors.reserve(vertices);
  out->faces.reserve(faces);
  if (labelled) {
    out->superpoint.reserve(vertices);
    out->semantic.reserve(vertices);
    out->instance.reserve(vertices);
  }
}

}  // namespace

LabelledMesh assembleBlockMeshes(const TsdfMap& map, const std::vector<const BlockMesh*>& blocks,
                                 const MeshLabeller& labeller) {
  size_t vertices = 0, faces = 0;
  for (const BlockMesh* mesh : blocks) {
    vertices += mesh->vertices.size();
    faces += mesh->faces.size();
  }
  LabelledMesh out;
  reserveMesh(vertices, faces, static_cast<bool>(labeller.superpoint), &out);
  MeshWelder welder(map, labeller, &out);
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (b + 1 < blocks.size()) welder.prefetch(*blocks[b + 1]);
    welder.add(*blocks[b]);
  }
  return out;
}

BlockMeshLabeller::BlockMeshLabeller(const TsdfMap& map, const MeshLabeller& labeller)
    : vertex_(labeller.superpoint ? std::make_unique<VertexLabeller>(map, labeller) : nullptr) {}

BlockMeshLabeller::~BlockMeshLabeller() = default;

LabelledMesh BlockMeshLabeller::label(const BlockMesh& mesh) {
  BlockLabels labelled = labels(mesh);
  LabelledMesh out;
  out.vertices = mesh.vertices;
  out.colors = mesh.colors;
  out.faces = mesh.faces;
  out.superpoint = std::move(labelled.superpoint);
  out.semantic = std::move(labelled.semantic);
  out.instance = std::move(labelled.instance);
  return out;
}

BlockLabels BlockMeshLabeller::labels(const BlockMesh& mesh) {
  BlockLabels out;
  if (!vertex_) return out;
  // As MeshWelder::add: the vote slots and sets, which marching cubes did not read, are
  // fetched for the whole block before any label waits on them.
  vertex_->setBlock(mesh.index);
  for (uint16_t source : mesh.sources) vertex_->prefetchSlot(source);
  const size_t n = mesh.vertices.size();
  out.superpoint.resize(n);
  out.semantic.resize(n);
  out.instance.resize(n);
  for (uint16_t source : mesh.sources) vertex_->prefetchVotes(source);
  for (size_t i = 0; i < n; ++i) {
    const VertexLabels labels = (*vertex_)(mesh.sources[i]);
    out.superpoint[i] = labels.superpoint;
    out.semantic[i] = labels.semantic;
    out.instance[i] = labels.instance;
  }
  return out;
}

LabelledMesh labelBlockMesh(const TsdfMap& map, const BlockMesh& mesh,
                            const MeshLabeller& labeller) {
  return BlockMeshLabeller(map, labeller).label(mesh);
}

LabelledMesh marchingCubes(const TsdfMap& map, const MarchingCubesConfig& config,
                           const MeshLabeller& labeller, ThreadPool* pool) {
  config.check();
  std::vector<const Block*> sorted;
  sorted.reserve(map.numBlocks());
  for (const auto& block : map.blocks()) sorted.push_back(block.get());
  std::sort(sorted.begin(), sorted.end(),
            [](const Block* a, const Block* b) { return blockIndexLess(a->index, b->index); });
  const int threads = pool ? pool->size() : 1;
  auto forEach = [&](size_t n, const std::function<void(size_t, size_t, int)>& fn) {
    // A few blocks at a time: blocks without surface cost a fraction of those with.
    if (pool && n > 1) {
      pool->parallelForDynamic(n, 16, fn);
    } else {
      fn(0, n, 0);
    }
  };
  // Pass 1 only counts, so that the mesh is reserved once and no block mesh is kept: a
  // building's block meshes are as large as its welded mesh (2 cm: 0.3 GB each). Marching
  // cubes twice costs less than holding both.
  std::vector<BlockMesh> scratch(threads);
  std::vector<uint8_t> has_surface(sorted.size(), 0);
  std::vector<size_t> vertices(threads, 0), faces(threads, 0);
  forEach(sorted.size(), [&](size_t begin, size_t end, int thread) {
    BlockMesh* mesh = &scratch[thread];
    meshBlocks(
        map, sorted.data() + begin, end - begin, config, [mesh](size_t) { return mesh; },
        [&, mesh, begin, thread](size_t i) {
          vertices[thread] += mesh->vertices.size();
          faces[thread] += mesh->faces.size();
          has_surface[begin + i] = !mesh->vertices.empty();
        });
  });
  std::vector<const Block*> surface;
  for (size_t i = 0; i < sorted.size(); ++i) {
    if (has_surface[i]) surface.push_back(sorted[i]);
  }
  sorted = std::vector<const Block*>();
  LabelledMesh out;
  reserveMesh(std::accumulate(vertices.begin(), vertices.end(), size_t{0}),
              std::accumulate(faces.begin(), faces.end(), size_t{0}),
              static_cast<bool>(labeller.superpoint), &out);
  // Pass 2: a batch of blocks meshed on every thread, then welded in order on this one.
  constexpr size_t kBatch = 1024;
  std::vector<BlockMesh> batch(std::min(kBatch, surface.size()));
  MeshWelder welder(map, labeller, &out);
  for (size_t first = 0; first < surface.size(); first += kBatch) {
    const size_t n = std::min(kBatch, surface.size() - first);
    forEach(n, [&](size_t begin, size_t end, int) {
      meshBlocks(map, surface.data() + first + begin, end - begin, config,
                 [&batch, begin](size_t i) { return &batch[begin + i]; });
    });
    for (size_t i = 0; i < n; ++i) {
      if (i + 1 < n) welder.prefetch(batch[i + 1]);
      welder.add(batch[i]);
    }
  }
  return out;
}

}  // namespace panmap
