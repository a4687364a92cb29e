#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "panmap/map/internal/block_integration.h"

namespace panmap {
namespace internal {
namespace {

// A depth image with smooth slopes, steps, holes and out-of-range pixels, so every branch of
// the depth sampling (bilinear, nearest across an edge, invalid) is taken.
Image<float> roughDepth(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> jitter(-0.002f, 0.002f);
  std::uniform_int_distribution<int> hole(0, 40);
  Image<float> depth(w, h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      float d = 0.9f + 0.0015f * u + 0.0007f * v + jitter(rng);
      if ((u / 9 + v / 7) % 5 == 0) d += 0.12f;  // steps: depth edges
      if (hole(rng) == 0) d = 0.0f;              // missing depth
      depth(u, v) = d;
    }
  }
  return depth;
}

Image<Rgb8> gradientColour(int w, int h) {
  Image<Rgb8> color(w, h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      color(u, v) = Rgb8{static_cast<uint8_t>(u * 3), static_cast<uint8_t>(v * 5),
                         static_cast<uint8_t>(u + v)};
    }
  }
  return color;
}

// Starting voxels with history, so the weighted running means are exercised too.
void seedBlock(Block* block, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> sdf(-0.03f, 0.03f), weight(0.0f, 5.0f);
  for (Voxel& v : block->voxels) {
    v.sdf_m = sdf(rng);
    v.weight = weight(rng) > 2.5f ? weight(rng) : 0.0f;
    v.color =
        Rgb8{static_cast<uint8_t>(rng()), static_cast<uint8_t>(rng()), static_cast<uint8_t>(rng())};
  }
}

// Block::lower_changed as it must be after an update that changed the voxels differing
// between `before` and `after`: bit s for each lower neighbour whose cubes read one of them.
uint8_t expectedLowerChanged(const Block& before, const Block& after) {
  uint8_t mask = 0;
  for (int z = 0; z < kBlockSide; ++z) {
    for (int y = 0; y < kBlockSide; ++y) {
      for (int x = 0; x < kBlockSide; ++x) {
        if (std::memcmp(&before.at(x, y, z), &after.at(x, y, z), sizeof(Voxel)) == 0) continue;
        for (int slot = 1; slot < 8; ++slot) {
          const bool reads =
              (!(slot & 1) || x == 0) && (!(slot & 2) || y == 0) && (!(slot & 4) || z == 0);
          if (reads) mask |= 1 << slot;
        }
      }
    }
  }
  return mask;
}

// The 8-wide path must give the portable path's voxels bit for bit, over blocks straddling
// the image border, the minimum depth and the truncation band, with and without colour,
// carving and weight drop-off.
TEST(BlockUpdate, VectorPathMatchesScalarBitForBit) {
  const int w = 80, h = 60;
  const Image<float> depth = roughDepth(w, h, 7);
  const Image<Rgb8> color = gradientColour(w, h);
  BlockUpdateParams p;
  p.depth_m = &depth;
  p.fx = p.fy = 70.0f;
  p.cx = 39.5f;
  p.cy = 29.5f;
  p.voxel_m = 0.01f;
  p.truncation_m = 0.04f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> angle(-0.4f, 0.4f), lateral(-0.6f, 0.6f),
      range(0.05f, 1.2f);
  size_t total_updated = 0, partial_masks = 0;
  for (int trial = 0; trial < 400; ++trial) {
    p.color = trial % 2 ? &color : nullptr;
    p.space_carving = trial % 3 == 0;
    p.weight_dropoff = trial % 5 != 0;
    p.R_C_W = (Eigen::AngleAxisf(angle(rng), Eigen::Vector3f::UnitX()) *
               Eigen::AngleAxisf(angle(rng), Eigen::Vector3f::UnitY()))
                  .toRotationMatrix();
    const Eigen::Vector3f origin_C(lateral(rng), lateral(rng), range(rng));
    Block scalar, vector, before;
    seedBlock(&scalar, trial);
    for (Block* copy : {&vector, &before}) {
      copy->index = scalar.index;
      copy->lower_changed = scalar.lower_changed;
      std::memcpy(copy->voxels, scalar.voxels, sizeof(Block::voxels));
    }
    const size_t n_scalar = updateBlockScalar(p, origin_C, &scalar);
    const size_t n_vector = updateBlock(p, origin_C, &vector);
    ASSERT_EQ(n_scalar, n_vector) << "trial " << trial;
    ASSERT_EQ(0, std::memcmp(scalar.voxels, vector.voxels, sizeof(scalar.voxels)))
        << "trial " << trial;
    // Every fused voxel changes here (weights stay far below the cap), so the mask is exact.
    ASSERT_EQ(scalar.lower_changed, expectedLowerChanged(before, scalar)) << "trial " << trial;
    ASSERT_EQ(vector.lower_changed, scalar.lower_changed) << "trial " << trial;
    partial_masks += scalar.lower_changed != 0 && scalar.lower_changed != 0xFE;
    total_updated += n_scalar;
  }
  // The trials must actually reach the surface, or the comparison proves nothing; and some
  // must change some of the lower faces but not all.
  EXPECT_GT(total_updated, 10000u);
  EXPECT_GT(partial_masks, 20u);
  if (!blockUpdateUsesAvx2()) GTEST_SKIP() << "no AVX2 on this CPU: only the scalar path ran";
}

// A fronto-parallel wall 1 m away seen by the voxel column on the optical axis: each voxel's
// new SDF is the measured distance, truncated (and rounded to the voxel's 2-byte float), and
// only the band is touched.
TEST(BlockUpdate, WallAtOneMetre) {
  const int w = 40, h = 40;
  Image<float> depth(w, h);
  for (size_t i = 0; i < depth.size(); ++i) depth.data()[i] = 1.0f;
  BlockUpdateParams p;
  p.depth_m = &depth;
  p.fx = p.fy = 50.0f;
  p.cx = p.cy = 19.5f;
  p.voxel_m = 0.01f;
  p.truncation_m = 0.03f;
  p.weight_dropoff = false;
  Block block;
  // Voxel centres at z = 0.965 .. 1.035 on the axis.
  const size_t n = updateBlock(p, Eigen::Vector3f(0.0f, 0.0f, 0.965f), &block);
  EXPECT_GT(n, 0u);
  for (int z = 0; z < kBlockSide; ++z) {
    const float vz = 0.965f + 0.01f * z;
    const Voxel& v = block.at(0, 0, z);
    const float sdf = 1.0f - vz;
    if (sdf < -p.truncation_m || sdf > p.truncation_m) {
      EXPECT_EQ(v.weight, 0.0f) << "z " << z;
    } else {
      EXPECT_EQ(v.weight, 1.0f) << "z " << z;
      // Stored as a 2-byte float: within half its step, 2^-11 of the value.
      EXPECT_NEAR(v.sdf_m, sdf, 1e-6f + std::ldexp(std::abs(sdf), -11)) << "z " << z;
    }
  }
}

// Voxels are half a cache line and blocks keep them on line boundaries, wherever the block
// lives: a voxel never straddles two lines.
TEST(BlockLayout, VoxelsStartOnACacheLine) {
  TsdfMap map(TsdfMap::Config{0.02f});
  for (int i = 0; i < 20; ++i) {
    const Block* block = map.allocateBlock(BlockIndex(i, -i, 2 * i));
    EXPECT_EQ(reinterpret_cast<uintptr_t>(&block->voxels[0]) % 64, 0u) << i;
  }
  Block on_stack;
  EXPECT_EQ(reinterpret_cast<uintptr_t>(&on_stack.voxels[0]) % 64, 0u);
  EXPECT_EQ(64 % sizeof(Voxel), 0u);
}

}  // namespace
}  // namespace internal
}  // namespace panmap
