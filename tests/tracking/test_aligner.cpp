// Frame-to-model alignment against TSDFs of a rendered room and of analytic scenes.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "analytic_tsdf.h"
#include "panmap/core/error.h"
#include "panmap/core/thread_pool.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/trajectory.h"
#include "panmap/tracking/frame_to_model_aligner.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

constexpr double kDeg = M_PI / 180.0;

using Config = FrameToModelAligner::Config;

DepthImage renderDepth(const MeshRenderer& renderer, const Eigen::Isometry3d& T_W_C, bool noisy,
                       uint64_t seed) {
  DepthNoiseConfig noise;
  noise.enabled = noisy;
  return simulateDepth(renderer.render(test::kinectCamera(), T_W_C), noise, seed);
}

// Procedural room 1 mapped at 1 cm from every 6th frame of 60..120 of its survey, with exact
// depth and true poses. The odd frames in between are the test frames: views of a furnished
// corner for 61..93, then of one wall with little in front of it.
struct RoomScene {
  RoomScene() : room(generateRoom(1)), renderer(room.mesh), map(TsdfMap::Config{0.01f}) {
    SurveyConfig survey;
    survey.num_frames = 300;
    trajectory = planSurvey(room.mesh, survey, 1);
    ThreadPool pool(2);
    ProjectiveIntegrator integrator(IntegratorConfig{}, &pool);
    for (int k = 60; k <= 120; k += 6) {
      RgbdFrame frame;
      frame.camera = test::kinectCamera();
      frame.depth = renderDepth(renderer, trajectory[k].T_W_C, false, 0);
      integrator.integrate(frame, trajectory[k].T_W_C, nullptr, &map);
    }
  }
  ProceduralRoom room;
  MeshRenderer renderer;
  TsdfMap map;
  std::vector<StampedPose> trajectory;
};

const RoomScene& roomScene() {
  static const RoomScene* scene = new RoomScene();  // built once, shared by the tests
  return *scene;
}

// The known rigid offset of the SLAM pose: 2 cm and 1 degree about mixed axes.
Vector6d knownOffset() {
  Vector6d d;
  d << Eigen::Vector3d(0.012, -0.010, 0.012).normalized() * 0.02,
      Eigen::Vector3d(0.3, 1.0, -0.5).normalized() * (1.0 * kDeg);
  return d;
}

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return incrementBetween(a, b).head<3>().norm();
}

double rotationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return incrementBetween(a, b).tail<3>().norm();
}

TEST(Aligner, RecoversAKnownOffsetInTheRoom) {
  const RoomScene& scene = roomScene();
  FrameToModelAligner aligner(Config{});
  for (int k : {63, 75, 87}) {
    const Eigen::Isometry3d T_true = scene.trajectory[k].T_W_C;
    const Eigen::Isometry3d prior = applyIncrement(T_true, knownOffset());
    const AlignmentResult r = aligner.align(
        scene.map, renderDepth(scene.renderer, T_true, false, 0), test::kinectCamera(), prior);
    EXPECT_EQ(r.status, AlignmentStatus::kAccepted) << k << ": " << r.reason;
    EXPECT_TRUE(r.accepted);
    EXPECT_EQ(r.unconstrained_directions, 0);
    EXPECT_GT(r.points_used, 4000) << k;
    EXPECT_GT(r.inlier_ratio, 0.95) << k;
    EXPECT_LT(translationError(r.T_W_C, T_true), 0.001) << k;
    EXPECT_LT(rotationError(r.T_W_C, T_true), 0.1 * kDeg) << k;
    EXPECT_EQ(r.T_W_C.matrix(), applyIncrement(prior, r.delta).matrix());
  }
  EXPECT_EQ(aligner.counts()[static_cast<int>(AlignmentStatus::kAccepted)], 3);
}

// The per-cell residuals after the fit (AlignmentResult::cell_sum_m, cell_count), which the
// mapper's depth check reads: exact depth at the true pose agrees with the map everywhere;
// depth whose left half reads 8 mm long leaves the left cells behind the surface and the right
// ones in front: the fit turns the view to absorb part of the step (3.5 mm of 8 remain).
TEST(Aligner, CellResidualsShowADepthPatternTheFitCannotRemove) {
  const RoomScene& scene = roomScene();
  FrameToModelAligner aligner(Config{});
  const PinholeCamera camera = test::kinectCamera();
  const Eigen::Isometry3d T_true = scene.trajectory[75].T_W_C;
  auto halves = [&](const DepthImage& depth, double* left_m, double* right_m) {
    const AlignmentResult r = aligner.align(scene.map, depth, camera, T_true);
    ASSERT_TRUE(r.accepted) << r.reason;
    ASSERT_EQ(r.cell_sum_m.size(), static_cast<size_t>(kResidualCellsX * kResidualCellsY));
    ASSERT_EQ(r.cell_count.size(), r.cell_sum_m.size());
    double sum[2] = {0.0, 0.0};
    int count[2] = {0, 0};
    for (int c = 0; c < kResidualCellsX * kResidualCellsY; ++c) {
      const int half = c % kResidualCellsX < kResidualCellsX / 2 ? 0 : 1;
      sum[half] += r.cell_sum_m[c];
      count[half] += r.cell_count[c];
    }
    ASSERT_GT(count[0], 500);
    ASSERT_GT(count[1], 500);
    *left_m = sum[0] / count[0];
    *right_m = sum[1] / count[1];
  };
  const DepthImage exact = renderDepth(scene.renderer, T_true, false, 0);
  double left = 0.0, right = 0.0;
  halves(exact, &left, &right);
  EXPECT_LT(std::abs(left), 0.001);
  EXPECT_LT(std::abs(right), 0.001);
  DepthImage patterned = exact;
  for (int v = 0; v < patterned.height(); ++v) {
    for (int u = 0; u < patterned.width() / 2; ++u) {
      if (patterned(u, v) > 0) patterned(u, v) += 8;  // millimetres
    }
  }
  halves(patterned, &left, &right);
  EXPECT_LT(left - right, -0.0025);
  RecordProperty("left_minus_right_mm", std::to_string(1000.0 * (left - right)));
}

// Depth with the simulator's sensor model (Nguyen's axial noise, 2 to 6 mm at 1 to 3 m, 80 %
// of it correlated over 8-pixel windows, edge jitter and dropouts): a few millimetres.
TEST(Aligner, RecoversAKnownOffsetFromNoisyDepth) {
  const RoomScene& scene = roomScene();
  FrameToModelAligner aligner(Config{});
  std::vector<double> errors_m;
  for (int k = 61; k <= 93; k += 2) {
    const Eigen::Isometry3d T_true = scene.trajectory[k].T_W_C;
    const AlignmentResult r =
        aligner.align(scene.map, renderDepth(scene.renderer, T_true, true, k), test::kinectCamera(),
                      applyIncrement(T_true, knownOffset()));
    EXPECT_EQ(r.status, AlignmentStatus::kAccepted) << k << ": " << r.reason;
    EXPECT_LT(translationError(r.T_W_C, T_true), 0.003) << k;
    EXPECT_LT(rotationError(r.T_W_C, T_true), 0.1 * kDeg) << k;
    errors_m.push_back(translationError(r.T_W_C, T_true));
  }
  ASSERT_EQ(errors_m.size(), 17u);
  std::sort(errors_m.begin(), errors_m.end());
  EXPECT_LT(errors_m[errors_m.size() / 2], 0.0015);
  RecordProperty("median_error_mm", std::to_string(errors_m[errors_m.size() / 2] * 1e3));
}

// Looking at one wall the alignment corrects what the wall pins down and keeps the rest.
TEST(Aligner, WeakViewsAreCorrectedOnlyWhereConstrained) {
  const RoomScene& scene = roomScene();
  FrameToModelAligner aligner(Config{});
  const int k = 111;
  const Eigen::Isometry3d T_true = scene.trajectory[k].T_W_C;
  const Eigen::Isometry3d prior = applyIncrement(T_true, knownOffset());
  const AlignmentResult r = aligner.align(scene.map, renderDepth(scene.renderer, T_true, true, k),
                                          test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kAcceptedPartially) << r.reason;
  EXPECT_EQ(r.unconstrained_directions, 1);
  EXPECT_NE(r.reason.find("degenerate: 1 unconstrained"), std::string::npos) << r.reason;
  // Never worse than the prior, and the rotation is fixed.
  EXPECT_LT(translationError(r.T_W_C, T_true), translationError(prior, T_true));
  EXPECT_LT(rotationError(r.T_W_C, T_true), 0.1 * kDeg);
}

// A wall x = 2 as an analytic TSDF: its gradient has exactly no in-plane component, so the
// unconstrained directions are exactly the in-plane translations and the rotation about x.
class SingleWall : public ::testing::Test {
 protected:
  SingleWall() : map_(TsdfMap::Config{0.01f}) {
    test::fillAnalyticTsdf(
        Eigen::AlignedBox3f(Eigen::Vector3f(1.9f, -1.2f, -1.2f), Eigen::Vector3f(2.1f, 1.2f, 1.2f)),
        0.04f, [](const Eigen::Vector3f& p) { return 2.0f - p.x(); }, &map_);
    LabelledMesh mesh;
    test::addQuad(&mesh, {2, -3, -3}, {2, 3, -3}, {2, 3, 3}, {2, -3, 3}, 1, 1, 4);
    T_true_ = test::lookAt({0.8, 0.1, 0.2}, {2.0, 0.25, 0.05});  // oblique, 1.2 m away
    depth_ = renderDepth(MeshRenderer(mesh), T_true_, false, 0);
  }
  TsdfMap map_;
  Eigen::Isometry3d T_true_;
  DepthImage depth_;
};

TEST_F(SingleWall, CorrectsOnlyTheConstrainedDirections) {
  FrameToModelAligner aligner(Config{});
  Vector6d offset;
  offset << 0.02, -0.015, 0.01, 0.5 * kDeg, -0.8 * kDeg, 0.6 * kDeg;
  const Eigen::Isometry3d prior = applyIncrement(T_true_, offset);
  const AlignmentResult r = aligner.align(map_, depth_, test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kAcceptedPartially) << r.reason;
  EXPECT_TRUE(r.accepted);
  EXPECT_EQ(r.unconstrained_directions, 3);
  EXPECT_EQ(r.reason, "degenerate: 3 unconstrained directions, kept at the prior");
  EXPECT_LT(r.eigenvalues[2], 1e-12 * r.eigenvalues[5]);
  EXPECT_GT(r.eigenvalues[3], 0.01 * r.eigenvalues[5]);
  const Vector6d applied = incrementBetween(prior, r.T_W_C);
  // Unconstrained: y and z translation, rotation about x: exactly the prior.
  EXPECT_LT(std::abs(applied[1]), 1e-9);
  EXPECT_LT(std::abs(applied[2]), 1e-9);
  EXPECT_LT(std::abs(applied[3]), 1e-9);
  // Constrained: the distance to the wall and the two tilts are recovered.
  const Vector6d truth = -offset;
  EXPECT_NEAR(applied[0], truth[0], 0.001);
  EXPECT_NEAR(applied[4], truth[4], 0.1 * kDeg);
  EXPECT_NEAR(applied[5], truth[5], 0.1 * kDeg);
}

// The same through the whole pipeline: an oblique wall rendered and integrated (projective
// distances, 1 mm depth steps), so the unconstrained directions are found numerically.
TEST(IntegratedWall, CorrectsOnlyTheConstrainedDirections) {
  const Eigen::Vector3d n = Eigen::Vector3d(-1.0, 0.6, 0.0).normalized();  // toward the camera
  const Eigen::Vector3d u = Eigen::Vector3d(0.6, 1.0, 0.0).normalized(),
                        w = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3f c(2.0f, 0.0f, 0.0f), uf = u.cast<float>(), wf = w.cast<float>();
  LabelledMesh mesh;
  test::addQuad(&mesh, c - 3 * uf - 3 * wf, c + 3 * uf - 3 * wf, c + 3 * uf + 3 * wf,
                c - 3 * uf + 3 * wf, 1, 1, 40);
  const MeshRenderer renderer(mesh);
  TsdfMap map(TsdfMap::Config{0.01f});
  ThreadPool pool(2);
  ProjectiveIntegrator integrator(IntegratorConfig{}, &pool);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Isometry3d T = test::lookAt({0.7, 0.1 * i, 0.2 + 0.1 * i}, {2.0, 0.1, 0.0});
    RgbdFrame frame;
    frame.camera = test::kinectCamera();
    frame.depth = renderDepth(renderer, T, false, 0);
    integrator.integrate(frame, T, nullptr, &map);
  }
  const Eigen::Isometry3d T_true = test::lookAt({0.75, 0.05, 0.25}, {2.0, 0.1, 0.0});
  Vector6d offset;
  offset << 0.02, -0.015, 0.01, 0.5 * kDeg, -0.8 * kDeg, 0.6 * kDeg;
  const Eigen::Isometry3d prior = applyIncrement(T_true, offset);
  const AlignmentResult r = FrameToModelAligner(Config{}).align(
      map, renderDepth(renderer, T_true, false, 0), test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kAcceptedPartially) << r.reason;
  EXPECT_EQ(r.unconstrained_directions, 3);
  const Vector6d applied = incrementBetween(prior, r.T_W_C);
  // The prior is off by 1.6 cm in the wall's plane and 0.4 degrees about its normal; none
  // of that is touched (tens of microns, thousandths of a degree, from the eigenvectors'
  // numerical tilt) ...
  EXPECT_LT(std::abs(applied.head<3>().dot(u)), 1e-4);
  EXPECT_LT(std::abs(applied.head<3>().dot(w)), 1e-4);
  EXPECT_LT(std::abs(applied.tail<3>().dot(n)), 1e-4);
  // ... while the distance to the wall is recovered.
  EXPECT_NEAR(applied.head<3>().dot(n), -offset.head<3>().dot(n), 0.001);
}

TEST_F(SingleWall, RefusedWhenRemappingIsOff) {
  Config config;
  config.remap_degenerate = false;
  FrameToModelAligner aligner(config);
  Vector6d offset;
  offset << 0.02, 0.0, 0.0, 0.0, 0.0, 0.0;
  const Eigen::Isometry3d prior = applyIncrement(T_true_, offset);
  const AlignmentResult r = aligner.align(map_, depth_, test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kDegenerate);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "degenerate: 3 unconstrained directions");
  EXPECT_EQ(r.T_W_C.matrix(), prior.matrix());
  EXPECT_EQ(r.delta, Vector6d::Zero());
  EXPECT_NEAR(r.solved_delta[0], -0.02, 0.001);  // what it would have done
  EXPECT_EQ(aligner.counts()[static_cast<int>(AlignmentStatus::kDegenerate)], 1);
}

TEST_F(SingleWall, BadInputThrows) {
  FrameToModelAligner aligner(Config{});
  const PinholeCamera camera = test::kinectCamera();
  Eigen::Isometry3d nan_pose = T_true_;
  nan_pose.translation().x() = std::nan("");
  test::expectError([&] { aligner.align(map_, depth_, camera, nan_pose); }, {"T_W_C_prior"});
  Eigen::Isometry3d sheared = T_true_;
  sheared.linear()(0, 1) += 0.1;
  test::expectError([&] { aligner.align(map_, depth_, camera, sheared); }, {"T_W_C_prior"});
  test::expectError([&] { aligner.align(map_, DepthImage(320, 240), camera, T_true_); },
                    {"depth image is 320x240", "640x480"});
  test::expectError([&] { aligner.align(map_, DepthImage(), camera, T_true_); },
                    {"depth image is 0x0"});
  PinholeCamera bad = camera;
  bad.fx = 0.0;
  test::expectError([&] { aligner.align(map_, depth_, bad, T_true_); }, {"camera"});
  test::expectError([&] { aligner.align(map_, depth_, camera, T_true_, 0.0); }, {"depth_scale_m"});
  for (int count : aligner.counts()) EXPECT_EQ(count, 0);  // nothing was counted
}

TEST_F(SingleWall, NothingToAlignIsRefusedAndKeepsThePrior) {
  FrameToModelAligner aligner(Config{});
  const Eigen::Isometry3d prior = applyIncrement(T_true_, knownOffset());
  const TsdfMap empty_map(TsdfMap::Config{0.01f});
  AlignmentResult r = aligner.align(empty_map, depth_, test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kTooFewPoints);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason.rfind("too few points", 0), 0u) << r.reason;
  EXPECT_EQ(r.T_W_C.matrix(), prior.matrix());
  r = aligner.align(map_, DepthImage(640, 480, 0), test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kTooFewPoints);
  EXPECT_EQ(r.points_selected, 0);
  EXPECT_EQ(r.T_W_C.matrix(), prior.matrix());
  // Looking away from the wall: depth, but none of it on the map.
  const Eigen::Isometry3d away = test::lookAt({0.8, 0.1, 0.2}, {-1.0, 0.1, 0.2});
  LabelledMesh mesh;
  test::addQuad(&mesh, {-1, -3, -3}, {-1, 3, -3}, {-1, 3, 3}, {-1, -3, 3}, 1, 1, 4);
  r = aligner.align(map_, renderDepth(MeshRenderer(mesh), away, false, 0), test::kinectCamera(),
                    away);
  EXPECT_EQ(r.status, AlignmentStatus::kTooFewPoints);
  EXPECT_GT(r.points_selected, 4000);
  EXPECT_EQ(r.points_used, 0);
  EXPECT_EQ(r.T_W_C.matrix(), away.matrix());
  EXPECT_EQ(aligner.counts()[static_cast<int>(AlignmentStatus::kTooFewPoints)], 3);
}

TEST(Aligner, RefusesLowInlierRatiosAndLargeCorrections) {
  const RoomScene& scene = roomScene();
  const int k = 75;
  const Eigen::Isometry3d T_true = scene.trajectory[k].T_W_C;
  const Eigen::Isometry3d prior = applyIncrement(T_true, knownOffset());
  const DepthImage noisy = renderDepth(scene.renderer, T_true, true, k);
  Config strict;
  strict.min_inlier_ratio = 0.99;  // noisy depth keeps ~96 % within 2 cm
  AlignmentResult r =
      FrameToModelAligner(strict).align(scene.map, noisy, test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kLowInlierRatio);
  EXPECT_EQ(r.reason.rfind("low inlier ratio: 0.9", 0), 0u) << r.reason;
  EXPECT_EQ(r.T_W_C.matrix(), prior.matrix());
  Config cautious;
  cautious.max_correction_translation_m = 0.01;  // the offset is 2 cm
  r = FrameToModelAligner(cautious).align(scene.map, noisy, test::kinectCamera(), prior);
  EXPECT_EQ(r.status, AlignmentStatus::kCorrectionTooLarge);
  EXPECT_EQ(r.reason.rfind("correction too large: 0.02", 0), 0u) << r.reason;
  EXPECT_EQ(r.T_W_C.matrix(), prior.matrix());
  EXPECT_NEAR(r.solved_delta.head<3>().norm(), 0.02, 0.003);
}

TEST(Aligner, SameInputSameBitsOnAnyThread) {
  const RoomScene& scene = roomScene();
  const int k = 81;
  const Eigen::Isometry3d T_true = scene.trajectory[k].T_W_C;
  const DepthImage depth = renderDepth(scene.renderer, T_true, true, k);
  const Eigen::Isometry3d prior = applyIncrement(T_true, knownOffset());
  auto run = [&] {
    return FrameToModelAligner(Config{}).align(scene.map, depth, test::kinectCamera(), prior);
  };
  const AlignmentResult first = run();
  ASSERT_TRUE(first.accepted);
  AlignmentResult a, b;
  std::thread ta([&] { a = run(); }), tb([&] { b = run(); });  // two at once
  ta.join();
  tb.join();
  for (const AlignmentResult* r : {&a, &b}) {
    EXPECT_EQ(
        std::memcmp(r->T_W_C.matrix().data(), first.T_W_C.matrix().data(), sizeof(double) * 16), 0);
    EXPECT_EQ(r->iterations, first.iterations);
    EXPECT_EQ(r->eigenvalues, first.eigenvalues);
    EXPECT_EQ(r->inlier_ratio, first.inlier_ratio);
  }
}

TEST(AlignerConfig, ChecksNameTheField) {
  auto expectBad = [](const std::function<void(Config*)>& change, const std::string& field) {
    Config config;
    change(&config);
    test::expectError([&] { FrameToModelAligner aligner(config); }, {field});
  };
  expectBad([](Config* c) { c->level_strides_px.clear(); }, "level_strides_px");
  expectBad([](Config* c) { c->level_strides_px = {8, 0}; }, "level_strides_px");
  expectBad([](Config* c) { c->max_iterations = 0; }, "max_iterations");
  expectBad([](Config* c) { c->robust_scale_m = 0.0; }, "robust_scale_m");
  expectBad([](Config* c) { c->point_sigma_m = -1.0; }, "point_sigma_m");
  expectBad([](Config* c) { c->prior_sigma_translation_m = 0.0; }, "prior_sigma_translation_m");
  expectBad([](Config* c) { c->prior_sigma_rotation_rad = std::nan(""); },
            "prior_sigma_rotation_rad");
  expectBad([](Config* c) { c->max_depth_m = c->min_depth_m; }, "max_depth_m");
  expectBad([](Config* c) { c->min_points = 0; }, "min_points");
  expectBad([](Config* c) { c->inlier_distance_m = 0.0; }, "inlier_distance_m");
  expectBad([](Config* c) { c->min_inlier_ratio = 1.5; }, "min_inlier_ratio");
  expectBad([](Config* c) { c->min_relative_eigenvalue = 0.0; }, "min_relative_eigenvalue");
  expectBad([](Config* c) { c->max_correction_translation_m = 0.0; },
            "max_correction_translation_m");
  expectBad([](Config* c) { c->max_correction_rotation_rad = -0.1; },
            "max_correction_rotation_rad");
  EXPECT_NO_THROW(FrameToModelAligner aligner(Config{}));
}

}  // namespace
}  // namespace panmap
