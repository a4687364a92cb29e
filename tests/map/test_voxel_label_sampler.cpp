// VoxelLabelSampler: labelRow() gives what label() and lastVoxel() give sample by sample.
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "panmap/map/voxel_label_sampler.h"

namespace panmap {
namespace {

TEST(VoxelLabelSampler, RowOfSamplesMatchesOneByOne) {
  TsdfMap::Config config;
  config.voxel_size_m = 0.05f;
  TsdfMap map(config);
  std::mt19937 rng(11);
  // Votes in some voxels of a few blocks in front of the camera; other blocks stay unallocated.
  for (int bx = -3; bx <= 2; ++bx) {
    for (int by = -2; by <= 1; ++by) {
      if ((bx + by) % 3 == 0) continue;
      Block* block = map.allocateBlock(BlockIndex(bx, by, 2));
      for (int i = 0; i < kBlockVoxels; ++i) {
        if (rng() % 4 == 0) continue;  // no votes: label 0
        for (int k = 0; k < 1 + static_cast<int>(rng() % 3); ++k) {
          addVotes(block->votesToWrite(i), 1 + static_cast<int32_t>(rng() % 6), 1 + rng() % 5);
        }
      }
    }
  }
  const PinholeCamera cam{200.0, 200.0, 159.5, 119.5, 320, 240};
  Eigen::Isometry3f T_W_C = Eigen::Isometry3f::Identity();
  T_W_C.rotate(Eigen::AngleAxisf(0.1f, Eigen::Vector3f(0.3f, 1.0f, 0.2f).normalized()));
  auto resolve = [](int32_t l) { return l == 5 ? 2 : l; };  // 5 was merged into 2
  VoxelLabelSampler one(map, T_W_C, cam, resolve), row(map, T_W_C, cam, resolve);
  std::uniform_real_distribution<float> depth_m(0.7f, 1.3f);
  int labelled = 0, unallocated = 0;
  for (int v = 0; v < cam.height; v += 3) {
    std::vector<RowSample> samples;
    for (int u = 0; u < cam.width; u += 1 + static_cast<int>(rng() % 3)) {
      samples.push_back({u, depth_m(rng)});
    }
    std::vector<int32_t> labels(samples.size()), labels_only(samples.size());
    std::vector<Eigen::Vector3i> voxels(samples.size());
    row.labelRow(v, samples, labels.data(), voxels.data());
    row.labelRow(v, samples, labels_only.data(), nullptr);
    for (size_t k = 0; k < samples.size(); ++k) {
      const int32_t expected = one.label(samples[k].u, v, samples[k].d_m);
      ASSERT_EQ(labels[k], expected) << "pixel " << samples[k].u << ", " << v;
      ASSERT_EQ(labels_only[k], expected);
      ASSERT_EQ(voxels[k], one.lastVoxel());
      ASSERT_NE(labels[k], 5);  // merged labels resolve
      labelled += expected > 0;
      unallocated += map.findBlock(BlockIndex(voxels[k].x() >> 3, voxels[k].y() >> 3,
                                              voxels[k].z() >> 3)) == nullptr;
    }
  }
  // Both kinds of sample occur.
  EXPECT_GT(labelled, 1000);
  EXPECT_GT(unallocated, 100);
}

}  // namespace
}  // namespace panmap
