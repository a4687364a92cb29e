// Mapped objects (DESIGN 4): hand-built voxel states with exact expectations, a rendered yawed
// box against its analytic boxes, and the objects.json round trip.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "panmap/core/error.h"
#include "panmap/mapper/final_labels.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mapper/objects.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/segmenter_noise.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// 0.25 m voxels: every centre (k + 0.5) * 0.25 and every expected value below is exact in
// binary floating point.
constexpr float kVoxel = 0.25f;
constexpr float kBand = kObjectSurfaceBandVoxels * kVoxel;

// Sets the voxel at global grid index g (allocating its block).
void setVoxel(TsdfMap* map, const Eigen::Vector3i& g, float sdf_m, float weight,
              std::initializer_list<LabelVote> votes) {
  const BlockIndex b(static_cast<int>(std::floor(g.x() / 8.0)),
                     static_cast<int>(std::floor(g.y() / 8.0)),
                     static_cast<int>(std::floor(g.z() / 8.0)));
  const Eigen::Vector3i l = g - kBlockSide * b;
  Block* block = map->allocateBlock(b);
  Voxel& v = block->at(l.x(), l.y(), l.z());
  v.sdf_m = sdf_m;
  v.weight = weight;
  if (votes.size() == 0) return;
  VoxelVotes* slots = block->votesToWrite(Block::linear(l.x(), l.y(), l.z()));
  int k = 0;
  for (const LabelVote& vote : votes) slots->slots[k++] = vote;
}

// Super-points 1..5; 4 was merged into 1. 1 and 2 form instance 7 (chair), 3 is instance 9
// (cabinet), 5 is wall without instance.
SuperpointTracker makeTracker() {
  SuperpointTracker tracker{SuperpointConfig{}};
  SuperpointTracker::Snapshot s;
  s.parents = {0, 1, 2, 3, 1, 5};
  s.states[1].class_counts = {{5, 4.0}};
  s.states[1].instance_counts = {{7, 3}, {2, 1}};  // stability 3 / (4 + 1) = 0.6
  s.states[2].class_counts = {{5, 2.0}, {0, 1.0}};
  s.states[2].instance_counts = {{7, 1}};  // 1 / 2 = 0.5
  s.states[3].class_counts = {{3, 6.0}};
  s.states[3].instance_counts = {{9, 4}};  // 4 / 5 = 0.8
  s.states[5].class_counts = {{1, 9.0}};
  s.next_instance = 10;
  tracker.restore(s);
  return tracker;
}

// Instance 7: a 4 x 2 x 2 slab of voxels, x 0..3, y 0..1, z 0 (super-point 4, i.e. 1) and z 1
// (super-point 2). Instance 9: a diagonal bar |i - j| <= 1, 0 <= i + j <= 10 at y offset 8
// (another block), z 0. Plus voxels that must not count.
TsdfMap makeMap() {
  TsdfMap map(TsdfMap::Config{kVoxel});
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 2; ++y) {
      // The band is inclusive: |sdf| = kObjectSurfaceBandVoxels still counts.
      setVoxel(&map, {x, y, 0}, x == 0 ? -kBand : 0.1f, 1.0f, {{4, 5}, {2, 1}});
      setVoxel(&map, {x, y, 1}, kBand, 2.0f, {{2, 3}, {4, 1}, {5, 1}});
    }
  }
  for (int i = 0; i <= 6; ++i) {
    for (int j = 0; j <= 6; ++j) {
      if (std::abs(i - j) <= 1 && i + j <= 10) setVoxel(&map, {i, j + 8, 0}, 0.0f, 1.0f, {{3, 1}});
    }
  }
  setVoxel(&map, {5, 0, 0}, -1.01f * kBand, 1.0f, {{1, 9}});  // outside the surface band
  setVoxel(&map, {6, 0, 0}, 0.0f, 0.0f, {{1, 9}});            // never observed
  setVoxel(&map, {7, 0, 0}, 0.0f, 1.0f, {{5, 2}, {1, 1}});    // wall wins the argmax
  setVoxel(&map, {-1, 0, 0}, 0.0f, 1.0f, {});                 // no vote
  return map;
}

TEST(Objects, HandBuiltFrameCountObjects) {
  const TsdfMap map = makeMap();
  const SuperpointTracker tracker = makeTracker();
  const std::vector<MappedObject> objects = computeObjects(map, tracker, nullptr);
  ASSERT_EQ(objects.size(), 2u);

  const MappedObject& chair = objects[0];
  EXPECT_EQ(chair.id, 7);
  EXPECT_EQ(chair.class_id, 5);
  EXPECT_EQ(chair.num_voxels, 16);
  EXPECT_EQ(chair.superpoints, (std::vector<int32_t>{1, 2}));
  EXPECT_FLOAT_EQ(chair.confidence, 0.55f);  // (8 * 0.6 + 8 * 0.5) / 16
  EXPECT_EQ(chair.centroid_W, Eigen::Vector3d(0.5, 0.25, 0.25));
  EXPECT_EQ(chair.aabb_min_W, Eigen::Vector3d(0.0, 0.0, 0.0));
  EXPECT_EQ(chair.aabb_max_W, Eigen::Vector3d(1.0, 0.5, 0.5));
  EXPECT_EQ(chair.obb_center_W, Eigen::Vector3d(0.5, 0.25, 0.25));
  EXPECT_EQ(chair.obb_extent_m, Eigen::Vector3d(1.0, 0.5, 0.5));
  EXPECT_EQ(chair.q_W_B.coeffs(), Eigen::Quaterniond::Identity().coeffs());

  // The bar's footprint hull is (0,0) (1,0) (5,4) (5,5) (4,5) (0,1) in cells: the
  // minimum-area rectangle lies along the diagonal, 10/sqrt2 x sqrt2 cells between centres,
  // plus a cell's width along a 45 degree axis (sqrt2 cells).
  const MappedObject& cabinet = objects[1];
  EXPECT_EQ(cabinet.id, 9);
  EXPECT_EQ(cabinet.class_id, 3);
  EXPECT_EQ(cabinet.num_voxels, 16);
  EXPECT_EQ(cabinet.superpoints, (std::vector<int32_t>{3}));
  EXPECT_FLOAT_EQ(cabinet.confidence, 0.8f);
  EXPECT_NEAR((cabinet.centroid_W - Eigen::Vector3d(0.75, 2.75, 0.125)).norm(), 0.0, 1e-12);
  EXPECT_EQ(cabinet.aabb_min_W, Eigen::Vector3d(0.0, 2.0, 0.0));
  EXPECT_EQ(cabinet.aabb_max_W, Eigen::Vector3d(1.5, 3.5, 0.25));
  const double r2 = std::sqrt(2.0);
  EXPECT_NEAR(cabinet.obb_extent_m.x(), (10.0 / r2 + r2) * kVoxel, 1e-12);
  EXPECT_NEAR(cabinet.obb_extent_m.y(), 2.0 * r2 * kVoxel, 1e-12);
  EXPECT_DOUBLE_EQ(cabinet.obb_extent_m.z(), kVoxel);
  EXPECT_NEAR((cabinet.obb_center_W - Eigen::Vector3d(0.75, 2.75, 0.125)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(cabinet.q_W_B.w(), std::cos(M_PI / 8), 1e-12);
  EXPECT_NEAR(cabinet.q_W_B.z(), std::sin(M_PI / 8), 1e-12);
  EXPECT_EQ(cabinet.q_W_B.x(), 0.0);
  EXPECT_EQ(cabinet.q_W_B.y(), 0.0);
}

TEST(Objects, NoInstanceWithoutAThingClass) {
  // Frame counting joined an unlabelled and a wall super-point to chair instance 7 (one thing
  // mask over them): live objects of class 0 and "wall" came of such joins.
  SuperpointTracker tracker{SuperpointConfig{}};
  SuperpointTracker::Snapshot s;
  s.parents = {0, 1, 2, 3};
  s.states[1].class_counts = {{5, 4.0}};
  s.states[1].instance_counts = {{7, 3}};
  s.states[2].class_counts = {{0, 5.0}, {5, 1.0}};
  s.states[2].instance_counts = {{7, 1}};
  s.states[3].class_counts = {{1, 6.0}};
  s.states[3].instance_counts = {{7, 2}};
  s.next_instance = 8;
  tracker.restore(s);
  EXPECT_EQ(finalLabels(1, tracker, nullptr).instance, 7);
  EXPECT_EQ(finalLabels(2, tracker, nullptr).semantic, 0);
  EXPECT_EQ(finalLabels(2, tracker, nullptr).instance, 0);
  EXPECT_EQ(finalLabels(3, tracker, nullptr).semantic, 1);
  EXPECT_EQ(finalLabels(3, tracker, nullptr).instance, 0);
  TsdfMap map(TsdfMap::Config{kVoxel});
  for (int x = 0; x < 4; ++x) {
    setVoxel(&map, {x, 0, 0}, 0.0f, 1.0f, {{1, 2}});
    setVoxel(&map, {x, 1, 0}, 0.0f, 1.0f, {{2, 2}});
    setVoxel(&map, {x, 2, 0}, 0.0f, 1.0f, {{3, 2}});
  }
  std::vector<MappedObject> objects = computeObjects(map, tracker, nullptr);
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].id, 7);
  EXPECT_EQ(objects[0].class_id, 5);
  EXPECT_EQ(objects[0].num_voxels, 4);  // the chair's own voxels only
  // The optimiser's labels decide for the super-points they name.
  GraphLabels labels;
  labels.semantic[2] = 5;
  labels.instance[2] = 7;
  EXPECT_EQ(finalLabels(2, tracker, &labels).instance, 7);
  objects = computeObjects(map, tracker, &labels);
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].num_voxels, 8);
}

TEST(Objects, OnlyObjectsTheMeshCarriesAreKept) {
  std::vector<MappedObject> objects(3);
  objects[0].id = 4;
  objects[1].id = 9;  // no vertex carries it
  objects[2].id = 12;
  EXPECT_EQ(keepObjectsOnMesh({4, 12}, &objects), 1u);
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[0].id, 4);
  EXPECT_EQ(objects[1].id, 12);
  EXPECT_EQ(keepObjectsOnMesh({0, 4, 4, 12}, &objects), 0u);
  EXPECT_EQ(keepObjectsOnMesh({}, &objects), 2u);
  EXPECT_TRUE(objects.empty());
}

// A square footprint turned by 45 degrees (a diamond of voxels |i - 3| + |j - 3| <= 3): PCA of
// its centres is isotropic and names no axis; the minimum-area rectangle is the diamond itself,
// half the area of the axis-aligned box. A square takes the positive yaw of its two axes.
TEST(Objects, SquareFootprintGetsItsTightYaw) {
  TsdfMap map(TsdfMap::Config{kVoxel});
  for (int i = 0; i <= 6; ++i) {
    for (int j = 0; j <= 6; ++j) {
      if (std::abs(i - 3) + std::abs(j - 3) <= 3) setVoxel(&map, {i, j, 2}, 0.0f, 1.0f, {{3, 1}});
    }
  }
  const std::vector<MappedObject> objects = computeObjects(map, makeTracker(), nullptr);
  ASSERT_EQ(objects.size(), 1u);
  const MappedObject& o = objects[0];
  EXPECT_EQ(o.num_voxels, 25);
  const double r2 = std::sqrt(2.0);
  EXPECT_NEAR(o.obb_extent_m.x(), 4.0 * r2 * kVoxel, 1e-12);  // 3 sqrt2 between centres + sqrt2
  EXPECT_NEAR(o.obb_extent_m.y(), 4.0 * r2 * kVoxel, 1e-12);
  EXPECT_NEAR(o.q_W_B.w(), std::cos(M_PI / 8), 1e-12);
  EXPECT_NEAR(o.q_W_B.z(), std::sin(M_PI / 8), 1e-12);
  EXPECT_NEAR((o.obb_center_W - Eigen::Vector3d(0.875, 0.875, 0.625)).norm(), 0.0, 1e-12);
  EXPECT_EQ(o.aabb_min_W, Eigen::Vector3d(0.0, 0.0, 0.5));
  EXPECT_EQ(o.aabb_max_W, Eigen::Vector3d(1.75, 1.75, 0.75));
}

// makeTracker() gave instances up to 9; the optimiser's graph was taken when the largest was 7,
// and it made instances 8 and 9 of its own. Super-point 3, made since and not named, counts
// frame instance 9: reported as they are, it and the optimiser's 9 would be one object.
TEST(FitLabels, FrameCountIdsGivenSinceTheGraphMoveAboveTheAnswers) {
  const TsdfMap map = makeMap();
  const SuperpointTracker tracker = makeTracker();
  GraphLabels labels;
  labels.semantic = {{1, 5}, {2, 24}};
  labels.instance = {{1, 8}, {2, 9}};
  labels.instance_confidence = {{8, 0.25f}, {9, 0.5f}};
  labels.instance_evidence[9].area_m2 = 2.0f;
  const GraphLabels fitted = fitLabelsToMap(labels, 7, tracker);
  EXPECT_EQ(fitted.semantic, labels.semantic);
  // The answer's ids as it gave them; super-point 3's 9 moved by 9 - 7 = 2 (the answer's
  // largest id less the graph's); super-point 5 has no instance, 4 is part of 1.
  EXPECT_EQ(fitted.instance, (std::map<int32_t, int32_t>{{1, 8}, {2, 9}, {3, 11}}));
  EXPECT_EQ(fitted.instance_confidence, labels.instance_confidence);
  ASSERT_EQ(fitted.instance_evidence.size(), 1u);
  EXPECT_EQ(fitted.instance_evidence.at(9).area_m2, 2.0f);
  std::vector<int32_t> ids;
  for (const MappedObject& o : computeObjects(map, tracker, &fitted)) ids.push_back(o.id);
  EXPECT_EQ(ids, (std::vector<int32_t>{8, 9, 11}));
  // Unfitted, super-point 3 joins the optimiser's instance 9.
  ids.clear();
  for (const MappedObject& o : computeObjects(map, tracker, &labels)) ids.push_back(o.id);
  EXPECT_EQ(ids, (std::vector<int32_t>{8, 9}));
}

// One answer, published again and again while the tracker gives more ids: every id stays (they
// moved above the tracker's newest id at each publish, and the ids they left went to other
// objects).
TEST(FitLabels, AnAnswersIdsStayWhileTheTrackerGivesMore) {
  SuperpointTracker tracker = makeTracker();
  GraphLabels labels;
  labels.instance = {{1, 8}, {2, 9}};
  labels.instance_confidence = {{8, 0.25f}, {9, 0.5f}};
  const GraphLabels first = fitLabelsToMap(labels, 7, tracker);
  SuperpointTracker::Snapshot later = tracker.snapshot();
  later.next_instance = 40;
  tracker.restore(later);
  const GraphLabels again = fitLabelsToMap(labels, 7, tracker);
  EXPECT_EQ(again.instance, first.instance);
  EXPECT_EQ(again.instance_confidence, first.instance_confidence);
}

// Kept frame-count ids (at most the graph's largest) never move, and when the answer made no id
// above the graph's, nothing does.
TEST(FitLabels, WithoutAClashTheLabelsStayAsTheyAre) {
  const SuperpointTracker tracker = makeTracker();
  GraphLabels labels;
  labels.semantic = {{1, 5}, {2, 5}, {3, 3}};
  labels.instance = {{1, 7}, {2, 10}, {3, 9}};
  labels.instance_confidence = {{7, 0.5f}, {10, 0.25f}};
  const GraphLabels fitted = fitLabelsToMap(labels, 9, tracker);
  EXPECT_EQ(fitted.instance, labels.instance);
  EXPECT_EQ(fitted.instance_confidence, labels.instance_confidence);
  // Super-point 3 unnamed, its frame instance 9 above a graph whose largest was 8: it moves
  // above the answer's 10.
  labels.instance.erase(3);
  EXPECT_EQ(fitLabelsToMap(labels, 8, tracker).instance,
            (std::map<int32_t, int32_t>{{1, 7}, {2, 10}, {3, 11}}));
  labels.instance = {{1, 7}};
  labels.instance_confidence = {{7, 0.5f}};
  EXPECT_EQ(fitLabelsToMap(labels, 8, tracker).instance, labels.instance);
}

TEST(Objects, OptimisedLabelsOverrideFrameCounts) {
  const TsdfMap map = makeMap();
  const SuperpointTracker tracker = makeTracker();
  GraphLabels labels;
  // Super-point 2 becomes its own object 11 of class 24; 1 keeps its frame-count labels.
  labels.semantic = {{2, 24}, {3, 3}};
  labels.instance = {{2, 11}, {3, 9}};
  labels.instance_confidence = {{11, 0.25f}, {7, 0.875f}};
  std::vector<MappedObject> objects = computeObjects(map, tracker, &labels);
  ASSERT_EQ(objects.size(), 3u);
  EXPECT_EQ(objects[0].id, 7);
  EXPECT_EQ(objects[0].num_voxels, 8);
  EXPECT_EQ(objects[0].superpoints, (std::vector<int32_t>{1}));
  EXPECT_EQ(objects[0].confidence, 0.875f);
  EXPECT_EQ(objects[0].aabb_max_W, Eigen::Vector3d(1.0, 0.5, 0.25));
  EXPECT_EQ(objects[1].id, 9);
  EXPECT_FLOAT_EQ(objects[1].confidence, 0.8f);  // not in instance_confidence: frame counts
  EXPECT_EQ(objects[2].id, 11);
  EXPECT_EQ(objects[2].class_id, 24);
  EXPECT_EQ(objects[2].num_voxels, 8);
  EXPECT_EQ(objects[2].confidence, 0.25f);
  EXPECT_EQ(objects[2].aabb_min_W, Eigen::Vector3d(0.0, 0.0, 0.25));
  EXPECT_EQ(objects[2].centroid_W, Eigen::Vector3d(0.5, 0.25, 0.375));

  // All three super-points in instance 7: the class of most voxels (cabinet, 16 of 32) wins.
  labels.instance = {{2, 7}, {3, 7}};
  objects = computeObjects(map, tracker, &labels);
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].class_id, 3);
  EXPECT_EQ(objects[0].num_voxels, 32);
  EXPECT_EQ(objects[0].superpoints, (std::vector<int32_t>{1, 2, 3}));
  EXPECT_EQ(objects[0].aabb_min_W, Eigen::Vector3d(0.0, 0.0, 0.0));
  EXPECT_EQ(objects[0].aabb_max_W, Eigen::Vector3d(1.5, 3.5, 0.5));
}

// Without an optimised confidence, an instance is scored as the optimiser scores its own: the
// logistic model of its voxels and of the class scores P_nu^C of its super-points, each
// super-point's score of its own class counting as support. Instance 9 keeps the optimiser's.
TEST(Objects, InstancesWithoutAnOptimisedConfidenceGetTheOptimisersModel) {
  const TsdfMap map = makeMap();
  const SuperpointTracker tracker = makeTracker();
  GraphAccumulator graph{GraphConfig{}};
  GraphAccumulator::Snapshot snapshot;
  snapshot.scores[1] = {{5, 40.0}, {1, 8.0}};  // chair super-point, seen as wall sometimes
  snapshot.scores[2] = {{5, 8.0}, {3, 8.0}};
  snapshot.scores[3] = {{3, 64.0}};
  graph.restore(snapshot);
  OptimiserConfig::Objects model;
  model.share = 0.5;  // the default holds it at 0: here it must count too
  const ObjectScoring scoring{&graph, model};
  GraphLabels labels;
  labels.instance_confidence = {{9, 0.125f}};
  const std::vector<MappedObject> objects = computeObjects(map, tracker, &labels, &scoring);
  ASSERT_EQ(objects.size(), 2u);
  // Chair: 16 voxels of 0.25 m (1 m2, log10 0); score of class 5: 40 + 8 of 64 in all.
  const MappedObject& chair = objects[0];
  EXPECT_EQ(chair.id, 7);
  const double z = model.bias + model.support * std::log2(48.0 / 16.0) + model.share * 0.75;
  EXPECT_FLOAT_EQ(chair.confidence, static_cast<float>(1.0 / (1.0 + std::exp(-z))));
  EXPECT_FLOAT_EQ(chair.evidence.area_m2, 1.0f);
  EXPECT_FLOAT_EQ(chair.evidence.support, 3.0f);
  EXPECT_FLOAT_EQ(chair.evidence.class_share, 0.75f);
  EXPECT_EQ(objects[1].id, 9);
  EXPECT_EQ(objects[1].confidence, 0.125f);
  EXPECT_EQ(objects[1].evidence, ObjectEvidence{});
  // Without scoring: the frame-count stability of HandBuiltFrameCountObjects.
  EXPECT_FLOAT_EQ(computeObjects(map, tracker, &labels)[0].confidence, 0.55f);
}

TEST(Objects, JsonRoundTripIsExactAndReadableByPanmapEval) {
  const TsdfMap map = makeMap();
  const SuperpointTracker tracker = makeTracker();
  std::vector<MappedObject> objects = computeObjects(map, tracker, nullptr);
  objects[0].confidence = 1.0f / 3.0f;  // not a short decimal
  test::TempDir dir;
  writeObjectsJson(dir.path("objects.json"), objects, 123456789);
  int64_t utime = 0;
  const std::vector<MappedObject> back = readObjectsJson(dir.path("objects.json"), &utime);
  EXPECT_EQ(utime, 123456789);
  EXPECT_EQ(back, objects);  // every field, exactly
  // What panmap-eval --confidences reads: {"objects": [{"id", "confidence"}]}.
  std::ifstream in(dir.path("objects.json"));
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j["objects"].is_array());
  EXPECT_EQ(j["objects"][0]["id"].get<int32_t>(), 7);
  EXPECT_EQ(static_cast<float>(j["objects"][0]["confidence"].get<double>()), 1.0f / 3.0f);
  EXPECT_EQ(j["objects"][0]["class_name"], "chair");
  EXPECT_EQ(j["objects"][1]["class_name"], "cabinet");
  EXPECT_EQ(j["objects"][1]["obb_orientation_wxyz"].size(), 4u);

  std::ofstream(dir.path("bad.json")) << R"({"objects": [{"id": 3, "class": 5}]})";
  test::expectError([&] { readObjectsJson(dir.path("bad.json")); },
                    {"bad.json", "object 0", "confidence"});
  test::expectError([&] { writeObjectsJson(dir.path("no/such/dir.json"), objects, 0); },
                    {"no/such/dir.json", "cannot write"});
}

// Appends a box of size (sx, sy, sz) standing on z = 0, centred at (cx, cy), turned by `yaw`
// about z.
void addYawedBox(LabelledMesh* mesh, const Eigen::Vector2f& centre, const Eigen::Vector3f& size,
                 float yaw, int32_t instance, int32_t semantic) {
  const Eigen::Vector2f u(std::cos(yaw), std::sin(yaw)), v(-u.y(), u.x());
  auto P = [&](int i, int j, int k) {
    const Eigen::Vector2f xy =
        centre + (i ? 0.5f : -0.5f) * size.x() * u + (j ? 0.5f : -0.5f) * size.y() * v;
    return Eigen::Vector3f(xy.x(), xy.y(), k ? size.z() : 0.0f);
  };
  test::addQuad(mesh, P(0, 0, 0), P(0, 1, 0), P(0, 1, 1), P(0, 0, 1), instance, semantic, 8);
  test::addQuad(mesh, P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1), instance, semantic, 8);
  test::addQuad(mesh, P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1), instance, semantic, 8);
  test::addQuad(mesh, P(0, 1, 0), P(1, 1, 0), P(1, 1, 1), P(0, 1, 1), instance, semantic, 8);
  test::addQuad(mesh, P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1), instance, semantic, 8);
}

// A 0.8 x 0.4 x 0.51 m cabinet turned by 30 degrees on a floor, mapped with 2 cm voxels from a
// circle of views with exact depth and ground-truth masks. Votes land in the voxels holding
// surface points; the boxes enclose those voxels' cells, so each side of a box lies between the
// true face and the farthest a cell holding a face point can reach: one voxel along a world
// axis, 4h in total along an axis at 30 degrees (h = v/2 (cos 30 + sin 30), a cell's half width
// along it, once from the point to the centre and once to the cell's far side). The top sits
// mid-voxel (0.51 m) so that one layer of voxels holds it.
TEST(Objects, RenderedYawedBoxMatchesItsAnalyticBoxes) {
  constexpr double kYaw = M_PI / 6, kHeight = 0.51;
  LabelledMesh scene;
  test::addQuad(&scene, {-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}, 1, 2, 30);  // floor
  addYawedBox(&scene, {0.0f, 0.0f}, {0.8f, 0.4f, static_cast<float>(kHeight)},
              static_cast<float>(kYaw), 2, 3);
  const MeshRenderer renderer(scene);
  SegmenterNoise segmenter(SegmenterNoiseConfig::fromPreset("clean"), 1);
  std::map<int32_t, InstanceInfo> infos;
  infos[1] = InstanceInfo{2, 6.0f, true};
  infos[2] = InstanceInfo{3, 0.8f, false};
  MapperConfig config;
  config.map.voxel_size_m = 0.02f;
  Mapper mapper(config);
  constexpr int kViews = 12;
  for (int k = 0; k < kViews; ++k) {
    const double a = 2.0 * M_PI * k / kViews;
    const Eigen::Isometry3d T_W_C =
        test::lookAt(Eigen::Vector3d(1.6 * std::cos(a), 1.6 * std::sin(a), 1.3), {0.0, 0.0, 0.2});
    const RenderedView view = renderer.render(test::kinectCamera(), T_W_C);
    DepthNoiseConfig exact;
    exact.enabled = false;
    RgbdFrame frame;
    frame.camera = test::kinectCamera();
    frame.utime = k * 33333;
    frame.frame_id = k;
    frame.depth = simulateDepth(view, exact, 0);
    frame.color = view.color;
    const PanopticFrame panoptic = segmenter.segment(view.instance, view.semantic, k, infos);
    mapper.integrate(frame, T_W_C, &panoptic);
  }
  const std::vector<MappedObject> objects = computeObjects(mapper);
  // The floor is stuff: the cabinet is the only object.
  ASSERT_EQ(objects.size(), 1u);
  const MappedObject& box = objects[0];
  EXPECT_EQ(box.class_id, 3);
  EXPECT_GT(box.confidence, 0.5f);
  EXPECT_LE(box.confidence, 1.0f);

  const double v = config.map.voxel_size_m;
  const double eps = 0.005;  // 1 mm depth steps, ~3 mm pixel footprint at the box's edges
  const double h = 0.5 * v * (std::cos(kYaw) + std::sin(kYaw));
  const Eigen::Vector3d half(0.4 * std::cos(kYaw) + 0.2 * std::sin(kYaw),  // 0.4464
                             0.4 * std::sin(kYaw) + 0.2 * std::cos(kYaw),  // 0.3732
                             0.5 * kHeight);
  const Eigen::Vector3d centre(0.0, 0.0, 0.5 * kHeight);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(box.aabb_min_W[k], centre[k] - half[k] + eps) << k;
    EXPECT_GE(box.aabb_min_W[k], centre[k] - half[k] - v - eps) << k;
    EXPECT_GE(box.aabb_max_W[k], centre[k] + half[k] - eps) << k;
    EXPECT_LE(box.aabb_max_W[k], centre[k] + half[k] + v + eps) << k;
  }
  const Eigen::Vector3d size(0.8, 0.4, kHeight);
  const Eigen::Vector3d reach(4 * h, 4 * h, 2 * v);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GE(box.obb_extent_m[k], size[k] - eps) << k;
    EXPECT_LE(box.obb_extent_m[k], size[k] + reach[k] + eps) << k;
    EXPECT_NEAR(box.obb_center_W[k], centre[k], 0.5 * reach[k] + eps) << k;
  }
  const Eigen::Vector3d x_B = box.q_W_B * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(x_B.y(), x_B.x()) * 180.0 / M_PI, 30.0, 1.0);
  EXPECT_NEAR(x_B.z(), 0.0, 1e-12);
  // A plane with unit normal n crosses (|n_x| + |n_y| + |n_z|) / v^2 voxels per square metre:
  // 1.366 for the sides (1.2 m^2), 1 for the top (0.32 m^2). The centroid's xy is the box's
  // by symmetry; its height is the crossing-weighted mean of the faces' heights.
  const double w_side = std::cos(kYaw) + std::sin(kYaw);
  const double area_side = 2.0 * (0.8 + 0.4) * kHeight, area_top = 0.8 * 0.4;
  EXPECT_NEAR(box.centroid_W.x(), 0.0, 0.5 * v);
  EXPECT_NEAR(box.centroid_W.y(), 0.0, 0.5 * v);
  EXPECT_NEAR(
      box.centroid_W.z(),
      (w_side * area_side * 0.5 * kHeight + area_top * kHeight) / (w_side * area_side + area_top),
      v);
  // Their number, within 15% (the faces' borders add partly crossed voxels).
  const double expected_voxels = (w_side * area_side + area_top) / (v * v);
  EXPECT_NEAR(box.num_voxels, expected_voxels, 0.15 * expected_voxels);
}

}  // namespace
}  // namespace panmap
