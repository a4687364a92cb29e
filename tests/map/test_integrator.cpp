#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/map/interpolation.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// Exact (noise-free, 1 mm quantised) RGB-D frame of a mesh.
RgbdFrame renderFrame(const MeshRenderer& renderer, const Eigen::Isometry3d& T_W_C) {
  const PinholeCamera cam = test::kinectCamera();
  const RenderedView view = renderer.render(cam, T_W_C);
  DepthNoiseConfig exact;
  exact.enabled = false;
  RgbdFrame frame;
  frame.camera = cam;
  frame.depth_scale_m = 0.001;
  frame.depth = simulateDepth(view, exact, 0);
  frame.color = view.color;
  return frame;
}

// A wall filling the view 2 m ahead of a camera at the origin looking along +x, its left half
// (u < 320) labelled 7, its right half 9.
struct LabelledWall {
  LabelledWall() : labels(640, 480, 0) {
    LabelledMesh mesh;
    test::addQuad(&mesh, {2, -3, -3}, {2, 3, -3}, {2, 3, 3}, {2, -3, 3}, 1, 1, 10);
    frame = renderFrame(MeshRenderer(mesh), T_W_C);
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) labels(u, v) = u < 320 ? 7 : 9;
    }
  }
  Eigen::Isometry3d T_W_C = test::lookAt({0, 0, 0}, {1, 0, 0});
  RgbdFrame frame;
  LabelImage labels;
};

class AnalyticScene : public ::testing::TestWithParam<float> {};

// Floor plane, a sphere and a box, integrated from four poses around them.
TEST_P(AnalyticScene, SurfaceErrorBelowHalfAVoxel) {
  const float voxel = GetParam();
  LabelledMesh mesh;
  test::addQuad(&mesh, {-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}, 1, 2, 60);
  test::addSphere(&mesh, {0.6f, 0.0f, 0.5f}, 0.4f, 2, 39);
  test::addBox(&mesh, {-0.9f, -0.4f, 0.0f}, {-0.3f, 0.3f, 0.7f}, 3, 3, 12);
  const MeshRenderer renderer(mesh);
  TsdfMap map(TsdfMap::Config{voxel});
  ThreadPool pool(2);
  IntegratorConfig config;
  config.max_depth_m = 6.0f;  // exact depth: no reason to cut the range
  ProjectiveIntegrator integrator(config, &pool);
  for (int k = 0; k < 4; ++k) {
    const double a = k * M_PI / 2 + 0.3;
    const Eigen::Vector3d eye(2.2 * std::cos(a), 2.2 * std::sin(a), 1.6);
    const RgbdFrame frame = renderFrame(renderer, test::lookAt(eye, {0, 0, 0.3}));
    integrator.integrate(frame, test::lookAt(eye, {0, 0, 0.3}), nullptr, &map);
  }
  // Sample the analytic surfaces and read the TSDF there: it should be ~0.
  std::vector<double> errors;
  auto check = [&](const Eigen::Vector3f& p) {
    float sdf = 0.0f;
    if (!interpolateSdf(map, p, &sdf)) return;
    errors.push_back(std::abs(sdf));
  };
  // Points of the visible surfaces, away from where two surfaces meet (there the zero level
  // is shared and the test would measure the corner, not the integrator).
  for (int i = 0; i < 400; ++i) {  // upper sphere, clear of the floor contact
    const float th = 0.1f + 1.9f * (i % 20) / 20.0f,
                ph = 2.0f * static_cast<float>(M_PI) * (i / 20) / 20.0f;
    check(Eigen::Vector3f(0.6f, 0.0f, 0.5f) + 0.4f * Eigen::Vector3f(std::sin(th) * std::cos(ph),
                                                                     std::sin(th) * std::sin(ph),
                                                                     std::cos(th)));
  }
  for (int i = 0; i < 900; ++i) {  // floor, outside the footprints of the sphere and the box
    const Eigen::Vector3f p(-1.5f + 3.0f * (i % 30) / 30.0f, -1.5f + 3.0f * (i / 30) / 30.0f, 0.0f);
    if ((p.head<2>() - Eigen::Vector2f(0.6f, 0.0f)).norm() < 0.55f) continue;
    if (p.x() > -1.05f && p.x() < -0.15f && p.y() > -0.55f && p.y() < 0.45f) continue;
    check(p);
  }
  for (int i = 0; i < 100; ++i)
    check(Eigen::Vector3f(-0.8f + 0.4f * (i % 10) / 10.0f, -0.3f + 0.5f * (i / 10) / 10.0f, 0.7f));
  // Surface error: 99 % of the samples within half a voxel; the few outliers sit where a view
  // grazes the sphere; none beyond a voxel.
  ASSERT_GT(errors.size(), 500u);
  std::sort(errors.begin(), errors.end());
  double mean = 0.0;
  for (double e : errors) mean += e / errors.size();
  EXPECT_LT(errors[errors.size() * 99 / 100], 0.5 * voxel);
  EXPECT_LT(errors.back(), 1.0 * voxel);
  EXPECT_LT(mean, 0.15 * voxel);
}

INSTANTIATE_TEST_SUITE_P(VoxelSizes, AnalyticScene, ::testing::Values(0.01f, 0.02f, 0.05f));

TEST(Integrator, FreeSpaceIsPositiveAndBehindIsNegative) {
  LabelledMesh mesh;
  test::addQuad(&mesh, {2, -3, -3}, {2, 3, -3}, {2, 3, 3}, {2, -3, 3}, 1, 1, 10);  // wall x = 2
  const MeshRenderer renderer(mesh);
  TsdfMap map(TsdfMap::Config{0.02f});
  ThreadPool pool(1);
  ProjectiveIntegrator integrator(IntegratorConfig{}, &pool);
  const Eigen::Isometry3d T = test::lookAt({0, 0, 0}, {1, 0, 0});
  integrator.integrate(renderFrame(renderer, T), T, nullptr, &map);
  float sdf = 0.0f;
  ASSERT_TRUE(interpolateSdf(map, {1.95f, 0.1f, 0.0f}, &sdf));
  EXPECT_NEAR(sdf, 0.05f, 0.01f);
  ASSERT_TRUE(interpolateSdf(map, {2.03f, 0.1f, 0.0f}, &sdf));
  EXPECT_NEAR(sdf, -0.03f, 0.01f);
  Eigen::Vector3f gradient;
  ASSERT_TRUE(interpolateSdf(map, {2.0f, 0.1f, 0.05f}, &sdf, &gradient));
  EXPECT_NEAR(gradient.x(), -1.0f, 0.05f);  // the distance grows toward the camera
  EXPECT_FALSE(interpolateSdf(map, {0.5f, 0.0f, 0.0f}, &sdf));  // never allocated
}

TEST(Integrator, VotesGoToSurfaceVoxelsAndSameInputGivesSameMap) {
  const LabelledWall wall;
  const Eigen::Isometry3d& T = wall.T_W_C;
  const RgbdFrame& frame = wall.frame;
  const LabelImage& labels = wall.labels;
  auto run = [&](int threads) {
    auto map = std::make_unique<TsdfMap>(TsdfMap::Config{0.02f});
    ThreadPool pool(threads);
    ProjectiveIntegrator integrator(IntegratorConfig{}, &pool);
    for (int k = 0; k < 3; ++k) integrator.integrate(frame, T, &labels, map.get());
    return map;
  };
  // Three threads as well: votes are grouped by owner for any thread count, not only two.
  const auto one = run(1);
  for (int threads : {2, 3}) {
    const auto other = run(threads);
    ASSERT_EQ(one->numBlocks(), other->numBlocks()) << threads << " threads";
    for (size_t b = 0; b < one->numBlocks(); ++b) {
      ASSERT_EQ(one->blocks()[b]->index, other->blocks()[b]->index);
      EXPECT_EQ(
          std::memcmp(one->blocks()[b]->voxels, other->blocks()[b]->voxels, sizeof(Block::voxels)),
          0)
          << threads << " threads, block " << b;
      for (int i = 0; i < kBlockVoxels; ++i) {
        const VoxelVotes* a = one->blocks()[b]->votes(i);
        const VoxelVotes* c = other->blocks()[b]->votes(i);
        ASSERT_EQ(a == nullptr, c == nullptr) << threads << " threads, block " << b;
        if (a) {
          EXPECT_EQ(std::memcmp(a, c, sizeof(VoxelVotes)), 0) << threads << " threads";
        }
      }
    }
  }
  // The camera looks along +x with x_C = -y_W: image left (u < 320) is world +y.
  const VoxelVotes* left = one->findVotes({2.0f, 0.5f, 0.1f});
  const VoxelVotes* right = one->findVotes({2.0f, -0.5f, 0.1f});
  ASSERT_TRUE(left && right);
  auto identity = [](int32_t l) { return l; };
  EXPECT_EQ(argmaxLabel(*left, identity), 7);
  EXPECT_EQ(argmaxLabel(*right, identity), 9);
  // A vote per pixel whose point falls in the voxel, in each of the 3 frames.
  EXPECT_GT(left->slots[0].count, 3u);
  EXPECT_EQ(left->slots[0].count % 3, 0u);
  size_t voted = 0;
  for (const auto& block : one->blocks()) {
    for (int i = 0; i < kBlockVoxels; ++i) voted += block->votes(i) != nullptr ? 1 : 0;
  }
  EXPECT_GT(voted, 0u);
  EXPECT_EQ(one->numVotedVoxels(), voted);
  // 5 cm in front: an observed voxel without a vote.
  ASSERT_TRUE(one->findVoxel({1.95f, 0.5f, 0.1f}));
  EXPECT_EQ(one->findVotes({1.95f, 0.5f, 0.1f}), nullptr);
  EXPECT_EQ(argmaxLabel(one->findVotes({1.95f, 0.5f, 0.1f}), identity), 0);
}

TEST(VoteStride, AutomaticIsTheLargestStrideHalfAVoxelApartAtMaxDepth) {
  ASSERT_EQ(IntegratorConfig{}.vote_stride_px, 1);  // every pixel by default
  IntegratorConfig automatic;                       // max_depth_m = 3.5
  automatic.vote_stride_px = 0;
  // floor(voxel * fx / (2 * 3.5 m)), at least 1.
  EXPECT_EQ(voteStride(automatic, 0.01f, 525.0), 1);  // 0.75
  EXPECT_EQ(voteStride(automatic, 0.02f, 525.0), 1);  // 1.5
  EXPECT_EQ(voteStride(automatic, 0.02f, 585.0), 1);  // 1.67
  EXPECT_EQ(voteStride(automatic, 0.05f, 525.0), 3);  // 3.75
  EXPECT_EQ(voteStride(automatic, 0.05f, 585.0), 4);  // 4.18
  EXPECT_EQ(voteStride(automatic, 0.10f, 525.0), 7);  // 7.5
  EXPECT_EQ(voteStride(automatic, 10.0f, 1e9), 64);   // clamped
  automatic.max_depth_m = 2.0f;
  EXPECT_EQ(voteStride(automatic, 0.05f, 525.0), 6);  // 6.56: a shorter range allows more
  IntegratorConfig fixed;
  fixed.vote_stride_px = 2;
  EXPECT_EQ(voteStride(fixed, 0.05f, 525.0), 2);
  EXPECT_EQ(voteStride(fixed, 0.01f, 525.0), 2);
  IntegratorConfig negative;
  negative.vote_stride_px = -1;
  EXPECT_THROW(negative.check(), Error);
}

// At 5 cm voxels 2 m away about 170 pixels cast the same vote in a voxel: the automatic stride
// keeps one in 9 and labels the same voxels the same way.
TEST(Integrator, AutomaticVoteStrideAtCoarseVoxelsLabelsTheSameVoxels) {
  const LabelledWall wall;
  const Eigen::Isometry3d& T = wall.T_W_C;
  const RgbdFrame& frame = wall.frame;
  const LabelImage& labels = wall.labels;
  ThreadPool pool(2);
  auto run = [&](int stride, IntegrationStats* stats) {
    auto map = std::make_unique<TsdfMap>(TsdfMap::Config{0.05f});
    IntegratorConfig config;
    config.vote_stride_px = stride;
    ProjectiveIntegrator integrator(config, &pool);
    *stats = integrator.integrate(frame, T, &labels, map.get());
    return map;
  };
  IntegrationStats every_stats, automatic_stats;
  const auto every = run(1, &every_stats);
  const auto automatic = run(0, &automatic_stats);
  // The wall fills the image: every pixel votes at stride 1, pixels (3i, 3j) at stride 3.
  EXPECT_EQ(every_stats.votes_added, 640u * 480u);
  EXPECT_EQ(automatic_stats.votes_added, 214u * 160u);
  auto identity = [](int32_t l) { return l; };
  size_t voted = 0, kept = 0;
  for (size_t b = 0; b < every->numBlocks(); ++b) {
    const Block& one = *every->blocks()[b];
    const Block& other = *automatic->blocks()[b];
    ASSERT_EQ(one.index, other.index);
    for (int i = 0; i < kBlockVoxels; ++i) {
      const int32_t label = argmaxLabel(one.votes(i), identity);
      if (label == 0) continue;
      ++voted;
      const int32_t sampled = argmaxLabel(other.votes(i), identity);
      if (sampled == 0) continue;
      ++kept;
      EXPECT_EQ(sampled, label);
    }
  }
  ASSERT_GT(voted, 1000u);
  EXPECT_GE(kept, voted * 95 / 100) << kept << " of " << voted;
}

// At 10 cm voxels a voxel of the wall gets its votes from about 15 rows of each band of 16;
// summed per band, every voxel still ends with one vote per pixel whose point falls in it, as
// the votes of each row applied pixel by pixel give it (two labels: nothing is evicted).
TEST(Integrator, VotesSummedPerBandOfRowsEqualAVoteAPixel) {
  const LabelledWall wall;
  const Eigen::Isometry3f T_W_C = wall.T_W_C.cast<float>();
  for (int threads : {1, 2}) {
    TsdfMap map(TsdfMap::Config{0.1f});
    ThreadPool pool(threads);
    ProjectiveIntegrator integrator(IntegratorConfig{}, &pool);
    const IntegrationStats stats = integrator.integrate(wall.frame, wall.T_W_C, &wall.labels, &map);
    EXPECT_EQ(stats.votes_added, 640u * 480u);
    // The reference: the same rows' votes applied one row at a time, into a copy of the map's
    // blocks without votes.
    TsdfMap reference(TsdfMap::Config{0.1f});
    for (const auto& block : map.blocks()) reference.allocateBlock(block->index);
    Image<float> depth_m(640, 480, 0.0f);
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const float d = wall.frame.depth(u, v) * static_cast<float>(wall.frame.depth_scale_m);
        depth_m(u, v) = d >= 0.1f && d <= 3.5f ? d : 0.0f;  // IntegratorConfig's range
      }
    }
    MutableVoxelLookup lookup(reference);
    std::vector<VoteRun> runs(640);
    for (int v = 0; v < 480; ++v) {
      const size_t n =
          internal::findRowVotesScalar(depth_m, wall.labels, v, 1, T_W_C,
                                       RowCamera::of(wall.frame.camera), &lookup, runs.data());
      for (size_t i = 0; i < n; ++i) {
        addVotes(runs[i].block->votesToWrite(runs[i].voxel), runs[i].label, runs[i].count);
      }
    }
    size_t voted = 0;
    for (size_t b = 0; b < map.numBlocks(); ++b) {
      const Block& got = *map.blocks()[b];
      const Block* want = reference.findBlock(got.index);
      ASSERT_NE(want, nullptr);
      for (int i = 0; i < kBlockVoxels; ++i) {
        const VoxelVotes* g = got.votes(i);
        const VoxelVotes* w = want->votes(i);
        ASSERT_EQ(g == nullptr, w == nullptr) << "block " << b << " voxel " << i;
        if (!g) continue;
        ++voted;
        EXPECT_EQ(std::memcmp(g, w, sizeof(VoxelVotes)), 0) << "block " << b << " voxel " << i;
      }
    }
    EXPECT_GT(voted, 100u) << threads << " threads";
  }
}

// A block keeps vote sets only for voxels that got a vote; the others have none (null), and
// giving one voxel its set leaves every other voxel's alone.
TEST(Votes, ABlockKeepsVoteSetsOnlyForVotedVoxels) {
  Block block;
  for (int i = 0; i < kBlockVoxels; ++i) ASSERT_EQ(block.votes(i), nullptr);
  VoxelVotes* three = block.votesToWrite(3);
  EXPECT_EQ(three->total(), 0u);
  addVotes(three, 11, 4);
  addVote(block.votesToWrite(200), 12);
  EXPECT_EQ(block.votesToWrite(3)->slots[0].label, 11);  // the same set again, not a new one
  ASSERT_EQ(block.vote_sets.size(), 2u);
  ASSERT_NE(block.votes(3), nullptr);
  EXPECT_EQ(block.votes(3)->slots[0].count, 4u);
  EXPECT_EQ(block.votes(200)->slots[0].label, 12);
  EXPECT_EQ(block.votes(200)->total(), 1u);
  for (int i = 0; i < kBlockVoxels; ++i) {
    if (i != 3 && i != 200) {
      ASSERT_EQ(block.votes(i), nullptr) << i;
    }
  }
  EXPECT_EQ(block.indexOf(block.at(1, 2, 3)), Block::linear(1, 2, 3));
  EXPECT_EQ(Block::linear(1, 2, 3), 1 + 8 * 2 + 64 * 3);
}

// Renamed votes that name one label afterwards are one slot, as if they had been cast for it;
// a sum beyond a slot's count halves the voxel's counts first, as addVotes does.
TEST(Votes, RenamingFoldsVotesThatNowNameOneLabel) {
  VoxelVotes v;
  addVotes(&v, 4, 10);
  addVotes(&v, 7, 3);
  addVotes(&v, 9, 6);
  renameVotes(&v, [](int32_t l) { return l == 9 ? 2 : (l == 4 ? 12 : 5); });
  EXPECT_EQ(v.slots[0].label, 12);
  EXPECT_EQ(v.slots[0].count, 10u);
  EXPECT_EQ(v.slots[1].label, 5);
  EXPECT_EQ(v.slots[1].count, 3u);
  EXPECT_EQ(v.slots[2].label, 2);
  EXPECT_EQ(v.slots[2].count, 6u);
  renameVotes(&v, [](int32_t l) { return l == 2 ? 12 : l; });
  EXPECT_EQ(v.slots[0].label, 12);
  EXPECT_EQ(v.slots[0].count, 16u);
  EXPECT_EQ(v.slots[2].count, 0u);
  EXPECT_EQ(v.total(), 19u);

  VoxelVotes full;
  addVotes(&full, 1, 60000);
  addVotes(&full, 2, 10000);
  addVotes(&full, 3, 7);
  renameVotes(&full, [](int32_t l) { return l == 2 ? 1 : l; });
  EXPECT_EQ(full.slots[0].count, 35000u);  // (30000 + 5000)
  EXPECT_EQ(full.slots[2].count, 4u);      // 7 halved, rounding up
}

// TsdfMap::renameVotes renames every voxel's votes, or, when a label has no new one, none.
TEST(Votes, AMapRenamesAllItsVotesOrNone) {
  TsdfMap map(TsdfMap::Config{0.05f});
  Block* a = map.allocateBlock(BlockIndex(0, 0, 0));
  Block* b = map.allocateBlock(BlockIndex(1, 0, 0));
  addVotes(a->votesToWrite(5), 1, 3);
  addVotes(b->votesToWrite(9), 3, 2);
  addVotes(b->votesToWrite(9), 2, 4);
  EXPECT_THROW(map.renameVotes({0, 8, 0, 6}), Error);  // 2 has no new label
  EXPECT_EQ(a->votes(5)->slots[0].label, 1);
  EXPECT_THROW(map.renameVotes({0, 8, 7}), Error);  // nor 3
  EXPECT_EQ(b->votes(9)->slots[0].label, 3);
  map.renameVotes({0, 8, 6, 6});
  EXPECT_EQ(a->votes(5)->slots[0].label, 8);
  EXPECT_EQ(b->votes(9)->slots[0].label, 6);
  EXPECT_EQ(b->votes(9)->slots[0].count, 6u);
  EXPECT_EQ(b->votes(9)->total(), 6u);
}

TEST(Votes, EvictionIsWeakestFirstAndCounted) {
  VoxelVotes v;
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(addVote(&v, 1));
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(addVote(&v, 2));
  EXPECT_FALSE(addVote(&v, 3));
  for (int i = 0; i < 2; ++i) EXPECT_FALSE(addVote(&v, 4));
  // All four slots are full: label 5 evicts label 3 (count 1), the weakest.
  EXPECT_TRUE(addVote(&v, 5));
  int32_t labels[kVoteSlots];
  for (int i = 0; i < kVoteSlots; ++i) labels[i] = v.slots[i].label;
  EXPECT_EQ(std::count(labels, labels + kVoteSlots, 3), 0);
  EXPECT_EQ(std::count(labels, labels + kVoteSlots, 5), 1);
  EXPECT_EQ(argmaxLabel(v, [](int32_t l) { return l; }), 1);
  // Merging 2 and 4 into 1's rival: 2 + 4 pooled = 5 ties with 1 (5): smaller label wins.
  EXPECT_EQ(argmaxLabel(v, [](int32_t l) { return l == 4 ? 2 : l; }), 1);
  EXPECT_EQ(argmaxLabel(v, [](int32_t l) { return l == 1 ? 9 : (l == 4 || l == 5 ? 2 : l); }), 2);
  // The tie is reported: counts 5 (label 1), 3 (2), 2 (4), 1 (5).
  auto same = [](int32_t l) { return l; };
  auto four_into_two = [](int32_t l) { return l == 4 ? 2 : l; };
  auto five_into_four = [](int32_t l) { return l == 5 ? 4 : l; };
  bool tie = true;
  EXPECT_EQ(argmaxLabel(v, same, &tie), 1);
  EXPECT_FALSE(tie);
  EXPECT_EQ(argmaxLabel(v, four_into_two, &tie), 1);
  EXPECT_TRUE(tie);
  EXPECT_EQ(argmaxLabel(v, five_into_four, &tie), 1);
  EXPECT_FALSE(tie);  // 4 and 5 pooled: 3 ties with 2, below the winner's 5
  tie = true;
  EXPECT_EQ(argmaxLabel(VoxelVotes{}, same, &tie), 0);
  tie = true;
  EXPECT_EQ(argmaxLabel(static_cast<const VoxelVotes*>(nullptr), same, &tie), 0);
  EXPECT_FALSE(tie);
  EXPECT_FALSE(tie);
}

TEST(Integrator, RejectsMismatchedImages) {
  TsdfMap map(TsdfMap::Config{0.02f});
  ThreadPool pool(1);
  ProjectiveIntegrator integrator(IntegratorConfig{}, &pool);
  RgbdFrame frame;
  frame.camera = test::kinectCamera();
  frame.depth = DepthImage(320, 240);
  EXPECT_THROW(integrator.integrate(frame, Eigen::Isometry3d::Identity(), nullptr, &map), Error);
  EXPECT_THROW(TsdfMap(TsdfMap::Config{0.0f}), Error);
}

}  // namespace
}  // namespace panmap
