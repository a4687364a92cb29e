#include "panmap/mesh/marching_cubes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>

#include <absl/container/flat_hash_map.h>

#include "panmap/core/error.h"
#include "panmap/mesh/internal/marching_cubes_tables.h"

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

void meshBlock(const TsdfMap& map, const Block& block, const MarchingCubesConfig& config,
               BlockMesh* mesh) {
  mesh->clear();
  mesh->index = block.index;

  // One hash look-up per neighbour block, none per voxel.
  const Block* neighbours[8];
  neighbours[0] = &block;
  for (int slot = 1; slot < 8; ++slot) {
    neighbours[slot] = map.findBlock(block.index + slotOffset(slot));
  }

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

namespace {

// A grid edge anywhere in the map: its lower voxel's block and its id within that block.
using EdgeKey = std::pair<uint64_t, uint16_t>;

struct VertexLabels {
  int32_t superpoint = 0, semantic = 0, instance = 0;
};

}  // namespace

namespace internal {

// Labels vertices from their source voxels through a MeshLabeller, one block's vertices at a
// time (setBlock). The labels of the voxels around the block are computed once each and kept
// (a vertex without a label reads its 26 neighbours, which the next vertices mostly share),
// and so are the last vertex's labels: neighbouring vertices mostly share their voxel, and
// neighbouring voxels their super-point. The map must not change while it is in use.
class VertexLabeller {
 public:
  VertexLabeller(const TsdfMap& map, const MeshLabeller& labeller)
      : map_(map), labeller_(labeller), region_(kRegionVoxels) {}

  /// Makes `index` the block whose cubes made the next vertices.
  void setBlock(const BlockIndex& index) {
    index_ = index;
    fetched_ = 0;
    if (++stamp_ == 0) {  // wrapped: forget every entry explicitly once
      for (Entry& e : region_) e.stamp = e.fill_stamp = 0;
      stamp_ = 1;
    }
    last_voxel_ = nullptr;
  }

  /// @param source a BlockMesh source of the block last given to setBlock()
  VertexLabels operator()(uint16_t source) {
    const int slot = source >> 9, local = source & 511;
    const int x = (slot & 1) * kBlockSide + (local & 7);
    const int y = ((slot >> 1) & 1) * kBlockSide + ((local >> 3) & 7);
    const int z = (slot >> 2) * kBlockSide + (local >> 6);
    const Block* owner = blockAt(x, y, z);
    if (!owner) return VertexLabels{};
    const Voxel* voxel = &owner->voxels[local];
    if (voxel == last_voxel_) return last_;
    last_voxel_ = voxel;
    const int r = regionIndex(x, y, z);
    const int32_t superpoint = entry(r, x, y, z).label;
    // A filled vertex takes its class and instance from the neighbours' super-point but keeps
    // super-point 0: it belongs to none (super-point diagnostics measure them as voted).
    int32_t source_label = superpoint;
    if (superpoint == 0 && labeller_.fill_from_neighbours) source_label = filledLabel(r, x, y, z);
    if (have_last_ && superpoint == last_.superpoint && source_label == last_source_) {
      return last_;
    }
    have_last_ = true;
    last_source_ = source_label;
    last_.superpoint = superpoint;
    last_.semantic = labeller_.semantic ? labeller_.semantic(source_label) : 0;
    last_.instance = labeller_.instance ? labeller_.instance(source_label) : 0;
    return last_;
  }

 private:
  // The region holds the voxels at block-local coordinates -1 .. 9: sources lie in 0 .. 8.
  static constexpr int kRegionSide = kBlockSide + 3;
  static constexpr int kRegionVoxels = kRegionSide * kRegionSide * kRegionSide;

  struct Entry {
    uint32_t stamp = 0;       // valid when equal to stamp_
    int32_t label = 0;        // super-point, 0 for none or no block
    uint64_t votes = 0;       // all votes of the voxel
    uint32_t fill_stamp = 0;  // `fill` valid when equal to stamp_
    int32_t fill = 0;         // neighbourhoodLabel() of the voxel
  };

  static int regionIndex(int x, int y, int z) {
    return (x + 1) + kRegionSide * ((y + 1) + kRegionSide * (z + 1));
  }

  // The block holding block-local (x, y, z), looked up once per setBlock() (most vertices
  // need only a few of the 27). Arithmetic shifts: -1 >> 3 is -1, so -1 .. 9 map to -1 .. 1.
  const Block* blockAt(int x, int y, int z) {
    const int dx = x >> 3, dy = y >> 3, dz = z >> 3;
    const int slot = (dx + 1) + 3 * ((dy + 1) + 3 * (dz + 1));
    if (!(fetched_ >> slot & 1u)) {
      blocks_[slot] = map_.findBlock(index_ + BlockIndex(dx, dy, dz));
      fetched_ |= 1u << slot;
    }
    return blocks_[slot];
  }

  // The labels of the voxel at block-local (x, y, z), region index r.
  const Entry& entry(int r, int x, int y, int z) {
    Entry& e = region_[r];
    if (e.stamp == stamp_) return e;
    e.stamp = stamp_;
    e.label = 0;
    e.votes = 0;
    const Block* b = blockAt(x, y, z);
    if (!b) return e;
    const VoxelVotes* votes = b->votes(Block::linear(x & 7, y & 7, z & 7));
    if (!votes) return e;
    e.votes = votes->total();
    // Voxels without a vote have label 0 without asking.
    if (e.votes > 0) e.label = labeller_.superpoint(*votes);
    return e;
  }

  // neighbourhoodLabel() of the voxel at block-local (x, y, z), region index r, computed once
  // per block: the up to 6 vertices (one per grid edge at the voxel) that take their label from
  // a voxel rarely come one after another.
  int32_t filledLabel(int r, int x, int y, int z) {
    Entry& e = region_[r];
    if (e.fill_stamp != stamp_) {
      e.fill = neighbourhoodLabel(x, y, z);
      e.fill_stamp = stamp_;
    }
    return e.fill;
  }

  // The label most of the 26 neighbours of the voxel at block-local (x, y, z) carry (ties:
  // more votes, then the smaller label); 0 when none carries one.
  int32_t neighbourhoodLabel(int x, int y, int z) {
    struct Tally {
      int32_t label;
      int voxels;
      uint64_t votes;
    };
    Tally tally[26];
    int n = 0;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const int nx = x + dx, ny = y + dy, nz = z + dz;
          const Entry& e = entry(regionIndex(nx, ny, nz), nx, ny, nz);
          if (e.label == 0) continue;
          int k = 0;
          while (k < n && tally[k].label != e.label) ++k;
          if (k == n) tally[n++] = Tally{e.label, 0, 0};
          ++tally[k].voxels;
          tally[k].votes += e.votes;
        }
      }
    }
    int32_t best = 0;
    int best_voxels = 0;
    uint64_t best_votes = 0;
    for (int k = 0; k < n; ++k) {
      const Tally& t = tally[k];
      if (t.voxels > best_voxels || (t.voxels == best_voxels && t.votes > best_votes) ||
          (t.voxels == best_voxels && t.votes == best_votes && t.label < best)) {
        best = t.label, best_voxels = t.voxels, best_votes = t.votes;
      }
    }
    return best;
  }

  const TsdfMap& map_;
  const MeshLabeller& labeller_;
  BlockIndex index_ = BlockIndex::Zero();  // the block of setBlock()
  const Block* blocks_[27] = {};           // it and its 26 neighbours, where fetched_ says
  uint32_t fetched_ = 0;
  std::vector<Entry> region_;
  uint32_t stamp_ = 0;
  const Voxel* last_voxel_ = nullptr;
  bool have_last_ = false;
  int32_t last_source_ = 0;  // the label last_'s class and instance come from
  VertexLabels last_;
};

}  // namespace internal

using internal::VertexLabeller;

LabelledMesh assembleBlockMeshes(const TsdfMap& map, const std::vector<const BlockMesh*>& blocks,
                                 const MeshLabeller& labeller) {
  LabelledMesh out;
  const bool labelled = static_cast<bool>(labeller.superpoint);
  std::vector<size_t> offsets(blocks.size() + 1, 0);
  size_t num_faces = 0, num_border = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    offsets[b + 1] = offsets[b] + blocks[b]->vertices.size();
    num_faces += blocks[b]->faces.size();
  }
  std::vector<int32_t> global(offsets.back(), -1);
  out.vertices.reserve(offsets.back());
  out.colors.reserve(offsets.back());
  out.faces.reserve(num_faces);
  if (labelled) {
    // Reserved like the positions: growing by doubling would briefly hold 1.5x a building's
    // labels on top of the rest of the mesh.
    out.superpoint.reserve(offsets.back());
    out.semantic.reserve(offsets.back());
    out.instance.reserve(offsets.back());
  }

  VertexLabeller label_vertex(map, labeller);
  auto findNeighbours = [&](const BlockIndex& index) {
    if (labelled) label_vertex.setBlock(index);
  };
  auto emit = [&](const BlockMesh& mesh, size_t i) {
    const int32_t index = static_cast<int32_t>(out.vertices.size());
    out.vertices.push_back(mesh.vertices[i]);
    out.colors.push_back(mesh.colors[i]);
    if (labelled) {
      const VertexLabels labels = label_vertex(mesh.sources[i]);
      out.superpoint.push_back(labels.superpoint);
      out.semantic.push_back(labels.semantic);
      out.instance.push_back(labels.instance);
    }
    return index;
  };
  auto decode = [](uint16_t id, int* x, int* y, int* z) {
    const int cell = id / 3;
    *x = cell % kGrid;
    *y = (cell / kGrid) % kGrid;
    *z = cell / (kGrid * kGrid);
  };

  // Pass 1: every block's own vertices (lower voxel inside the block), in block order. Those
  // on the block's lower faces may be shared with a lower neighbour's border vertices.
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (uint16_t id : blocks[b]->edges) {
      int x, y, z;
      decode(id, &x, &y, &z);
      num_border +=
          (x == 0 || y == 0 || z == 0 || x == kBlockSide || y == kBlockSide || z == kBlockSide);
    }
  }
  absl::flat_hash_map<EdgeKey, int32_t> border;
  border.reserve(num_border);
  for (size_t b = 0; b < blocks.size(); ++b) {
    const BlockMesh& mesh = *blocks[b];
    findNeighbours(mesh.index);
    const uint64_t key = TsdfMap::key(mesh.index);
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      int x, y, z;
      decode(mesh.edges[i], &x, &y, &z);
      if (x == kBlockSide || y == kBlockSide || z == kBlockSide) continue;
      global[offsets[b] + i] = emit(mesh, i);
      if (x == 0 || y == 0 || z == 0)
        border.emplace(EdgeKey(key, mesh.edges[i]), global[offsets[b] + i]);
    }
  }
  // Pass 2: border vertices owned by an upper neighbour: weld with the owner's vertex, or
  // with the first lower block that produced it when the owner's cubes did not.
  for (size_t b = 0; b < blocks.size(); ++b) {
    const BlockMesh& mesh = *blocks[b];
    bool have_neighbours = false;
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      int x, y, z;
      decode(mesh.edges[i], &x, &y, &z);
      if (x < kBlockSide && y < kBlockSide && z < kBlockSide) continue;
      const BlockIndex owner = mesh.index + BlockIndex(x >> 3, y >> 3, z >> 3);
      const EdgeKey key(TsdfMap::key(owner), blockEdgeId(x & 7, y & 7, z & 7, mesh.edges[i] % 3));
      auto [it, inserted] = border.try_emplace(key, -1);
      if (inserted) {
        if (!have_neighbours) {
          findNeighbours(mesh.index);
          have_neighbours = true;
        }
        it->second = emit(mesh, i);
      }
      global[offsets[b] + i] = it->second;
    }
  }
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int32_t* map_to = global.data() + offsets[b];
    for (const Eigen::Vector3i& f : blocks[b]->faces) {
      out.faces.emplace_back(map_to[f[0]], map_to[f[1]], map_to[f[2]]);
    }
  }
  return out;
}

BlockMeshLabeller::BlockMeshLabeller(const TsdfMap& map, const MeshLabeller& labeller)
    : vertex_(labeller.superpoint ? std::make_unique<VertexLabeller>(map, labeller) : nullptr) {}

BlockMeshLabeller::~BlockMeshLabeller() = default;

LabelledMesh BlockMeshLabeller::label(const BlockMesh& mesh) {
  LabelledMesh out;
  out.vertices = mesh.vertices;
  out.colors = mesh.colors;
  out.faces = mesh.faces;
  if (!vertex_) return out;
  vertex_->setBlock(mesh.index);
  const size_t n = mesh.vertices.size();
  out.superpoint.resize(n);
  out.semantic.resize(n);
  out.instance.resize(n);
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
                           const MeshLabeller& labeller) {
  config.check();
  std::vector<const Block*> sorted;
  sorted.reserve(map.numBlocks());
  for (const auto& block : map.blocks()) sorted.push_back(block.get());
  std::sort(sorted.begin(), sorted.end(),
            [](const Block* a, const Block* b) { return blockIndexLess(a->index, b->index); });
  std::vector<BlockMesh> meshes(sorted.size());
  std::vector<const BlockMesh*> pointers;
  pointers.reserve(sorted.size());
  for (size_t i = 0; i < sorted.size(); ++i) {
    meshBlock(map, *sorted[i], config, &meshes[i]);
    if (!meshes[i].vertices.empty()) pointers.push_back(&meshes[i]);
  }
  return assembleBlockMeshes(map, pointers, labeller);
}

}  // namespace panmap
