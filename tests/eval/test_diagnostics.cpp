#include <cmath>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/eval/diagnostics.h"

namespace panmap {
namespace {

// GT: 100 wall vertices (two annotation pieces, instances 1 and 2), 100 floor, 200 chair A
// (instance 3), 150 chair B (instance 4), 50 unannotated.
struct Case {
  LabelledMesh gt;
  TransferredLabels pred;
  void add(int count, int32_t cls, int32_t inst, int32_t p_cls, int32_t p_inst, int32_t sp,
           bool reached = true) {
    for (int k = 0; k < count; ++k) {
      pred.reached.push_back(reached ? 1 : 0);
      // 1 m apart: no vertex is near a class boundary, so every one counts for bridging.
      gt.vertices.emplace_back(static_cast<float>(gt.vertices.size()), 0.0f, 0.0f);
      gt.semantic.push_back(cls);
      gt.instance.push_back(inst);
      pred.semantic.push_back(p_cls);
      pred.instance.push_back(p_inst);
      pred.superpoint.push_back(sp);
    }
  }
};

Case makeCase() {
  Case c;
  // Walls: super-point 1 spans both annotation pieces (pure: one stuff identity).
  c.add(50, 1, 1, 1, 0, 1);
  c.add(50, 1, 2, 1, 0, 1);
  // Floor: super-point 2, of which 20 vertices are labelled wall.
  c.add(80, 2, 5, 2, 0, 2);
  c.add(20, 2, 5, 1, 0, 2);
  // Chair A: object 7 (180 vertices, super-point 3) + 20 vertices in super-point 2 as floor.
  c.add(180, 5, 3, 5, 7, 3);
  c.add(20, 5, 3, 2, 0, 2);
  // Chair B: object 8 covers only 60 of 150 (IoU 0.4), the rest object 9 (90, IoU 0.6).
  c.add(60, 5, 4, 5, 8, 4);
  c.add(90, 5, 4, 5, 9, 5);
  // Unannotated: 40 carry object 10 (a clutter object), 10 are in super-point 3.
  c.add(40, 0, 0, 39, 10, 6);
  c.add(10, 0, 0, 5, 7, 3);
  return c;
}

TEST(Diagnostics, MissedThingsGetTheCauseThatBoundsThem) {
  Case c;
  // Chair (200): object 1 holds 180 of it and nothing else: IoU 0.9, matched.
  c.add(180, 5, 1, 5, 1, 1);
  c.add(20, 5, 1, 0, 0, 2);
  // Cabinet (200): only 80 vertices reached, all in object 2: IoU 0.4, unobserved.
  c.add(80, 3, 2, 3, 2, 3);
  c.add(120, 3, 2, 0, 0, 0, false);
  // Table (200): 150 labelled desk (object 3), 50 table (object 4): wrong class.
  c.add(150, 7, 3, 14, 3, 4);
  c.add(50, 7, 3, 7, 4, 5);
  // Two cabinets (100 each) in one cabinet object 5: IoU 100 / 200 = 0.5 each, merged.
  c.add(100, 3, 4, 3, 5, 6);
  c.add(100, 3, 5, 3, 5, 6);
  // Fridge (200): objects 6 and 7 hold 80 each, 40 unlabelled: class share 0.8, split.
  c.add(80, 24, 6, 24, 6, 7);
  c.add(80, 24, 6, 24, 7, 8);
  c.add(40, 24, 6, 0, 0, 9);
  // Other furniture (200): 60 in object 8, 140 reached but unlabelled: unlabelled.
  c.add(60, 39, 7, 39, 8, 10);
  c.add(140, 39, 7, 0, 0, 0);
  // Bookshelf (200): 110 seen, 100 of them its own object 9 and nothing else, 90 never seen:
  // IoU 0.5, not a match; over the 0.55 seen 0.91: partly observed (by shares, unlabelled).
  c.add(100, 10, 8, 10, 9, 11);
  c.add(10, 10, 8, 0, 0, 12);
  c.add(90, 10, 8, 0, 0, 0, false);
  // Desk (200): 120 seen, 100 of them labelled table (object 10), 20 desk (object 11), 80 never
  // seen: IoU 0.1, over the 0.6 seen 0.17: seen, and wrongly labelled.
  c.add(100, 14, 9, 7, 10, 13);
  c.add(20, 14, 9, 14, 11, 14);
  c.add(80, 14, 9, 0, 0, 0, false);
  const SceneDiagnostics d = diagnose(c.gt, c.pred, {});
  ASSERT_EQ(d.gt_things.size(), 9u);
  std::map<int32_t, SceneDiagnostics::GtThing> by_instance;
  for (const auto& t : d.gt_things) by_instance[t.instance_id] = t;
  using Cause = SceneDiagnostics::MissCause;
  EXPECT_EQ(by_instance[1].cause, Cause::kMatched);
  EXPECT_NEAR(by_instance[1].best_same_class_iou, 0.9, 1e-12);
  EXPECT_NEAR(by_instance[1].observed_share, 1.0, 1e-12);
  EXPECT_EQ(by_instance[2].cause, Cause::kUnobserved);
  EXPECT_NEAR(by_instance[2].observed_share, 0.4, 1e-12);
  EXPECT_NEAR(by_instance[2].best_same_class_iou, 0.4, 1e-12);
  EXPECT_EQ(by_instance[3].cause, Cause::kWrongClass);
  EXPECT_NEAR(by_instance[3].class_share, 0.25, 1e-12);
  EXPECT_NEAR(by_instance[3].other_class_share, 0.75, 1e-12);
  EXPECT_EQ(by_instance[7].cause, Cause::kUnlabelled);
  EXPECT_NEAR(by_instance[7].class_share, 0.3, 1e-12);
  EXPECT_NEAR(by_instance[7].other_class_share, 0.0, 1e-12);
  EXPECT_EQ(by_instance[3].best_object, 3);  // the desk holds most of it
  EXPECT_EQ(by_instance[4].cause, Cause::kMerged);
  EXPECT_EQ(by_instance[5].cause, Cause::kMerged);
  EXPECT_NEAR(by_instance[4].best_same_class_iou, 0.5, 1e-12);
  EXPECT_NEAR(by_instance[4].best_same_class_cover, 1.0, 1e-12);
  EXPECT_EQ(by_instance[6].cause, Cause::kSplit);
  EXPECT_NEAR(by_instance[6].class_share, 0.8, 1e-12);
  EXPECT_NEAR(by_instance[6].best_same_class_cover, 0.4, 1e-12);
  EXPECT_EQ(by_instance[8].cause, Cause::kPartlyObserved);
  EXPECT_NEAR(by_instance[8].observed_share, 0.55, 1e-12);
  EXPECT_NEAR(by_instance[8].best_same_class_iou, 0.5, 1e-12);
  EXPECT_EQ(by_instance[9].cause, Cause::kWrongClass);
  EXPECT_NEAR(by_instance[9].best_same_class_iou, 0.1, 1e-12);
  EXPECT_STREQ(missCauseName(Cause::kWrongClass), "wrong class");
  EXPECT_STREQ(missCauseName(Cause::kPartlyObserved), "partly observed");
  EXPECT_NE(formatDiagnostics(d).find("1 matched; missed: 1 unobserved, 1 partly observed, 2 "
                                      "wrong class, 1 unlabelled, 2 merged, 1 split"),
            std::string::npos);
  // Labels built without `reached` count every vertex as observed.
  Case bare = c;
  bare.pred.reached.clear();
  for (const auto& t : diagnose(bare.gt, bare.pred, {}).gt_things) {
    EXPECT_NEAR(t.observed_share, 1.0, 1e-12) << "instance " << t.instance_id;
  }
}

TEST(Diagnostics, StuffIoUComesWithTheShareTheMapObserved) {
  Case c;
  // Wall: 100, all reached, 90 labelled wall. Ceiling: 200, 40 reached and labelled ceiling,
  // 160 never reached (a survey at head height): IoU 0.2 with 0.2 observed, no labelling error.
  c.add(90, 1, 1, 1, 0, 1);
  c.add(10, 1, 1, 2, 0, 2);
  c.add(40, 22, 2, 22, 0, 3);
  c.add(160, 22, 2, 0, 0, 0, false);
  const SceneDiagnostics d = diagnose(c.gt, c.pred, {});
  EXPECT_NEAR(d.wall_iou, 0.9, 1e-12);
  EXPECT_NEAR(d.wall_observed, 1.0, 1e-12);
  EXPECT_NEAR(d.ceiling_iou, 40.0 / 200.0, 1e-12);
  EXPECT_NEAR(d.ceiling_observed, 40.0 / 200.0, 1e-12);
  // Floor: no GT vertex of it (10 wall vertices labelled floor still make its IoU 0).
  EXPECT_TRUE(std::isnan(d.floor_observed));
  EXPECT_NE(
      formatDiagnostics(d).find("wall 0.900 (1.000), floor none in GT, ceiling 0.200 (0.200)"),
      std::string::npos)
      << formatDiagnostics(d);
  // Labels built without `reached` count every vertex as observed.
  Case bare = c;
  bare.pred.reached.clear();
  EXPECT_NEAR(diagnose(bare.gt, bare.pred, {}).ceiling_observed, 1.0, 1e-12);
}

TEST(Diagnostics, HandComputedCase) {
  const Case c = makeCase();
  const std::map<int32_t, double> objects = {{7, 0.9}, {8, 0.7}, {9, 0.3}, {10, 0.95}, {11, 0.6}};
  const SceneDiagnostics d = diagnose(c.gt, c.pred, objects);
  // Purity: sp1 100/100, sp2 100 floor of 120 annotated (20 chair A), sp3 180/180, sp4 60/60,
  // sp5 90/90; sp6 has no annotated vertex. (100 + 100 + 180 + 60 + 90) / (100 + 120 + 180 +
  // 60 + 90) = 530 / 550.
  EXPECT_NEAR(d.superpoint_purity, 530.0 / 550.0, 1e-12);
  EXPECT_NEAR(d.superpoint_class_purity, 530.0 / 550.0, 1e-12);
  EXPECT_EQ(d.num_superpoints, 5);
  // sp2 (120 annotated >= 100) has 20 / 120 = 0.167 chair: one bridging super-point.
  EXPECT_EQ(d.num_bridging_superpoints, 1);
  EXPECT_NEAR(d.worst_second_class_share, 20.0 / 120.0, 1e-12);
  // Largest: sp3 with 190 vertices, 10 unannotated, all chair.
  EXPECT_EQ(d.largest_superpoint, 3);
  EXPECT_EQ(d.largest_vertices, 190);
  EXPECT_EQ(d.largest_unannotated_vertices, 10);
  ASSERT_EQ(d.largest_class_mix.size(), 1u);
  EXPECT_EQ(d.largest_class_mix[0].first, 5);
  EXPECT_EQ(d.largest_gt_instances, 1);
  // Wall IoU: tp 100, fp 20 (floor labelled wall), fn 0. Floor: tp 80, fn 20, fp 20 (chair).
  EXPECT_NEAR(d.wall_iou, 100.0 / 120.0, 1e-12);
  EXPECT_NEAR(d.floor_iou, 80.0 / 120.0, 1e-12);
  EXPECT_TRUE(std::isnan(d.ceiling_iou));
  // Objects: 5 listed for 2 GT things.
  ASSERT_EQ(d.gt_things.size(), 2u);
  EXPECT_EQ(d.num_objects, 5);
  EXPECT_NEAR(d.objects_per_gt_instance, 2.5, 1e-12);
  // Object 10 lies on unannotated GT only: 4 can be checked against the 2 GT things.
  EXPECT_EQ(d.num_checkable_objects, 4);
  EXPECT_NEAR(d.checkable_objects_per_gt_instance, 2.0, 1e-12);
  EXPECT_NE(formatDiagnostics(d).find("objects: 5 for 2 GT thing instances (2.50 each; 4 on "
                                      "annotated GT, 2.00 each)"),
            std::string::npos);
  std::map<int32_t, SceneDiagnostics::ObjectMatch> by_id;
  for (const auto& o : d.objects) by_id[o.id] = o;
  // Object 7: 190 vertices (10 void), IoU with chair A = 180 / (200 + 190 - 180).
  EXPECT_NEAR(by_id[7].best_iou, 180.0 / 210.0, 1e-12);
  EXPECT_TRUE(by_id[7].matched);
  EXPECT_NEAR(by_id[8].best_iou, 0.4, 1e-12);
  EXPECT_FALSE(by_id[8].matched);
  EXPECT_NEAR(by_id[9].best_iou, 0.6, 1e-12);
  EXPECT_TRUE(by_id[9].matched);
  EXPECT_TRUE(by_id[10].unverifiable);  // all on unannotated GT
  EXPECT_EQ(by_id[11].vertices, 0);     // listed, on no GT vertex: unmatched
  EXPECT_FALSE(by_id[11].matched);
  // Confident (>= 0.5, verifiable): 7 (match), 8 (no), 11 (no) -> 1/3; they cover chair A only.
  EXPECT_EQ(d.confident_objects, 3);
  EXPECT_NEAR(d.confident_precision, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(d.confident_recall, 0.5, 1e-12);
  // Reliability, 5 bins: 9 (0.3) in [0.2, 0.4) matched; 8 (0.7), 11 (0.6) in [0.6, 0.8) none;
  // 7 (0.9) in [0.8, 1] matched.
  ASSERT_EQ(d.reliability.size(), 5u);
  EXPECT_EQ(d.reliability[1].count, 1);
  EXPECT_EQ(d.reliability[1].matched, 1);
  EXPECT_EQ(d.reliability[3].count, 2);
  EXPECT_EQ(d.reliability[3].matched, 0);
  EXPECT_NEAR(d.reliability[3].mean_confidence, 0.65, 1e-12);
  EXPECT_EQ(d.reliability[4].count, 1);
  EXPECT_EQ(d.reliability[4].matched, 1);
}

TEST(Diagnostics, WithoutAnObjectListEveryMeshInstanceIsAnObject) {
  const Case c = makeCase();
  const SceneDiagnostics d = diagnose(c.gt, c.pred, {});
  EXPECT_EQ(d.num_objects, 4);        // 7, 8, 9, 10
  EXPECT_EQ(d.confident_objects, 3);  // 10 is unverifiable
}

// A 50 x 50 cm wall sampled every centimetre with a 20 x 20 cm picture on it (vertex indices
// 10-29 in x and y), and one super-point over the picture and the wall within `from`-`to`.
struct PictureOnWall {
  LabelledMesh gt;
  TransferredLabels pred;
  PictureOnWall(int from, int to) {
    for (int j = 0; j < 50; ++j) {
      for (int i = 0; i < 50; ++i) {
        const bool picture = i >= 10 && i < 30 && j >= 10 && j < 30;
        const bool inside = i >= from && i < to && j >= from && j < to;
        gt.vertices.emplace_back(0.01f * i, 0.01f * j, 0.0f);
        gt.semantic.push_back(picture ? 11 : 1);
        gt.instance.push_back(picture ? 2 : 1);
        pred.semantic.push_back(inside ? 11 : 1);
        pred.instance.push_back(inside ? 2 : 0);
        pred.superpoint.push_back(inside ? 1 : 2);
      }
    }
  }
};

TEST(Diagnostics, AOneVoxelRimIsResolutionNotABridge) {
  // The super-point holds the picture and a 1 cm rim of wall: 84 wall of 484 vertices (17 %).
  const PictureOnWall rim(9, 31);
  const SceneDiagnostics raw = diagnose(rim.gt, rim.pred, {}, 5, 0.0);
  EXPECT_EQ(raw.num_bridging_superpoints, 1);
  EXPECT_EQ(raw.num_bridging_superpoints_with_boundaries, 1);
  EXPECT_NEAR(raw.worst_second_class_share, 84.0 / 484.0, 1e-12);
  // With a 1.5 cm band every rim vertex (1 or 1.41 cm from the picture) is left out, and so are
  // the picture's own outer ring (76): 324 picture vertices, no wall.
  const SceneDiagnostics banded = diagnose(rim.gt, rim.pred, {}, 5, 0.015);
  EXPECT_EQ(banded.num_bridging_superpoints, 0);
  EXPECT_EQ(banded.num_bridging_superpoints_with_boundaries, 1);
  EXPECT_EQ(banded.worst_second_class_share, 0.0);
  EXPECT_NEAR(banded.superpoint_purity, raw.superpoint_purity, 1e-12);  // purity keeps all
}

TEST(Diagnostics, ASuperPointReachingWellIntoTheWallStillBridges) {
  // 5 cm of wall around the picture: 500 wall vertices, 84 of them within the band, 416 away;
  // 324 picture vertices away from the wall. Wall share 416 / 740.
  const PictureOnWall wide(5, 35);
  const SceneDiagnostics d = diagnose(wide.gt, wide.pred, {}, 5, 0.015);
  EXPECT_EQ(d.num_bridging_superpoints, 1);
  ASSERT_EQ(d.bridges.size(), 1u);
  EXPECT_EQ(d.bridges[0].superpoint, 1);
  EXPECT_EQ(d.bridges[0].vertices, 740);
  ASSERT_EQ(d.bridges[0].class_mix.size(), 2u);
  EXPECT_EQ(d.bridges[0].class_mix[0].first, 1);
  EXPECT_NEAR(d.bridges[0].class_mix[0].second, 416.0 / 740.0, 1e-12);
  EXPECT_NEAR(d.bridges[0].class_mix[1].second, 324.0 / 740.0, 1e-12);
  // Reach: its wall goes 5 cm past the picture on both axes (corner (5, 5) is 7.07 cm from the
  // picture's (10, 10)); its picture lies at most 10 cm from the wall (the centre, (19, 19) to
  // (9, 19)). The smaller of the two.
  EXPECT_NEAR(d.bridges[0].reach_m, 0.05 * std::sqrt(2.0), 1e-6);
  // Its objects, most vertices first: the wall as a whole (stuff: instance 0), the picture.
  ASSERT_EQ(d.bridges[0].parts.size(), 2u);
  EXPECT_EQ(d.bridges[0].parts[0].class_id, 1);
  EXPECT_EQ(d.bridges[0].parts[0].instance, 0);
  EXPECT_EQ(d.bridges[0].parts[0].vertices, 416);
  EXPECT_EQ(d.bridges[0].parts[1].class_id, 11);
  EXPECT_EQ(d.bridges[0].parts[1].instance, 2);
  EXPECT_EQ(d.bridges[0].parts[1].vertices, 324);
  // Labels built by hand keep no distances to the map: none reported.
  EXPECT_TRUE(std::isnan(d.bridges[0].map_distance_m[0]));
  EXPECT_TRUE(std::isnan(d.bridges[0].map_distance_m[1]));
  EXPECT_EQ(formatDiagnostics(d).find("distance to the map"), std::string::npos);
  EXPECT_THROW(diagnose(wide.gt, wide.pred, {}, 5, -0.01), Error);
}

TEST(Diagnostics, ABridgeSaysHowFarEachOfItsClassesLiesFromTheMap) {
  // The wall the super-point takes was never mapped (2.5 cm from the nearest mapped vertex,
  // as behind an object); the picture was: 72 of its 324 vertices beyond the band at 1 mm, the
  // other 252 at 4 mm. Medians: 2.5 cm and 4 mm (the mean, 3.3 mm, would not be a median).
  PictureOnWall wide(5, 35);
  for (size_t v = 0; v < wide.gt.numVertices(); ++v) {
    const bool picture = wide.gt.semantic[v] == 11;
    const bool low_rows = wide.gt.vertices[v].y() < 0.145f;  // rows j = 11..14 of the picture
    wide.pred.distance_m.push_back(!picture ? 0.025f : low_rows ? 0.001f : 0.004f);
  }
  const SceneDiagnostics d = diagnose(wide.gt, wide.pred, {}, 5, 0.015);
  ASSERT_EQ(d.bridges.size(), 1u);
  ASSERT_EQ(d.bridges[0].class_mix[0].first, 1);  // wall first
  EXPECT_NEAR(d.bridges[0].map_distance_m[0], 0.025, 1e-7);
  EXPECT_NEAR(d.bridges[0].map_distance_m[1], 0.004, 1e-7);
  EXPECT_NE(formatDiagnostics(d).find("reaching 7.1 cm past their boundary; median distance to "
                                      "the map 2.5 / 0.4 cm\n"),
            std::string::npos)
      << formatDiagnostics(d);
  // A distance per GT vertex or none: anything else is refused like the other arrays.
  wide.pred.distance_m.pop_back();
  EXPECT_THROW(diagnose(wide.gt, wide.pred, {}, 5, 0.015), Error);
}

TEST(Diagnostics, RefusesMismatchedInput) {
  Case c = makeCase();
  c.pred.superpoint.pop_back();
  EXPECT_THROW(diagnose(c.gt, c.pred, {}), Error);
}

}  // namespace
}  // namespace panmap
