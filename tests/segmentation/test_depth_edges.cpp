// The edge maps' two paths (AVX2, all offsets of a row in one pass; scalar, one offset at a
// time) give the same bits, on random geometry of many widths, windows and bands.
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "panmap/segmentation/internal/depth_edges.h"

namespace panmap {
namespace {

// Random points and unit normals; about one pixel in six without depth and one in five
// without a normal, so every branch of the pair test and of the flags is taken.
internal::DepthGeometry randomGeometry(int width, int height, uint32_t seed) {
  internal::DepthGeometry g;
  g.resize(width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f), depth(0.3f, 4.0f);
  std::uniform_int_distribution<int> die(0, 29);
  for (size_t i = 0; i < g.z_m.size(); ++i) {
    const int roll = die(rng);
    if (roll < 5) {  // no depth: every plane 0
      g.x_m[i] = g.y_m[i] = g.z_m[i] = g.nx[i] = g.ny[i] = g.nz[i] = g.has_normal[i] = 0.0f;
      g.discontinuity[i] = g.surface_step[i] = 0.0f;
      continue;
    }
    g.x_m[i] = coordinate(rng);
    g.y_m[i] = coordinate(rng);
    g.z_m[i] = depth(rng);
    g.discontinuity[i] = roll == 5 ? 1.0f : 0.0f;
    g.surface_step[i] = 0.0f;
    if (roll < 11) {
      g.nx[i] = g.ny[i] = g.nz[i] = g.has_normal[i] = 0.0f;
      continue;
    }
    float n[3] = {coordinate(rng), coordinate(rng), -std::abs(coordinate(rng)) - 0.2f};
    const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    g.nx[i] = n[0] / length;
    g.ny[i] = n[1] / length;
    g.nz[i] = n[2] / length;
    g.has_normal[i] = 1.0f;
  }
  return g;
}

internal::EdgeMaps edgeMaps(const internal::DepthGeometry& g, int window_px, int band_rows,
                            internal::EdgePath path) {
  DepthSegmentationConfig config;
  config.min_convexity_window_px = window_px;
  internal::EdgeMaps edges;
  edges.resize(g.width, g.height);
  internal::EdgeScratch scratch;
  for (int v0 = 0; v0 < g.height; v0 += band_rows) {
    internal::computeEdgeRows(g, config, v0, std::min(g.height, v0 + band_rows), &scratch, &edges,
                              path);
  }
  return edges;
}

TEST(DepthEdges, BothPathsGiveTheSameBits) {
  int concave = 0;
  for (const int width : {3, 12, 13, 37, 64, 200}) {
    for (const int window_px : {3, 5, 9}) {
      for (const int band_rows : {1, 7, 1000}) {
        const internal::DepthGeometry g = randomGeometry(width, 23, 1000u * width + window_px);
        const internal::EdgeMaps fast =
            edgeMaps(g, window_px, band_rows, internal::EdgePath::kFastest);
        const internal::EdgeMaps scalar =
            edgeMaps(g, window_px, band_rows, internal::EdgePath::kScalar);
        const std::vector<float>& a = fast.min_convexity.pixels();
        const std::vector<float>& b = scalar.min_convexity.pixels();
        ASSERT_EQ(a.size(), b.size());
        ASSERT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0)
            << "width " << width << ", window " << window_px << ", bands of " << band_rows;
        ASSERT_EQ(fast.flags.pixels(), scalar.flags.pixels());
        for (const float c : a) concave += c < 1.0f;
      }
    }
  }
  // The comparison is not of two all-flat maps.
  EXPECT_GT(concave, 10000);
}

TEST(DepthEdges, MinConvexityIsTheWindowMinimumOfPairConvexities) {
  // Hand-checked against the definition on one pixel, the scalar path and the fast one alike.
  const internal::DepthGeometry g = randomGeometry(40, 9, 7u);
  const int u = 21, v = 4, r = 2;
  float expected = 1.0f;
  for (int dv = -r; dv <= r; ++dv) {
    for (int du = -r; du <= r; ++du) {
      if (du == 0 && dv == 0) continue;
      const size_t i = g.index(u, v), j = g.index(u + du, v + dv);
      const float c =
          internal::pairConvexity(g.x_m[j] - g.x_m[i], g.y_m[j] - g.y_m[i], g.z_m[j] - g.z_m[i],
                                  g.nx[i], g.ny[i], g.nz[i], g.nx[j], g.ny[j], g.nz[j]);
      const float value = 1.0f - g.has_normal[i] * g.has_normal[j] * (1.0f - c);
      expected = std::min(expected, value);
    }
  }
  for (const internal::EdgePath path :
       {internal::EdgePath::kFastest, internal::EdgePath::kScalar}) {
    EXPECT_FLOAT_EQ(edgeMaps(g, 5, 1000, path).min_convexity(u, v), expected);
  }
}

}  // namespace
}  // namespace panmap
