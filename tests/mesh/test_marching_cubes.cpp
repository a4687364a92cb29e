#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "panmap/core/error.h"
#include "panmap/core/thread_pool.h"
#include "panmap/io/ply.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/mesh/incremental_mesher.h"
#include "panmap/mesh/internal/marching_cubes_tables.h"
#include "panmap/mesh/marching_cubes.h"
#include "panmap/mesh/mesh_export.h"
#include "panmap/mesh/mesh_welder.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using SdfFunction = std::function<float(const Eigen::Vector3f&)>;

/// Global integer coordinates of a voxel.
Eigen::Vector3i globalVoxel(const BlockIndex& block, int x, int y, int z) {
  return block * kBlockSide + Eigen::Vector3i(x, y, z);
}

/// A colour that varies linearly with the voxel's global coordinates (kept within 0..255).
Rgb8 voxelColor(const Eigen::Vector3i& g) {
  return Rgb8{static_cast<uint8_t>(100 + 2 * (g.x() % 50)), static_cast<uint8_t>(g.y() & 0xFF),
              static_cast<uint8_t>(200 - (g.z() % 100))};
}

/// A super-point label per voxel that changes often, so nearer-voxel errors show.
int32_t voxelLabel(const Eigen::Vector3i& g) {
  const Eigen::Matrix<uint32_t, 3, 1> u = g.cast<uint32_t>();
  const uint32_t h = u.x() * 73856093u ^ u.y() * 19349663u ^ u.z() * 83492791u;
  return 1 + static_cast<int32_t>(h % 7);
}

/// Writes an analytic signed distance (+ outside) into every voxel of the boxes of blocks
/// [lo, hi] within `band_m` of the surface: weight 1, colour and a vote from the voxel's
/// coordinates. Voxels farther away stay unobserved.
void fillMap(TsdfMap* map, const Eigen::Vector3f& lo_m, const Eigen::Vector3f& hi_m, float band_m,
             const SdfFunction& sdf) {
  const BlockIndex lo = map->blockIndexOf(lo_m), hi = map->blockIndexOf(hi_m);
  for (int bz = lo.z(); bz <= hi.z(); ++bz) {
    for (int by = lo.y(); by <= hi.y(); ++by) {
      for (int bx = lo.x(); bx <= hi.x(); ++bx) {
        Block* block = map->allocateBlock(BlockIndex(bx, by, bz));
        for (int z = 0; z < kBlockSide; ++z) {
          for (int y = 0; y < kBlockSide; ++y) {
            for (int x = 0; x < kBlockSide; ++x) {
              const float d = sdf(map->voxelCentre(block->index, x, y, z));
              if (std::abs(d) > band_m) continue;
              Voxel& v = block->at(x, y, z);
              v.sdf_m = d;
              v.weight = 1.0f;
              const Eigen::Vector3i g = globalVoxel(block->index, x, y, z);
              v.color = voxelColor(g);
              block->votesToWrite(Block::linear(x, y, z))->slots[0] = LabelVote{voxelLabel(g), 3};
            }
          }
        }
        block->updated = true;
      }
    }
  }
}

const Eigen::Vector3f kCentre(0.0123f, -0.0071f, 0.0042f);  // off the voxel grid
constexpr float kRadius = 0.3f;

float sphereSdf(const Eigen::Vector3f& p) { return (p - kCentre).norm() - kRadius; }

void fillSphere(TsdfMap* map, float radius = kRadius) {
  const float band = 3.0f * map->voxelSize();
  const Eigen::Vector3f r = Eigen::Vector3f::Constant(radius + band);
  fillMap(map, kCentre - r, kCentre + r, band,
          [radius](const Eigen::Vector3f& p) { return (p - kCentre).norm() - radius; });
}

/// Undirected edge -> number of faces using it, and directed edge -> count.
struct EdgeCounts {
  std::map<std::pair<int, int>, int> undirected;
  std::map<std::pair<int, int>, int> directed;
};

EdgeCounts countEdges(const LabelledMesh& mesh) {
  EdgeCounts counts;
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      ++counts.undirected[{std::min(a, b), std::max(a, b)}];
      ++counts.directed[{a, b}];
    }
  }
  return counts;
}

double meshArea(const LabelledMesh& mesh) {
  double area = 0.0;
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[f[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[f[2]].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

Eigen::Vector3f faceNormal(const LabelledMesh& mesh, const Eigen::Vector3i& f) {
  return (mesh.vertices[f[1]] - mesh.vertices[f[0]])
      .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
}

/// Asserts a closed, consistently oriented 2-manifold: every edge in exactly two faces, once
/// in each direction, no face repeating a vertex.
void expectWatertight(const LabelledMesh& mesh) {
  const EdgeCounts counts = countEdges(mesh);
  size_t bad = 0;
  for (const auto& [edge, n] : counts.undirected) bad += n != 2;
  EXPECT_EQ(bad, 0u) << "edges not shared by exactly two faces";
  size_t flipped = 0;
  for (const auto& [edge, n] : counts.directed) flipped += n != 1;
  EXPECT_EQ(flipped, 0u) << "directed edges used twice: inconsistent winding";
  for (const Eigen::Vector3i& f : mesh.faces) {
    ASSERT_TRUE(f[0] != f[1] && f[1] != f[2] && f[0] != f[2]);
  }
}

void expectSameMesh(const LabelledMesh& a, const LabelledMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.faces.size(), b.faces.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) {
    ASSERT_EQ(a.vertices[i], b.vertices[i]) << "vertex " << i;
    ASSERT_EQ(a.colors[i], b.colors[i]) << "vertex " << i;
  }
  for (size_t i = 0; i < a.faces.size(); ++i) ASSERT_EQ(a.faces[i], b.faces[i]) << "face " << i;
  EXPECT_EQ(a.superpoint, b.superpoint);
  EXPECT_EQ(a.semantic, b.semantic);
  EXPECT_EQ(a.instance, b.instance);
}

MeshLabeller identityLabeller() {
  MeshLabeller labeller;
  labeller.superpoint = [](const VoxelVotes& v) {
    return argmaxLabel(v, [](int32_t l) { return l; });
  };
  labeller.semantic = [](int32_t sp) { return sp == 0 ? 0 : sp + 2; };
  labeller.instance = [](int32_t sp) { return sp == 0 ? 0 : 1000 + sp; };
  return labeller;
}

// ---- MarchingCubes ---------------------------------------------------------------------

TEST(MarchingCubes, TablesUseExactlyTheCrossedEdges) {
  for (int c = 0; c < 256; ++c) {
    std::set<int> crossed, used;
    for (int e = 0; e < 12; ++e) {
      const int a = internal::kMcEdgeCorners[e][0], b = internal::kMcEdgeCorners[e][1];
      if (((c >> a) ^ (c >> b)) & 1) crossed.insert(e);
    }
    int n = 0;
    while (n < 16 && internal::kMcTriangles[c][n] >= 0) used.insert(internal::kMcTriangles[c][n++]);
    EXPECT_EQ(n % 3, 0) << "case " << c;
    EXPECT_LE(n, 15) << "case " << c;
    EXPECT_EQ(used, crossed) << "case " << c;
  }
}

class MarchingCubesSphere : public ::testing::TestWithParam<float> {};

TEST_P(MarchingCubesSphere, IsWatertightAccurateAndFacesOutward) {
  const float voxel = GetParam();
  TsdfMap map(TsdfMap::Config{voxel});
  fillSphere(&map);
  const LabelledMesh mesh = marchingCubes(map);
  ASSERT_EQ(mesh.check(), "");
  ASSERT_GT(mesh.numFaces(), 1000u);
  expectWatertight(mesh);
  // A sphere: V - E + F = 2 (one closed component of genus 0).
  const long edges = static_cast<long>(countEdges(mesh).undirected.size());
  EXPECT_EQ(static_cast<long>(mesh.numVertices()) - edges + static_cast<long>(mesh.numFaces()), 2);

  const double truth = 4.0 * M_PI * kRadius * kRadius;
  EXPECT_NEAR(meshArea(mesh), truth, 0.02 * truth);
  for (const Eigen::Vector3f& p : mesh.vertices) {
    ASSERT_LT(std::abs(sphereSdf(p)), 0.5f * voxel);
  }
  size_t inward = 0;
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3f n = faceNormal(mesh, f);
    if (n.norm() < 1e-12f) continue;  // degenerate sliver
    const Eigen::Vector3f centroid =
        (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / 3.0f;
    inward += n.dot(centroid - kCentre) <= 0.0f;
  }
  EXPECT_EQ(inward, 0u);
}

INSTANTIATE_TEST_SUITE_P(VoxelSizes, MarchingCubesSphere, ::testing::Values(0.01f, 0.02f));

// A plane tilted against every axis through 2 x 2 x 1 blocks of 1 cm voxels.
const Eigen::Vector3f kPlaneNormal = Eigen::Vector3f(0.2f, 0.3f, 1.0f).normalized();
const Eigen::Vector3f kPlanePoint(0.08f, 0.08f, 0.041f);
float planeSdf(const Eigen::Vector3f& p) { return kPlaneNormal.dot(p - kPlanePoint); }

void fillPlane(TsdfMap* map) {
  fillMap(map, Eigen::Vector3f(0.001f, 0.001f, -0.079f), Eigen::Vector3f(0.159f, 0.159f, 0.159f),
          3.0f * map->voxelSize(), planeSdf);
}

TEST(MarchingCubes, PlaneIsExactAndOpenOnlyAtTheObservedBorder) {
  TsdfMap map(TsdfMap::Config{0.01f});
  fillPlane(&map);
  const LabelledMesh mesh = marchingCubes(map);
  ASSERT_EQ(mesh.check(), "");
  // Linear interpolation of a linear field is exact.
  for (const Eigen::Vector3f& p : mesh.vertices) ASSERT_NEAR(planeSdf(p), 0.0f, 2e-6f);
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3f n = faceNormal(mesh, f);
    if (n.norm() < 1e-10f) continue;
    ASSERT_GT(n.normalized().dot(kPlaneNormal), 0.9999f);
  }
  // Cubes span voxel centres 0.5 cm .. 15.5 cm in x and y; the plane stays inside in z.
  const double side = 0.15;
  EXPECT_NEAR(meshArea(mesh), side * side / kPlaneNormal.z(), 1e-6);
  const EdgeCounts counts = countEdges(mesh);
  size_t border = 0;
  for (const auto& [edge, n] : counts.undirected) {
    ASSERT_LE(n, 2);
    if (n == 1) {
      ++border;
      // Only the outline of the observed square is open.
      const Eigen::Vector3f mid = 0.5f * (mesh.vertices[edge.first] + mesh.vertices[edge.second]);
      const float margin =
          std::min({mid.x() - 0.005f, 0.155f - mid.x(), mid.y() - 0.005f, 0.155f - mid.y()});
      EXPECT_LT(margin, 1e-5f);
    }
  }
  EXPECT_GT(border, 0u);
}

/// Lower-corner voxel of the cube a face lies in (its centroid is inside the cube).
Eigen::Vector3i cubeOfFace(const LabelledMesh& mesh, const Eigen::Vector3i& f, float voxel) {
  const Eigen::Vector3f c =
      (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / 3.0f;
  return (c / voxel - Eigen::Vector3f::Constant(0.5f)).array().floor().cast<int>();
}

TEST(MarchingCubes, NoFacesInCubesWithAnUnobservedCorner) {
  TsdfMap map(TsdfMap::Config{0.01f});
  fillPlane(&map);
  const LabelledMesh full = marchingCubes(map);
  // Forget the voxel nearest to a point on the plane, inside block (0, 0, 0)'s border so
  // cubes of several blocks touch it.
  const Eigen::Vector3i gap(7, 7, 3);
  Voxel& voxel = map.findBlock(BlockIndex(0, 0, 0))->at(7, 7, 3);
  ASSERT_LT(std::abs(voxel.sdf_m), 0.01f);
  voxel.weight = 0.0f;
  const LabelledMesh holed = marchingCubes(map);

  auto touchesGap = [&](const Eigen::Vector3i& cube) {
    return ((gap - cube).array() >= 0).all() && ((gap - cube).array() <= 1).all();
  };
  size_t full_touching = 0;
  for (const Eigen::Vector3i& f : full.faces)
    full_touching += touchesGap(cubeOfFace(full, f, 0.01f));
  ASSERT_GT(full_touching, 0u);
  for (const Eigen::Vector3i& f : holed.faces) {
    ASSERT_FALSE(touchesGap(cubeOfFace(holed, f, 0.01f)));
  }
  EXPECT_EQ(holed.numFaces(), full.numFaces() - full_touching);
}

/// 2 x 2 x 2 blocks, every voxel observed: `outside_m` for x < 8, `inside_m` (< 0) beyond.
LabelledMesh meshStep(float outside_m, float inside_m, float weight, float min_weight) {
  TsdfMap map(TsdfMap::Config{0.01f});
  for (int b = 0; b < 8; ++b) {
    Block* block = map.allocateBlock(BlockIndex(b & 1, (b >> 1) & 1, b >> 2));
    for (int i = 0; i < kBlockVoxels; ++i) {
      block->voxels[i].sdf_m = block->index.x() == 0 ? outside_m : inside_m;
      block->voxels[i].weight = weight;
    }
  }
  MarchingCubesConfig config;
  config.min_weight = min_weight;
  return marchingCubes(map, config);
}

TEST(MarchingCubes, SignChangeOnlyWhenTheJumpIsBelowTheLimit) {
  // A wall between x = 7 and x = 8: 15 x 15 cubes, 2 triangles each.
  const float v = 0.01f;
  EXPECT_EQ(meshStep(3.4f * v, -0.5f * v, 1.0f, 0.0f).numFaces(), 450u);
  // A sample clamped at the truncation (4 voxels) next to a negative one: no surface.
  EXPECT_EQ(meshStep(4.0f * v, -0.5f * v, 1.0f, 0.0f).numFaces(), 0u);
  EXPECT_EQ(meshStep(0.5f * v, -4.0f * v, 1.0f, 0.0f).numFaces(), 0u);
  // Weights at or under min_weight count as unobserved.
  EXPECT_EQ(meshStep(0.5f * v, -0.5f * v, 1.0f, 1.0f).numFaces(), 0u);
  EXPECT_EQ(meshStep(0.5f * v, -0.5f * v, 1.5f, 1.0f).numFaces(), 450u);
  // Weights are 2-byte floats, compared by their bits: 0.3 is stored as 0.30004883, above 0.3
  // and not above itself or 0.3001. Likewise a distance of -0 is not inside.
  const float stored = Float16(0.3f);
  ASSERT_GT(stored, 0.3f);
  EXPECT_EQ(meshStep(0.5f * v, -0.5f * v, 0.3f, 0.3f).numFaces(), 450u);
  EXPECT_EQ(meshStep(0.5f * v, -0.5f * v, 0.3f, stored).numFaces(), 0u);
  EXPECT_EQ(meshStep(0.5f * v, -0.5f * v, 0.3f, 0.3001f).numFaces(), 0u);
  EXPECT_EQ(meshStep(0.5f * v, -0.5f * v, 0.3f, 0.2999f).numFaces(), 450u);
  EXPECT_EQ(meshStep(0.5f * v, -0.0f, 1.0f, 0.0f).numFaces(), 0u);
  EXPECT_EQ(meshStep(0.5f * v, -1e-6f, 1.0f, 0.0f).numFaces(), 450u);  // a subnormal
}

TEST(MarchingCubes, RandomFieldGivesAClosedConsistentSurface) {
  // Random signs everywhere (all 256 cases and their ambiguous faces occur), positive on the
  // border so the surface is closed: the tables must not leave cracks between cubes.
  TsdfMap map(TsdfMap::Config{0.01f});
  uint64_t state = 12345;
  auto next = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>((state >> 33) % 1000) / 1000.0f;
  };
  for (int b = 0; b < 27; ++b) {
    Block* block = map.allocateBlock(BlockIndex(b % 3, (b / 3) % 3, b / 9));
    for (int z = 0; z < kBlockSide; ++z) {
      for (int y = 0; y < kBlockSide; ++y) {
        for (int x = 0; x < kBlockSide; ++x) {
          const Eigen::Vector3i g = globalVoxel(block->index, x, y, z);
          const bool border = (g.array() == 0).any() || (g.array() == 23).any();
          Voxel& v = block->at(x, y, z);
          v.sdf_m = border ? 0.004f : 0.01f * (next() - 0.5f) + 1e-4f;
          v.weight = 1.0f;
        }
      }
    }
  }
  const LabelledMesh mesh = marchingCubes(map);
  ASSERT_GT(mesh.numFaces(), 10000u);
  expectWatertight(mesh);
}

TEST(MarchingCubes, BlockGridHoldsTheUpperNeighboursBySlotAndNullWhereNone) {
  TsdfMap map(TsdfMap::Config{0.01f});
  const BlockIndex origin(4, -2, 7);
  Block* block = map.allocateBlock(origin);
  // Slots 1 (+x), 3 (+x +y) and 6 (+y +z) exist; 2, 4, 5 and 7 do not.
  const Block* plus_x = map.allocateBlock(origin + BlockIndex(1, 0, 0));
  const Block* plus_xy = map.allocateBlock(origin + BlockIndex(1, 1, 0));
  const Block* plus_yz = map.allocateBlock(origin + BlockIndex(0, 1, 1));
  map.allocateBlock(origin - BlockIndex(1, 0, 0));  // a lower neighbour is not in the grid
  const BlockGrid grid = blockGrid(map, *block);
  const Block* expected[8] = {block, plus_x, nullptr, plus_xy, nullptr, nullptr, plus_yz, nullptr};
  for (int slot = 0; slot < 8; ++slot) EXPECT_EQ(expected[slot], grid.blocks[slot]) << slot;
  prefetchBlockGrid(grid);  // reads nothing it may not: missing neighbours are skipped
}

TEST(MarchingCubes, MeshBlocksMeshesEachIntoItsTargetAndReportsEachInOrder) {
  TsdfMap map(TsdfMap::Config{0.003f});
  fillSphere(&map);
  std::vector<const Block*> blocks;
  for (const auto& block : map.blocks()) blocks.push_back(block.get());
  ASSERT_GT(blocks.size(), 100u);
  std::vector<BlockMesh> meshes(blocks.size());
  std::vector<size_t> done;
  meshBlocks(
      map, blocks.data(), blocks.size(), MarchingCubesConfig(),
      [&meshes](size_t i) { return &meshes[i]; },
      [&](size_t i) {
        // Called right after block i is meshed, before block i + 1.
        EXPECT_EQ(meshes[i].index, blocks[i]->index);
        if (i + 1 < meshes.size()) EXPECT_TRUE(meshes[i + 1].vertices.empty());
        done.push_back(i);
      });
  ASSERT_EQ(done.size(), blocks.size());
  size_t with_surface = 0;
  for (size_t i = 0; i < blocks.size(); ++i) {
    EXPECT_EQ(done[i], i);
    BlockMesh one;
    meshBlock(map, *blocks[i], MarchingCubesConfig(), &one);
    EXPECT_EQ(one.vertices, meshes[i].vertices);
    EXPECT_EQ(one.faces, meshes[i].faces);
    with_surface += !one.vertices.empty();
  }
  EXPECT_GT(with_surface, 100u);
  meshBlocks(map, blocks.data(), 0, MarchingCubesConfig(), [](size_t) -> BlockMesh* {
    ADD_FAILURE() << "no block to mesh";
    return nullptr;
  });
}

// Every block's own mesh, in blockIndexLess order, those with surface only.
std::vector<BlockMesh> sortedBlockMeshes(const TsdfMap& map) {
  std::vector<const Block*> blocks;
  for (const auto& block : map.blocks()) blocks.push_back(block.get());
  std::sort(blocks.begin(), blocks.end(),
            [](const Block* a, const Block* b) { return blockIndexLess(a->index, b->index); });
  std::vector<BlockMesh> meshes;
  for (const Block* block : blocks) {
    BlockMesh mesh;
    meshBlock(map, *block, MarchingCubesConfig(), &mesh);
    // Meshing from a grid looked up beforehand (as IncrementalMesher does) is the same.
    BlockMesh from_grid;
    meshBlock(map, blockGrid(map, *block), MarchingCubesConfig(), &from_grid);
    EXPECT_EQ(mesh.vertices, from_grid.vertices);
    EXPECT_EQ(mesh.sources, from_grid.sources);
    EXPECT_EQ(mesh.faces, from_grid.faces);
    if (!mesh.vertices.empty()) meshes.push_back(std::move(mesh));
  }
  return meshes;
}

TEST(MarchingCubes, BatchedOnThreadsItEqualsTheAssembledBlockMeshes) {
  // A 3 mm sphere has more blocks with surface than one batch of marchingCubes (1,024).
  TsdfMap map(TsdfMap::Config{0.003f});
  fillSphere(&map);
  const std::vector<BlockMesh> meshes = sortedBlockMeshes(map);
  ASSERT_GT(meshes.size(), 2048u);
  std::vector<const BlockMesh*> pointers;
  for (const BlockMesh& mesh : meshes) pointers.push_back(&mesh);
  const LabelledMesh assembled = assembleBlockMeshes(map, pointers, identityLabeller());
  expectWatertight(assembled);
  expectSameMesh(marchingCubes(map, {}, identityLabeller()), assembled);
  ThreadPool pool(3);
  expectSameMesh(marchingCubes(map, {}, identityLabeller(), &pool), assembled);
  // A map without blocks meshes to nothing, threads or not.
  const TsdfMap empty(TsdfMap::Config{0.003f});
  EXPECT_EQ(marchingCubes(empty, {}, identityLabeller(), &pool).numVertices(), 0u);
  EXPECT_EQ(marchingCubes(empty).numFaces(), 0u);
}

TEST(MeshWelder, WeldsEachSharedEdgeOnceAndRemembersOnlyTheSeam) {
  TsdfMap map(TsdfMap::Config{0.01f});
  fillSphere(&map);
  const std::vector<BlockMesh> meshes = sortedBlockMeshes(map);
  // Border vertices (on a block face) are the ones two or more blocks make.
  size_t block_vertices = 0, border = 0;
  for (const BlockMesh& mesh : meshes) {
    block_vertices += mesh.vertices.size();
    for (uint16_t edge : mesh.edges) {
      const int cell = edge / 3, x = cell % 9, y = (cell / 9) % 9, z = cell / 81;
      border += x % kBlockSide == 0 || y % kBlockSide == 0 || z % kBlockSide == 0;
    }
  }
  LabelledMesh out;
  MeshWelder welder(map, identityLabeller(), &out);
  size_t largest_seam = 0;
  for (const BlockMesh& mesh : meshes) {
    welder.add(mesh);
    largest_seam = std::max(largest_seam, welder.seamEdges());
  }
  expectWatertight(out);
  // Every vertex a block shares with another is made once: the welded mesh has exactly the
  // block vertices less the repeats, and the sphere's area (within 1 %).
  EXPECT_LT(out.numVertices(), block_vertices);
  EXPECT_NEAR(meshArea(out), 4.0 * M_PI * kRadius * kRadius, 0.01 * 4.0 * M_PI * kRadius * kRadius);
  EXPECT_EQ(out.superpoint.size(), out.numVertices());
  // The closed surface's every edge was made by its own block too, so nothing is left over,
  // and the seam never held more than a part of the border.
  EXPECT_EQ(welder.seamEdges(), 0u);
  EXPECT_GT(largest_seam, 0u);
  EXPECT_LT(largest_seam, border / 3);
}

TEST(MarchingCubes, ColoursInterpolateAndLabelsComeFromTheNearerVoxel) {
  const float voxel = 0.01f;
  TsdfMap map(TsdfMap::Config{voxel});
  fillSphere(&map, 0.15f);
  const LabelledMesh mesh = marchingCubes(map, {}, identityLabeller());
  ASSERT_EQ(mesh.check(), "");
  ASSERT_EQ(mesh.superpoint.size(), mesh.numVertices());
  size_t checked = 0;
  for (size_t i = 0; i < mesh.numVertices(); ++i) {
    // The vertex sits on a grid edge: two coordinates on voxel centres, one between.
    const Eigen::Vector3f q = mesh.vertices[i] / voxel - Eigen::Vector3f::Constant(0.5f);
    int axis = -1;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(q[k] - std::round(q[k])) > 1e-3f) axis = k;
    }
    if (axis < 0) continue;  // on a voxel centre: either end is right
    Eigen::Vector3i a = q.array().round().cast<int>();
    a[axis] = static_cast<int>(std::floor(q[axis]));
    const Eigen::Vector3i b = a + Eigen::Vector3i::Unit(axis);
    const float t = q[axis] - static_cast<float>(a[axis]);
    const Rgb8 ca = voxelColor(a), cb = voxelColor(b), c = mesh.colors[i];
    EXPECT_NEAR(c.r, ca.r + t * (cb.r - ca.r), 1.01f);
    EXPECT_NEAR(c.g, ca.g + t * (cb.g - ca.g), 1.01f);
    EXPECT_NEAR(c.b, ca.b + t * (cb.b - ca.b), 1.01f);
    if (std::abs(t - 0.5f) < 1e-3f) continue;  // equidistant
    const int32_t expected = voxelLabel(t < 0.5f ? a : b);
    ASSERT_EQ(mesh.superpoint[i], expected) << "vertex " << i;
    ASSERT_EQ(mesh.semantic[i], expected + 2);
    ASSERT_EQ(mesh.instance[i], 1000 + expected);
    ++checked;
  }
  EXPECT_GT(checked, mesh.numVertices() * 9 / 10);
}

TEST(MarchingCubes, VerticesOfUnvotedVoxelsTakeTheirNeighboursLabelWhenAsked) {
  const float voxel = 0.01f;
  TsdfMap map(TsdfMap::Config{voxel});
  fillSphere(&map, 0.15f);
  // Every 4th voxel along a diagonal pattern loses its votes (as voxels no pixel voted for).
  auto erased = [](const Eigen::Vector3i& g) { return ((g.x() + 2 * g.y() + 3 * g.z()) & 3) == 0; };
  auto votesAt = [&map](const Eigen::Vector3i& g) -> const VoxelVotes* {
    const BlockIndex b(static_cast<int>(std::floor(g.x() / 8.0)),
                       static_cast<int>(std::floor(g.y() / 8.0)),
                       static_cast<int>(std::floor(g.z() / 8.0)));
    const Block* block = map.findBlock(b);
    if (!block) return nullptr;
    const Eigen::Vector3i l = g - b * kBlockSide;
    return block->votes(Block::linear(l.x(), l.y(), l.z()));
  };
  for (const auto& block : map.blocks()) {
    for (int z = 0; z < kBlockSide; ++z) {
      for (int y = 0; y < kBlockSide; ++y) {
        for (int x = 0; x < kBlockSide; ++x) {
          VoxelVotes* votes = block->votes(Block::linear(x, y, z));
          if (votes && erased(globalVoxel(block->index, x, y, z))) votes->slots[0] = {};
        }
      }
    }
  }
  // The label most of the 26 neighbours carry; every vote count is 3, so ties go to the
  // smaller label.
  auto expectedFill = [&](const Eigen::Vector3i& g) {
    std::map<int32_t, int> counts;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const VoxelVotes* v = votesAt(g + Eigen::Vector3i(dx, dy, dz));
          if (v && v->slots[0].count > 0) ++counts[v->slots[0].label];
        }
      }
    }
    int32_t best = 0;
    int most = 0;
    for (const auto& [label, count] : counts) {
      if (count > most) best = label, most = count;
    }
    return best;
  };
  MeshLabeller plain = identityLabeller();
  MeshLabeller filling = identityLabeller();
  filling.fill_from_neighbours = true;
  const LabelledMesh without = marchingCubes(map, {}, plain);
  const LabelledMesh with = marchingCubes(map, {}, filling);
  ASSERT_EQ(with.vertices, without.vertices);
  size_t filled = 0, kept = 0;
  for (size_t i = 0; i < with.numVertices(); ++i) {
    const Eigen::Vector3f q = with.vertices[i] / voxel - Eigen::Vector3f::Constant(0.5f);
    int axis = -1;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(q[k] - std::round(q[k])) > 1e-3f) axis = k;
    }
    if (axis < 0) continue;
    Eigen::Vector3i a = q.array().round().cast<int>();
    a[axis] = static_cast<int>(std::floor(q[axis]));
    const float t = q[axis] - static_cast<float>(a[axis]);
    if (std::abs(t - 0.5f) < 1e-3f) continue;
    const Eigen::Vector3i source = t < 0.5f ? a : Eigen::Vector3i(a + Eigen::Vector3i::Unit(axis));
    if (erased(source)) {
      ASSERT_EQ(without.superpoint[i], 0);
      ASSERT_EQ(without.semantic[i], 0);
      const int32_t fill = expectedFill(source);
      ASSERT_EQ(with.superpoint[i], 0) << "vertex " << i;  // belongs to no super-point
      ASSERT_EQ(with.semantic[i], fill == 0 ? 0 : fill + 2) << "vertex " << i;
      ASSERT_EQ(with.instance[i], fill == 0 ? 0 : 1000 + fill) << "vertex " << i;
      filled += fill != 0;
    } else {
      ASSERT_EQ(with.superpoint[i], voxelLabel(source));
      ASSERT_EQ(without.superpoint[i], voxelLabel(source));
      ++kept;
    }
  }
  EXPECT_GT(filled, with.numVertices() / 8);
  EXPECT_GT(kept, with.numVertices() / 2);

  // One BlockMeshLabeller over every block, in reverse order, labels each block as a fresh
  // one does: nothing it keeps from one block leaks into the next.
  IncrementalMesher mesher{MarchingCubesConfig()};
  mesher.update(&map);
  std::vector<BlockIndex> blocks = mesher.takeChangedBlocks();
  std::reverse(blocks.begin(), blocks.end());
  BlockMeshLabeller reused(map, filling);
  size_t block_vertices = 0;
  for (const BlockIndex& index : blocks) {
    const BlockMesh* stored = mesher.find(index);
    ASSERT_NE(stored, nullptr);
    const LabelledMesh fresh = labelBlockMesh(map, *stored, filling);
    const LabelledMesh again = reused.label(*stored);
    ASSERT_EQ(again.vertices, fresh.vertices);
    ASSERT_EQ(again.superpoint, fresh.superpoint);
    ASSERT_EQ(again.semantic, fresh.semantic);
    ASSERT_EQ(again.instance, fresh.instance);
    block_vertices += fresh.numVertices();
  }
  EXPECT_GT(block_vertices, with.numVertices());  // border vertices appear in two blocks

  // Nothing to copy from: no label is invented.
  for (const auto& block : map.blocks()) {
    for (VoxelVotes& v : block->vote_sets) v.slots[0] = {};
  }
  for (int32_t label : marchingCubes(map, {}, filling).semantic) ASSERT_EQ(label, 0);
}

TEST(MarchingCubes, RejectsBadConfig) {
  MarchingCubesConfig config;
  config.max_sdf_jump_voxels = 0.0f;
  try {
    config.check();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("max_sdf_jump_voxels"), std::string::npos);
  }
  config = MarchingCubesConfig();
  config.min_weight = -1.0f;
  EXPECT_THROW(IncrementalMesher{config}, Error);
}

// ---- IncrementalMesher -----------------------------------------------------------------

TEST(IncrementalMesher, RemeshesOnlyChangedBlocksAndMatchesFromScratch) {
  TsdfMap map(TsdfMap::Config{0.01f});
  fillSphere(&map);
  IncrementalMesher mesher;
  EXPECT_EQ(mesher.update(&map), map.numBlocks());
  for (const auto& block : map.blocks()) ASSERT_FALSE(block->updated);
  const LabelledMesh before = mesher.assemble(map);
  expectSameMesh(before, marchingCubes(map));
  EXPECT_EQ(mesher.update(&map), 0u);

  // Dent the sphere inside one block on the surface: push its surface inward by 4 mm.
  const BlockIndex changed = map.blockIndexOf(kCentre + Eigen::Vector3f(kRadius, 0.0f, 0.0f));
  Block* block = map.findBlock(changed);
  ASSERT_NE(block, nullptr);
  for (Voxel& v : block->voxels) v.sdf_m += v.weight > 0.0f ? 0.004f : 0.0f;
  block->updated = true;
  block->lower_changed = 0xFE;  // every face changed
  size_t expected = 0;
  for (int slot = 0; slot < 8; ++slot) {
    expected +=
        map.findBlock(changed - BlockIndex(slot & 1, (slot >> 1) & 1, slot >> 2)) != nullptr;
  }
  EXPECT_EQ(mesher.update(&map), expected);
  EXPECT_EQ(mesher.lastRemeshedBlocks(), expected);
  EXPECT_EQ(mesher.totalRemeshedBlocks(), map.numBlocks() + expected);

  const LabelledMesh after = mesher.assemble(map);
  expectSameMesh(after, marchingCubes(map));
  expectWatertight(after);
  size_t moved = 0;
  for (const Eigen::Vector3f& p : after.vertices) moved += std::abs(sphereSdf(p) + 0.004f) < 1e-3f;
  EXPECT_GT(moved, 10u);

  // A change inside the block, off the faces its lower neighbours read, re-meshes it alone.
  for (int z = 1; z < kBlockSide; ++z) {
    for (int y = 1; y < kBlockSide; ++y) {
      for (int x = 1; x < kBlockSide; ++x) {
        Voxel& v = block->at(x, y, z);
        v.sdf_m += v.weight > 0.0f ? 0.002f : 0.0f;
      }
    }
  }
  block->updated = true;
  EXPECT_EQ(mesher.update(&map), 1u);
  expectSameMesh(mesher.assemble(map), marchingCubes(map));
  // A change on its lower x face alone re-meshes it and its lower x neighbour.
  for (int z = 0; z < kBlockSide; ++z) {
    for (int y = 0; y < kBlockSide; ++y) {
      Voxel& v = block->at(0, y, z);
      v.sdf_m += v.weight > 0.0f ? 0.002f : 0.0f;
    }
  }
  block->updated = true;
  block->lower_changed = 1 << 1;
  ASSERT_NE(map.findBlock(changed - BlockIndex(1, 0, 0)), nullptr);
  EXPECT_EQ(mesher.update(&map), 2u);
  expectSameMesh(mesher.assemble(map), marchingCubes(map));

  // A block the mesher has never seen is meshed even without its flag, with its lower
  // neighbours (whose border cubes now reach observed voxels).
  const BlockIndex fresh(50, 50, 50);
  Block* lone = map.allocateBlock(fresh);
  for (int i = 0; i < kBlockVoxels; ++i) {
    lone->voxels[i].sdf_m = (i % kBlockSide) < 4 ? 0.003f : -0.003f;
    lone->voxels[i].weight = 1.0f;
  }
  EXPECT_EQ(mesher.update(&map), 1u);
  expectSameMesh(mesher.assemble(map), marchingCubes(map));
}

TEST(IncrementalMesher, RelabelsAtAssembleTimeWithoutRemeshing) {
  TsdfMap map(TsdfMap::Config{0.01f});
  fillSphere(&map, 0.15f);
  IncrementalMesher mesher;
  mesher.update(&map);
  const uint64_t meshed = mesher.totalRemeshedBlocks();

  const LabelledMesh separate = mesher.assemble(map, identityLabeller());
  std::set<int32_t> labels(separate.superpoint.begin(), separate.superpoint.end());
  EXPECT_EQ(labels, (std::set<int32_t>{1, 2, 3, 4, 5, 6, 7}));

  // Super-points 2..7 merge into 1: every vertex becomes 1, no block is re-meshed.
  MeshLabeller merged = identityLabeller();
  merged.superpoint = [](const VoxelVotes& v) { return argmaxLabel(v, [](int32_t) { return 1; }); };
  const LabelledMesh relabelled = mesher.assemble(map, merged);
  EXPECT_EQ(mesher.totalRemeshedBlocks(), meshed);
  EXPECT_EQ(relabelled.vertices, separate.vertices);
  EXPECT_EQ(relabelled.faces, separate.faces);
  for (size_t i = 0; i < relabelled.numVertices(); ++i) {
    ASSERT_EQ(relabelled.superpoint[i], 1);
    ASSERT_EQ(relabelled.semantic[i], 3);
    ASSERT_EQ(relabelled.instance[i], 1001);
  }
  // Votes changed in the map (no geometry change) show up at the next assembly too.
  for (const auto& block : map.blocks()) {
    for (VoxelVotes& v : block->vote_sets) v.slots[0].label = 9;
  }
  const LabelledMesh revoted = mesher.assemble(map, identityLabeller());
  EXPECT_EQ(std::set<int32_t>(revoted.superpoint.begin(), revoted.superpoint.end()),
            std::set<int32_t>{9});
}

TEST(IncrementalMesher, ThreadsGiveTheSameMesh) {
  TsdfMap a(TsdfMap::Config{0.01f}), b(TsdfMap::Config{0.01f});
  fillSphere(&a);
  fillSphere(&b);
  ThreadPool pool(2);
  IncrementalMesher serial, parallel(MarchingCubesConfig(), &pool);
  serial.update(&a);
  parallel.update(&b);
  expectSameMesh(serial.assemble(a, identityLabeller()), parallel.assemble(b, identityLabeller()));
}

TEST(IncrementalMesher, ReportsChangedBlocksOnceAndTheirMeshesMatchTheWholeMesh) {
  TsdfMap map(TsdfMap::Config{0.01f});
  fillSphere(&map, 0.15f);
  ThreadPool pool(2);
  IncrementalMesher mesher(MarchingCubesConfig(), &pool);
  EXPECT_TRUE(mesher.takeChangedBlocks().empty());
  std::vector<BlockIndex> meshed_on_thread;
  std::mutex mutex;
  mesher.update(&map, [&](const BlockMesh& mesh, int thread) {
    ASSERT_GE(thread, 0);
    ASSERT_LT(thread, 2);
    std::lock_guard<std::mutex> lock(mutex);
    meshed_on_thread.push_back(mesh.index);
  });
  std::vector<BlockIndex> all;
  for (const auto& block : map.blocks()) all.push_back(block->index);
  std::sort(all.begin(), all.end(), blockIndexLess);
  std::sort(meshed_on_thread.begin(), meshed_on_thread.end(), blockIndexLess);
  EXPECT_EQ(meshed_on_thread, all);
  EXPECT_EQ(mesher.takeChangedBlocks(), all);
  EXPECT_TRUE(mesher.takeChangedBlocks().empty());

  // Every block's own labelled mesh, vertex by vertex, is the whole mesh's: same positions,
  // colours and labels (border vertices appear in two blocks, welded once in the whole mesh).
  const MeshLabeller labeller = identityLabeller();
  const LabelledMesh whole = mesher.assemble(map, labeller);
  std::map<std::array<float, 3>, std::array<int32_t, 3>> expected;
  for (size_t i = 0; i < whole.numVertices(); ++i) {
    const Eigen::Vector3f& p = whole.vertices[i];
    expected[{p.x(), p.y(), p.z()}] = {whole.superpoint[i], whole.semantic[i], whole.instance[i]};
  }
  std::set<std::array<float, 3>> seen;
  size_t faces = 0;
  for (const BlockIndex& index : all) {
    const BlockMesh* stored = mesher.find(index);
    ASSERT_NE(stored, nullptr);
    const LabelledMesh mesh = labelBlockMesh(map, *stored, labeller);
    ASSERT_EQ(mesh.check(), "");
    faces += mesh.numFaces();
    for (size_t i = 0; i < mesh.numVertices(); ++i) {
      const Eigen::Vector3f& p = mesh.vertices[i];
      const auto it = expected.find({p.x(), p.y(), p.z()});
      ASSERT_NE(it, expected.end()) << "block vertex not in the whole mesh";
      EXPECT_EQ(it->second,
                (std::array<int32_t, 3>{mesh.superpoint[i], mesh.semantic[i], mesh.instance[i]}));
      seen.insert(it->first);
    }
  }
  EXPECT_EQ(seen.size(), expected.size());
  EXPECT_EQ(faces, whole.numFaces());
  EXPECT_EQ(mesher.find(BlockIndex(99, 99, 99)), nullptr);

  // One block changed on all its faces: it and its existing lower neighbours are reported,
  // whoever updated.
  const BlockIndex changed = map.blockIndexOf(kCentre + Eigen::Vector3f(0.15f, 0.0f, 0.0f));
  map.findBlock(changed)->updated = true;
  map.findBlock(changed)->lower_changed = 0xFE;
  std::vector<BlockIndex> expected_changed;
  for (int slot = 0; slot < 8; ++slot) {
    const BlockIndex lower = changed - BlockIndex(slot & 1, (slot >> 1) & 1, slot >> 2);
    if (map.findBlock(lower)) expected_changed.push_back(lower);
  }
  std::sort(expected_changed.begin(), expected_changed.end(), blockIndexLess);
  mesher.update(&map);
  mesher.update(&map);  // nothing new: the list is kept until taken
  EXPECT_EQ(mesher.takeChangedBlocks(), expected_changed);
}

// ---- MeshExport ------------------------------------------------------------------------

TEST(MeshExport, PalettesAreFixedAndDeterministic) {
  EXPECT_EQ(semanticColor(0), (Rgb8{0, 0, 0}));
  EXPECT_EQ(semanticColor(1), (Rgb8{174, 199, 232}));  // wall
  EXPECT_EQ(semanticColor(5), (Rgb8{188, 189, 34}));   // chair
  EXPECT_EQ(semanticColor(40), (Rgb8{100, 85, 144}));
  EXPECT_EQ(semanticColor(41), (Rgb8{0, 0, 0}));
  EXPECT_EQ(idColor(0), (Rgb8{0, 0, 0}));
  std::set<std::tuple<int, int, int>> colours;
  for (int32_t id = 1; id <= 1000; ++id) {
    const Rgb8 c = idColor(id);
    EXPECT_EQ(c, idColor(id));
    EXPECT_GE(std::min({c.r, c.g, c.b}), 48);
    colours.insert({c.r, c.g, c.b});
  }
  EXPECT_GE(colours.size(), 995u);
}

TEST(MeshExport, WritesThreeColouringsThatReadBack) {
  TsdfMap map(TsdfMap::Config{0.02f});
  fillSphere(&map, 0.2f);
  const LabelledMesh mesh = marchingCubes(map, {}, identityLabeller());
  test::TempDir dir;
  writeLabelledMeshes(dir.path("out"), mesh);
  const std::pair<const char*, const std::vector<int32_t>*> files[] = {
      {kSemanticMeshFile, &mesh.semantic},
      {kInstanceMeshFile, &mesh.instance},
      {kSuperpointMeshFile, &mesh.superpoint}};
  for (const auto& [name, ids] : files) {
    SCOPED_TRACE(name);
    const LabelledMesh back = readPly(dir.path("out/") + name);
    EXPECT_EQ(back.vertices, mesh.vertices);
    EXPECT_EQ(back.faces, mesh.faces);
    EXPECT_EQ(back.semantic, mesh.semantic);
    EXPECT_EQ(back.instance, mesh.instance);
    EXPECT_EQ(back.superpoint, mesh.superpoint);
    ASSERT_EQ(back.colors.size(), mesh.numVertices());
    for (size_t i = 0; i < back.colors.size(); ++i) {
      const int32_t id = (*ids)[i];
      ASSERT_EQ(back.colors[i], ids == &mesh.semantic ? semanticColor(id) : idColor(id));
    }
  }
}

TEST(MeshExport, UnlabelledMeshGetsZeroPropertiesAndErrorsNameTheFile) {
  TsdfMap map(TsdfMap::Config{0.02f});
  fillSphere(&map, 0.1f);
  const LabelledMesh mesh = marchingCubes(map);
  ASSERT_TRUE(mesh.superpoint.empty());
  test::TempDir dir;
  writeLabelledMeshes(dir.path(), mesh, PlyFormat::kAscii);
  const LabelledMesh back = readPly(dir.path(kInstanceMeshFile));
  EXPECT_EQ(back.instance, std::vector<int32_t>(mesh.numVertices(), 0));
  EXPECT_EQ(back.semantic, std::vector<int32_t>(mesh.numVertices(), 0));
  EXPECT_EQ(back.superpoint, std::vector<int32_t>(mesh.numVertices(), 0));

  // The output folder is a regular file.
  std::ofstream(dir.path("file")) << "x";
  try {
    writeLabelledMeshes(dir.path("file"), mesh);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir.path("file")), std::string::npos) << e.what();
  }
  // One of the three files cannot be written.
  std::filesystem::create_directories(dir.path("blocked/") + kSuperpointMeshFile);
  try {
    writeLabelledMeshes(dir.path("blocked"), mesh);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(kSuperpointMeshFile), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace panmap
