#include <map>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/superpoint/superpoint_tracker.h"
#include "panmap/superpoint/vote_split.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// A wall at x = 2 seen head-on; surfaces are drawn by hand so that every step of III-B is
// under the test's control.
class WallScene : public ::testing::Test {
 protected:
  WallScene() : renderer_(makeWall()), pool_(1), integrator_(IntegratorConfig{}, &pool_) {
    T_W_C_ = test::lookAt({0, 0, 1}, {2, 0, 1});
    const RenderedView view = renderer_.render(test::kinectCamera(), T_W_C_);
    DepthNoiseConfig exact;
    exact.enabled = false;
    frame_.camera = test::kinectCamera();
    frame_.depth = simulateDepth(view, exact, 0);
  }
  static LabelledMesh makeWall() {
    LabelledMesh mesh;
    test::addQuad(&mesh, {2, -4, -2}, {2, 4, -2}, {2, 4, 4}, {2, -4, 4}, 1, 1, 8);
    return mesh;
  }
  // Surfaces by image column: [0, split) and [split, 640), with categories a and b; split 640
  // gives one surface of category a.
  // same_mask: both surfaces lie in one panoptic mask (an object split by an occluder).
  FrameSegmentation columns(int split, int32_t a, int32_t b, bool same_mask = false) const {
    FrameSegmentation seg;
    seg.geometric = LabelImage(640, 480, 1);
    seg.surfaces = LabelImage(640, 480, 0);
    int count[2] = {0, 0};
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        seg.surfaces(u, v) = u < split ? 1 : 2;
        ++count[u < split ? 0 : 1];
      }
    }
    seg.surface_list.push_back(Surface{1, 1, a ? 1 : 0, a, a > 3, 0.9f, count[0]});
    const int32_t mask_b = b ? (same_mask ? 1 : 2) : 0;
    if (split < 640) seg.surface_list.push_back(Surface{2, 1, mask_b, b, b > 3, 0.9f, count[1]});
    return seg;
  }
  // Surfaces as vertical stripes: (first column past the stripe, category) per stripe.
  FrameSegmentation stripes(const std::vector<std::pair<int, int32_t>>& parts) const {
    FrameSegmentation seg;
    seg.geometric = LabelImage(640, 480, 1);
    seg.surfaces = LabelImage(640, 480, 0);
    int start = 0;
    for (size_t k = 0; k < parts.size(); ++k) {
      const auto [end, category] = parts[k];
      const int32_t id = static_cast<int32_t>(k) + 1;
      for (int v = 0; v < 480; ++v) {
        for (int u = start; u < end; ++u) seg.surfaces(u, v) = id;
      }
      seg.surface_list.push_back(
          Surface{id, 1, category ? id : 0, category, category > 3, 0.9f, (end - start) * 480});
      start = end;
    }
    return seg;
  }
  // Two objects of one thing class on the wall's halves: two frames with a mask each, then
  // 8 rounds of such a frame and `ones` frames of one mask over both. Returns the merges and
  // splits of the rounds.
  std::pair<int, int> twoMasksThenOne(SuperpointTracker* tracker, TsdfMap* map, int ones) {
    const auto two = stripes({{320, 5}, {640, 5}});  // two masks (ids 1 and 2)
    const auto one = stripes({{640, 5}});            // one mask over both
    step(tracker, map, two);
    step(tracker, map, two);
    int merges = 0, splits = 0;
    for (int k = 0; k < 8; ++k) {
      const FrameAssociation a = step(tracker, map, two);
      merges += a.merges;
      splits += static_cast<int>(a.splits.size());
      for (int i = 0; i < ones; ++i) merges += step(tracker, map, one).merges;
    }
    return {merges, splits};
  }
  // One frame as the mapper runs it: association, splits, integration.
  FrameAssociation step(SuperpointTracker* tracker, TsdfMap* map, const FrameSegmentation& seg) {
    FrameAssociation a = tracker->associate(seg, frame_, T_W_C_, *map);
    applySplits(&a, seg, frame_, T_W_C_, tracker->labels(), map);
    integrator_.integrate(frame_, T_W_C_, &a.pixel_labels, map);
    return a;
  }

  MeshRenderer renderer_;
  ThreadPool pool_;
  ProjectiveIntegrator integrator_;
  Eigen::Isometry3d T_W_C_;
  RgbdFrame frame_;
};

TEST(SuperpointState, VoidShareIsTheShareOfFramesWithoutAMask) {
  SuperpointState state;
  EXPECT_EQ(state.voidShare(), 0.0);  // never seen
  state.class_counts = {{0, 3.0}, {5, 1.0}};
  EXPECT_EQ(state.voidShare(), 0.75);
  EXPECT_EQ(state.semanticClass(), 0);
  EXPECT_EQ(state.labelledClass(), 5);
  state.class_counts = {{1, 2.0}, {5, 2.0}};
  EXPECT_EQ(state.voidShare(), 0.0);
}

TEST_F(WallScene, SurfacesKeepTheirSuperpointAcrossFrames) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  const FrameAssociation first = step(&tracker, &map, columns(384, 1, 4));
  ASSERT_EQ(first.surface_labels.size(), 2u);
  EXPECT_EQ(first.surface_labels[0], 1);
  EXPECT_EQ(first.surface_labels[1], 2);
  EXPECT_EQ(first.new_labels, 2);
  const FrameAssociation second = step(&tracker, &map, columns(384, 1, 4));
  EXPECT_EQ(second.new_labels, 0);
  EXPECT_EQ(second.surface_labels, first.surface_labels);
  EXPECT_EQ(tracker.state(1)->semanticClass(), 1);
  EXPECT_EQ(tracker.state(2)->semanticClass(), 4);
  // Things get a global instance from frame counting; stuff-like class 1 (a <= 3) none.
  EXPECT_EQ(second.surface_instances[0], 0);
  EXPECT_EQ(second.surface_instances[1], first.surface_instances[1]);
  EXPECT_GT(first.surface_instances[1], 0);
  EXPECT_EQ(tracker.numInstances(), 1);
}

TEST_F(WallScene, FramesWithoutASegmentationAreNoClassEvidence) {
  // A network that segments one frame in six: the five frames between see the same surfaces
  // with class 0 everywhere. Counted as "no mask here", they made the wall 83 % void.
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  FrameSegmentation geometry_only = columns(384, 0, 0);
  geometry_only.panoptic = false;
  for (int round = 0; round < 3; ++round) {
    step(&tracker, &map, columns(384, 1, 4));
    for (int k = 0; k < 5; ++k) {
      const FrameAssociation a = step(&tracker, &map, geometry_only);
      EXPECT_EQ(a.new_labels, 0);  // still associated with the super-points they hold
    }
  }
  EXPECT_EQ(tracker.state(1)->class_counts, (std::map<int32_t, double>{{1, 3.0}}));
  EXPECT_EQ(tracker.state(2)->class_counts, (std::map<int32_t, double>{{4, 3.0}}));
  EXPECT_EQ(tracker.state(1)->voidShare(), 0.0);
  EXPECT_EQ(tracker.state(2)->semanticClass(), 4);
  // A segmentation that holds no mask of a known class is evidence: class 0 counts.
  step(&tracker, &map, columns(384, 0, 0));
  EXPECT_EQ(tracker.state(2)->class_counts, (std::map<int32_t, double>{{0, 1.0}, {4, 3.0}}));
}

// The paper's Fig. 4: a surface spanning a wall and a bed (noisy geometric segmentation)
// co-observes both super-points. Spatial-only merging (Voxblox++) joins them once M exceeds
// theta_merge; the semantic consistency check keeps them apart. Clean frames in between keep
// the bed super-point alive (a spanning surface alone would out-vote it within two frames).
TEST_F(WallScene, SemanticConsistencyPreventsWallBedMerge) {
  for (bool semantic : {true, false}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointConfig config;
    config.semantic_consistency = semantic;
    SuperpointTracker tracker(config);
    step(&tracker, &map, columns(384, 1, 4));  // wall (60 %) and bed (40 %)
    step(&tracker, &map, columns(384, 1, 4));
    int merges = 0;
    for (int k = 0; k < 6; ++k) {
      merges += step(&tracker, &map, columns(384, 1, 4)).merges;
      merges += step(&tracker, &map, columns(640, 1, 0)).merges;  // spans wall and bed
    }
    if (semantic) {
      EXPECT_EQ(merges, 0);
      EXPECT_NE(tracker.labels().resolve(1), tracker.labels().resolve(2));
      EXPECT_EQ(tracker.state(2)->semanticClass(), 4);
      // A wall surface is no verdict on a bed: the spanning frames are not counted.
      EXPECT_EQ(tracker.coObservations().count({1, 2}), 0u);
    } else {
      EXPECT_EQ(merges, 1);
      EXPECT_EQ(tracker.labels().resolve(2), 1);  // the older id survives
      ASSERT_EQ(tracker.merges().size(), 1u);
      EXPECT_EQ(tracker.merges()[0].removed, 2);
      // M exceeds theta_merge = 3 at the 4th spanning frame, frame 10.
      EXPECT_EQ(tracker.merges()[0].frame, 10);
      EXPECT_EQ(tracker.state(2), tracker.state(1));
    }
  }
}

// Issue 19: an unlabelled super-point between a wall and a floor (here: stripes of a plane)
// that unlabelled surfaces keep spanning. With the paper's rule (one of the two may be
// background) it merges with the wall and then with the floor, chaining two classes into one
// super-point; unlabelled super-points now merge only with unlabelled ones.
TEST_F(WallScene, UnlabelledSuperpointsDoNotChainClasses) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  const auto clean = stripes({{220, 1}, {420, 0}, {640, 2}});  // wall | unlabelled | floor
  const auto left = stripes({{420, 0}, {640, 2}});             // spans wall and unlabelled
  const auto right = stripes({{220, 1}, {640, 0}});            // spans unlabelled and floor
  step(&tracker, &map, clean);
  step(&tracker, &map, clean);
  int merges = 0;
  for (int k = 0; k < 6; ++k) {
    merges += step(&tracker, &map, clean).merges;
    merges += step(&tracker, &map, left).merges;
    merges += step(&tracker, &map, right).merges;
  }
  EXPECT_EQ(merges, 0);
  EXPECT_EQ(tracker.states().size(), 3u);
  EXPECT_GT(tracker.coObservations().at({1, 2}), 3);  // spatially connected, kept apart
  EXPECT_GT(tracker.coObservations().at({2, 3}), 3);
  EXPECT_EQ(tracker.state(1)->labelledClass(), 1);
  EXPECT_EQ(tracker.state(2)->labelledClass(), 0);
  EXPECT_EQ(tracker.state(3)->labelledClass(), 2);
}

// Two unlabelled pieces of one surface merge like labelled ones; a super-point the network
// labelled once stays labelled however often it was seen unlabelled, and does not merge with
// an unlabelled neighbour.
TEST_F(WallScene, UnlabelledPiecesMergeOnlyAmongThemselves) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  step(&tracker, &map, stripes({{320, 0}, {640, 0}}));
  step(&tracker, &map, stripes({{320, 0}, {640, 0}}));
  int merges = 0;
  for (int k = 0; k < 4; ++k) {
    merges += step(&tracker, &map, stripes({{320, 0}, {640, 0}})).merges;
    merges += step(&tracker, &map, stripes({{640, 0}})).merges;
  }
  EXPECT_EQ(merges, 1);
  EXPECT_EQ(tracker.labels().resolve(2), 1);

  TsdfMap map2(TsdfMap::Config{0.05f});
  SuperpointTracker labelled(SuperpointConfig{});
  step(&labelled, &map2, stripes({{320, 5}, {640, 0}}));  // a chair once, then never again
  for (int k = 0; k < 3; ++k) step(&labelled, &map2, stripes({{320, 0}, {640, 0}}));
  merges = 0;
  for (int k = 0; k < 6; ++k) {
    merges += step(&labelled, &map2, stripes({{320, 0}, {640, 0}})).merges;
    merges += step(&labelled, &map2, stripes({{640, 0}})).merges;
  }
  EXPECT_EQ(merges, 0);
  EXPECT_GT(labelled.coObservations().at({1, 2}), 3);
  EXPECT_EQ(labelled.state(1)->semanticClass(), 0);  // mostly seen unlabelled
  EXPECT_EQ(labelled.state(1)->labelledClass(), 5);  // but the network called it a chair
}

// A chair piece (left) beside surface the network masked as a chair once and never since
// (right: an unannotated object next to the chair, in view more often than the chair). Now and
// then one surface without a mask covers both. Merged, their pooled frame counts would be left
// unlabelled, taking the chair piece's class away, so they do not merge; without the rule
// (unlabelled_void_share 1) they do, once co-observed in theta_merge + 1 = 4 frames.
TEST_F(WallScene, NoMergeLeavesALabelledPieceUnlabelled) {
  FrameSegmentation right_only = stripes({{640, 0}});  // the chair piece out of the surfaces
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 200; ++u) right_only.surfaces(u, v) = 0;
  }
  right_only.surface_list[0].num_pixels = 440 * 480;
  for (const double limit : {0.6, 1.0}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointConfig config;
    config.unlabelled_void_share = limit;
    SuperpointTracker tracker(config);
    step(&tracker, &map, columns(200, 5, 5, true));  // one chair mask over both pieces
    int merges = 0;
    for (int k = 0; k < 4; ++k) {
      step(&tracker, &map, columns(200, 5, 0));
      step(&tracker, &map, columns(200, 5, 0));
      merges += step(&tracker, &map, stripes({{640, 0}})).merges;
      if (k < 3) {
        for (int i = 0; i < 3; ++i) step(&tracker, &map, right_only);
      }
    }
    if (limit < 1.0) {
      EXPECT_EQ(merges, 0);
      EXPECT_EQ(tracker.coObservations().at({1, 2}), 4);
      EXPECT_EQ(tracker.state(1)->class_counts, (std::map<int32_t, double>{{5, 9.0}}));
      // 2 + 1 + 3 frames without a mask in each of 3 rounds, then 2 + 1.
      EXPECT_EQ(tracker.state(2)->class_counts, (std::map<int32_t, double>{{0, 21.0}, {5, 1.0}}));
    } else {
      EXPECT_EQ(merges, 1);
      EXPECT_EQ(tracker.labels().resolve(2), 1);
      EXPECT_EQ(tracker.state(1)->class_counts, (std::map<int32_t, double>{{0, 21.0}, {5, 10.0}}));
    }
  }
}

// Two touching objects of one class, one plane (geometry cannot tell them apart): the network
// shows them as two masks, and now and then as one. Co-observed in one surface more than
// theta_merge times, they still do not merge while the frames showing them as two objects,
// times apart_weight, are at least as many; the same pair seen as one object far more often
// merges.
TEST_F(WallScene, SuperpointsSeenAsTwoObjectsDoNotMerge) {
  for (bool mostly_one : {false, true}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointTracker tracker(SuperpointConfig{});
    ASSERT_EQ(tracker.config().apart_weight, 1.5f);
    const auto [merges, splits] = twoMasksThenOne(&tracker, &map, mostly_one ? 2 : 1);
    if (mostly_one) {
      // The pair itself stops at 4 co-observations against 3 apart (1.5 x 3 >= 4): the
      // one-mask frames' votes hand the whole plane to super-point 1 first. From then on
      // each two-mask frame splits the right half off (mask_verdicts) and the next round's
      // one-mask frames, outnumbering the new pair's single two-mask frame, merge it back.
      EXPECT_EQ(merges, 3);
      EXPECT_EQ(splits, 3);
      EXPECT_EQ(tracker.labels().resolve(2), 2);
      EXPECT_EQ(tracker.coObservations().at({1, 2}), 4);
      EXPECT_EQ(tracker.apartCounts().at({1, 2}), 3);
    } else {
      EXPECT_EQ(merges, 0);
      EXPECT_EQ(splits, 0);
      // Every two-mask frame but the first (its super-points were only just created).
      EXPECT_EQ(tracker.apartCounts().at({1, 2}), 9);
      EXPECT_EQ(tracker.coObservations().at({1, 2}), 8);
    }
  }
}

// With apart_weight 1, the plain majority (the rule of map files before version 8): the pair
// merges as soon as its one-mask frames outnumber the two-mask ones.
TEST_F(WallScene, ApartWeightOneMergesOnAPlainMajority) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointConfig config;
  config.apart_weight = 1.0f;
  SuperpointTracker tracker(config);
  const auto [merges, splits] = twoMasksThenOne(&tracker, &map, 2);
  EXPECT_EQ(merges, 4);
  EXPECT_EQ(splits, 3);
  EXPECT_EQ(tracker.states().size(), 1u);
}

// A frame is one verdict: two surfaces that both show the same pair (one mask cut in two by
// the frame's geometry) count once towards theta_merge, as the frames showing the pair apart
// do. Spatial-only merging (the Voxblox++-like baseline) counts each surface.
TEST_F(WallScene, CoObservationsCountOncePerFrame) {
  for (bool consistency : {true, false}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointConfig config;
    config.semantic_consistency = consistency;
    SuperpointTracker tracker(config);
    const auto sides = stripes({{320, 0}, {640, 0}});  // super-points 1 (left) and 2 (right)
    // Upper and lower halves: each surface covers half of both super-points.
    FrameSegmentation halves;
    halves.geometric = LabelImage(640, 480, 1);
    halves.surfaces = LabelImage(640, 480, 0);
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) halves.surfaces(u, v) = v < 240 ? 1 : 2;
    }
    halves.surface_list.push_back(Surface{1, 1, 0, 0, false, 0.9f, 640 * 240});
    halves.surface_list.push_back(Surface{2, 1, 0, 0, false, 0.9f, 640 * 240});
    step(&tracker, &map, sides);
    step(&tracker, &map, sides);
    if (!consistency) {
      step(&tracker, &map, halves);
      EXPECT_EQ(tracker.coObservations().at({1, 2}), 2);
      EXPECT_EQ(step(&tracker, &map, halves).merges, 1);  // M = 4 > theta_merge
      continue;
    }
    for (int k = 1; k <= 3; ++k) {
      EXPECT_EQ(step(&tracker, &map, halves).merges, 0);
      // Both surfaces show the pair in every frame, counted once: with a count per surface,
      // M would reach 4 > theta_merge in the second frame and merge them.
      EXPECT_EQ(tracker.coObservations().at({1, 2}), k);
    }
  }
}

// Two touching objects of one class first seen under one mask (the network merged them for a
// window) become one super-point. When the network then shows them as two masks, the surface
// that loses that super-point to the other splits from it (mask_verdicts): its voxels' votes
// move to its new super-point at once, so the next frames find two super-points and create
// none. Without the split, the loser's new super-point never outvotes the old one in those
// voxels and every frame starts yet another one there.
TEST_F(WallScene, SuperpointUnderOneMaskSplitsWhenShownAsTwoObjects) {
  for (bool verdicts : {true, false}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointConfig config;
    config.mask_verdicts = verdicts;
    config.revisit_votes = false;  // the rule of RevisitingSurfacesTakeBackTheirSuperpoint
    SuperpointTracker tracker(config);
    const auto one = stripes({{640, 5}});            // one mask over both objects
    const auto two = stripes({{320, 5}, {640, 5}});  // two masks (ids 1 and 2) of class 5
    for (int k = 0; k < 4; ++k) step(&tracker, &map, one);
    ASSERT_EQ(tracker.states().size(), 1u);
    const FrameAssociation first = step(&tracker, &map, two);
    ASSERT_EQ(first.surface_labels.size(), 2u);
    EXPECT_EQ(first.surface_labels[0], 1);  // equal overlaps: the first surface keeps it
    EXPECT_EQ(first.surface_labels[1], 2);
    int created = 0;
    FrameAssociation last;
    for (int k = 0; k < 5; ++k) {
      last = step(&tracker, &map, two);
      created += last.new_labels;
    }
    if (verdicts) {
      ASSERT_EQ(first.splits.size(), 1u);
      EXPECT_EQ(first.splits[0].surface_id, 2);
      EXPECT_EQ(first.splits[0].from, 1);
      EXPECT_EQ(first.splits[0].to, 2);
      EXPECT_EQ(created, 0);
      EXPECT_EQ(last.surface_labels, first.surface_labels);
      // 4 frames of votes for 1 in the right half moved to 2, and it kept its own.
      EXPECT_EQ(tracker.states().size(), 2u);
    } else {
      EXPECT_TRUE(first.splits.empty());
      EXPECT_EQ(created, 5);
      EXPECT_EQ(last.surface_labels[0], 1);
      EXPECT_EQ(last.surface_labels[1], 7);
    }
  }
}

// A mask cut in two by a depth edge: the piece whose super-point the other piece took joins it
// (join_mask_pieces), instead of starting one that the next frame's piece replaces.
TEST_F(WallScene, PiecesOfOneMaskShareItsSuperpoint) {
  for (bool join : {true, false}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointConfig config;
    config.join_mask_pieces = join;
    config.revisit_votes = false;
    SuperpointTracker tracker(config);
    for (int k = 0; k < 3; ++k) step(&tracker, &map, columns(640, 5, 5));
    int created = 0;
    FrameAssociation last;
    for (int k = 0; k < 4; ++k) {
      last = step(&tracker, &map, columns(384, 5, 5, /*same_mask=*/true));
      created += last.new_labels;
    }
    ASSERT_EQ(last.surface_labels.size(), 2u);
    EXPECT_EQ(last.surface_labels[0], 1);
    if (join) {
      EXPECT_EQ(created, 0);
      EXPECT_EQ(last.surface_labels[1], 1);
      EXPECT_EQ(tracker.state(1)->class_counts.at(5), 3.0 + 2 * 4);  // both pieces count
    } else {
      EXPECT_EQ(created, 4);  // a new one every frame: 2, 3, 4, 5
      EXPECT_EQ(last.surface_labels[1], 5);
    }
    // Two masks of one class are two verdicts, not pieces: the right half splits off.
    const FrameAssociation two = step(&tracker, &map, columns(384, 5, 5));
    ASSERT_EQ(two.splits.size(), 1u);
    EXPECT_EQ(two.splits[0].from, 1);
  }
}

// An object on a wall whose voxels the wall's super-point leads (6 frames of votes): the
// object's surface loses that super-point to the wall's surface each frame. With
// revisit_votes it takes back the super-point it started, from the voxels' second vote slot,
// until its own votes lead; without, every frame starts another.
TEST_F(WallScene, RevisitingSurfacesTakeBackTheirSuperpoint) {
  for (bool revisit : {true, false}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointConfig config;
    config.revisit_votes = revisit;
    SuperpointTracker tracker(config);
    for (int k = 0; k < 6; ++k) step(&tracker, &map, columns(640, 1, 1));
    int created = 0;
    std::vector<int32_t> object_labels;
    for (int k = 0; k < 9; ++k) {
      const FrameAssociation a = step(&tracker, &map, columns(384, 1, 6));
      created += a.new_labels;
      object_labels.push_back(a.surface_labels.at(1));
      EXPECT_EQ(a.surface_labels[0], 1);
      EXPECT_TRUE(a.splits.empty());  // another class: no split
    }
    if (revisit) {
      EXPECT_EQ(created, 1);
      EXPECT_EQ(object_labels, std::vector<int32_t>(9, 2));
      EXPECT_EQ(tracker.state(2)->class_counts.at(6), 9.0);
    } else {
      EXPECT_EQ(created, 9);
      EXPECT_EQ(object_labels.back(), 10);
      EXPECT_EQ(tracker.state(10)->class_counts.at(6), 1.0);
    }
  }
}

// A surface of another class than the super-points in its voxels' slots starts its own.
TEST_F(WallScene, RevisitingTakesOnlyASuperpointOfTheSurfacesClass) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointConfig config;
  config.revisit_votes = true;
  SuperpointTracker tracker(config);
  for (int k = 0; k < 6; ++k) step(&tracker, &map, columns(640, 1, 1));
  step(&tracker, &map, columns(384, 1, 6));  // super-point 2, class 6, on the right
  const FrameAssociation a = step(&tracker, &map, columns(384, 1, 7));
  EXPECT_EQ(a.new_labels, 1);
  EXPECT_EQ(a.surface_labels[1], 3);
}

// Three objects first seen under one mask, then as three masks: two surfaces split from the
// same super-point in one frame, and each split measures its distance to the surface that
// kept it (the middle stripe's centroid is nearer to the left one than the right stripe's).
TEST_F(WallScene, TwoSurfacesSplittingFromOneSuperpointBothMeasureTheirDistance) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  for (int k = 0; k < 4; ++k) step(&tracker, &map, stripes({{640, 5}}));
  const FrameAssociation a = step(&tracker, &map, stripes({{216, 5}, {428, 5}, {640, 5}}));
  ASSERT_EQ(a.splits.size(), 2u);
  EXPECT_EQ(a.splits[0].from, 1);
  EXPECT_EQ(a.splits[1].from, 1);
  EXPECT_GT(a.splits[0].distance_m, 0.0);
  EXPECT_GT(a.splits[1].distance_m, 1.5 * a.splits[0].distance_m);
  EXPECT_EQ(tracker.states().size(), 3u);
}

// A surface of another class over two super-points is no verdict on them. Two objects of one
// class, seen apart once; then the network misses the second and a floor mask spills over the
// border between them. Counted, those floor surfaces would merge the two (co-observed four
// times, apart once); with mask_verdicts they are not counted.
TEST_F(WallScene, ForeignMaskOverTwoSuperpointsDoesNotMergeThem) {
  for (bool verdicts : {true, false}) {
    TsdfMap map(TsdfMap::Config{0.05f});
    SuperpointConfig config;
    config.mask_verdicts = verdicts;
    // Revisiting, the floor surface would take back its own super-point, whose votes lead its
    // voxels from the third spill frame on: the pair would no longer be co-observed there.
    config.revisit_votes = false;
    SuperpointTracker tracker(config);
    const auto two = stripes({{320, 5}, {640, 5}});
    const auto spill = stripes({{280, 5}, {360, 2}, {640, 0}});  // object, floor, unlabelled
    step(&tracker, &map, two);
    step(&tracker, &map, two);
    int merges = 0;
    for (int k = 0; k < 6; ++k) merges += step(&tracker, &map, spill).merges;
    EXPECT_EQ(tracker.apartCounts().count({1, 2}), verdicts ? 1u : 0u);
    if (verdicts) {
      EXPECT_EQ(merges, 0);
      EXPECT_NE(tracker.labels().resolve(1), tracker.labels().resolve(2));
      EXPECT_EQ(tracker.coObservations().count({1, 2}), 0u);
      EXPECT_EQ(tracker.state(2)->labelledClass(), 5);
    } else {
      EXPECT_EQ(merges, 1);  // at the 4th spill frame
      EXPECT_EQ(tracker.labels().resolve(2), 1);
    }
  }
}

TEST_F(WallScene, SameClassPiecesMergeAndPoolTheirCounts) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  // A table top seen in two pieces of one mask (e.g. split by an occluder), sometimes whole.
  step(&tracker, &map, columns(320, 7, 7, true));
  step(&tracker, &map, columns(320, 7, 7, true));
  int merges = 0;
  for (int k = 0; k < 4; ++k) {
    merges += step(&tracker, &map, columns(320, 7, 7, true)).merges;
    merges += step(&tracker, &map, columns(640, 7, 0)).merges;
  }
  EXPECT_EQ(merges, 1);
  EXPECT_EQ(tracker.labels().resolve(2), 1);
  ASSERT_EQ(tracker.merges().size(), 1u);
  EXPECT_EQ(tracker.merges()[0].frame, 10);
  const SuperpointState* s = tracker.state(2);
  ASSERT_NE(s, nullptr);
  // 6 two-piece frames (12 surface counts) and 4 whole frames: pooled after the merge.
  EXPECT_EQ(s->class_counts.at(7), 16.0);
  int instance_frames = 0;
  for (const auto& [id, count] : s->instance_counts) instance_frames += count;
  EXPECT_EQ(instance_frames, 16);
  EXPECT_EQ(s->instance(), 1);
}

TEST(LabelRegistry, MergesResolveToTheOldestId) {
  LabelRegistry labels;
  for (int i = 0; i < 5; ++i) EXPECT_EQ(labels.create(), i + 1);
  EXPECT_EQ(labels.merge(4, 2), 2);
  EXPECT_EQ(labels.merge(5, 4), 2);
  EXPECT_EQ(labels.resolve(5), 2);
  EXPECT_EQ(labels.resolve(3), 3);
  EXPECT_EQ(labels.resolve(0), 0);
  EXPECT_EQ(labels.resolve(99), 0);
  EXPECT_FALSE(labels.isRoot(4));
  EXPECT_THROW(labels.merge(1, 42), Error);
  LabelRegistry copy;
  copy.restore(labels.parents());
  EXPECT_EQ(copy.resolve(5), 2);
  EXPECT_THROW(copy.restore({0, 2}), Error);
}

// A renumbered registry: the given roots live, every other label up to its size retired (it
// resolves to none and cannot merge), new labels above it; it saves and loads as it is.
TEST(LabelRegistry, RenumberingRetiresEveryOtherLabel) {
  LabelRegistry labels;
  for (int i = 0; i < 4; ++i) labels.create();
  labels.merge(4, 3);
  labels.renumber({2, 7}, 9);
  EXPECT_EQ(labels.size(), 9);
  EXPECT_EQ(labels.resolve(2), 2);
  EXPECT_EQ(labels.resolve(7), 7);
  for (const int32_t retired : {1, 3, 4, 5, 6, 8, 9}) {
    EXPECT_EQ(labels.resolve(retired), 0) << retired;
    EXPECT_FALSE(labels.isRoot(retired)) << retired;
  }
  EXPECT_THROW(labels.merge(2, 3), Error);
  EXPECT_EQ(labels.create(), 10);
  EXPECT_EQ(labels.merge(10, 7), 7);
  LabelRegistry copy;
  copy.restore(labels.parents());
  EXPECT_EQ(copy.parents(), labels.parents());
  EXPECT_EQ(copy.resolve(10), 7);
  EXPECT_EQ(copy.resolve(5), 0);
  const std::vector<int32_t> parents = labels.parents();
  EXPECT_THROW(labels.renumber({2, 12}, 11), Error);  // 12 outside 1..11
  EXPECT_EQ(labels.parents(), parents);
}

TEST(LabelRegistry, LongChainsResolveAndCompress) {
  LabelRegistry labels;
  for (int i = 0; i < 6; ++i) labels.create();
  // Each merge puts the previous root under a smaller one: 6 -> 5 -> 4 -> 3 -> 2 -> 1.
  for (int32_t keep = 5; keep >= 1; --keep) EXPECT_EQ(labels.merge(keep + 1, keep), keep);
  EXPECT_EQ(labels.parents(), (std::vector<int32_t>{0, 1, 1, 2, 3, 4, 5}));
  EXPECT_EQ(labels.resolve(6), 1);
  // The path from 6 now points at the root; 2 (a root's child) was never longer.
  EXPECT_EQ(labels.parents(), (std::vector<int32_t>{0, 1, 1, 1, 1, 1, 1}));
  labels.create();                   // 7
  labels.create();                   // 8
  EXPECT_EQ(labels.merge(8, 7), 7);  // 8 -> 7
  EXPECT_EQ(labels.merge(7, 1), 1);  // 8 -> 7 -> 1
  labels.flatten();
  EXPECT_EQ(labels.parents()[8], 1);
  for (int32_t l = 1; l <= 8; ++l) EXPECT_EQ(labels.resolve(l), 1) << l;
}

}  // namespace
}  // namespace panmap

namespace panmap {
namespace {

// Super-points 1..4 where 2 was merged into 1; only 1 (through its merged label 2) and 4 still
// hold votes. 3 is forgotten with its co-observations; the others keep their counts.
TEST(SuperpointTracker, ForgetsSuperpointsWithoutVotes) {
  SuperpointTracker tracker{SuperpointConfig{}};
  SuperpointTracker::Snapshot s;
  s.parents = {0, 1, 1, 3, 4};
  s.states[1].class_counts[5] = 3.0;
  s.states[3].class_counts[7] = 1.0;
  s.states[4].class_counts[0] = 2.0;
  s.co_observed[{1, 3}] = 2;
  s.co_observed[{1, 4}] = 5;
  s.co_observed[{3, 4}] = 1;
  tracker.restore(s);
  std::vector<uint8_t> has_votes = {0, 1, 0, 0, 1};
  EXPECT_EQ(1u, tracker.forgetUnvoted(has_votes));
  ASSERT_EQ(2u, tracker.states().size());
  EXPECT_EQ(3.0, tracker.states().at(1).class_counts.at(5));
  EXPECT_EQ(2.0, tracker.states().at(4).class_counts.at(0));
  ASSERT_EQ(1u, tracker.coObservations().size());
  EXPECT_EQ(5, tracker.coObservations().at({1, 4}));
  // Labels beyond the flags (created after they were computed) count as unvoted.
  EXPECT_EQ(2u, tracker.forgetUnvoted({0, 0}));
  EXPECT_TRUE(tracker.states().empty());
}

// Three super-points over instances 1-3, as a repair finds them before it renumbers.
SuperpointTracker trackerWithInstances() {
  SuperpointTracker tracker{SuperpointConfig()};
  SuperpointTracker::Snapshot s;
  s.parents = {0, 1, 2, 3};
  s.states[1].instance_counts = {{1, 4}, {2, 1}};
  s.states[2].instance_counts = {{2, 3}};
  s.states[3].instance_counts = {{3, 2}, {1, 2}};
  s.next_instance = 4;
  tracker.restore(s);
  return tracker;
}

TEST(SuperpointTrackerInstances, RenumberingRenamesEveryCountAndContinuesAfterIt) {
  SuperpointTracker tracker = trackerWithInstances();
  // 1 -> 7, 3 -> 1, 2 keeps its id; new instances from 9 on.
  tracker.renumberInstances({{1, 7}, {3, 1}}, 9);
  EXPECT_EQ(tracker.numInstances(), 8);
  EXPECT_EQ(tracker.state(1)->instance_counts, (std::map<int32_t, int>{{2, 1}, {7, 4}}));
  EXPECT_EQ(tracker.state(1)->instance(), 7);
  EXPECT_EQ(tracker.state(2)->instance(), 2);
  // The tie of 3 and 1 (two frames each) now reads 1 and 7: the smaller id still wins.
  EXPECT_EQ(tracker.state(3)->instance_counts, (std::map<int32_t, int>{{1, 2}, {7, 2}}));
  EXPECT_EQ(tracker.state(3)->instance(), 1);
}

TEST(SuperpointTrackerInstances, ARenumberingThatWouldJoinOrLoseInstancesChangesNothing) {
  SuperpointTracker tracker = trackerWithInstances();
  const SuperpointTracker::Snapshot before = tracker.snapshot();
  EXPECT_THROW(tracker.renumberInstances({{1, 2}}, 4), Error);          // 1 and 2 as one
  EXPECT_THROW(tracker.renumberInstances({{1, 5}}, 5), Error);          // 5 not below next
  EXPECT_THROW(tracker.renumberInstances({{2, 0}}, 4), Error);          // no id
  EXPECT_THROW(tracker.renumberInstances({{1, 4}, {2, 1}}, 4), Error);  // 4 not below next
  EXPECT_EQ(tracker.numInstances(), before.next_instance - 1);
  for (const auto& [label, state] : before.states) {
    EXPECT_EQ(tracker.state(label)->instance_counts, state.instance_counts) << label;
  }
}

// Super-points 1, 2 (2 merged away into 1) and 3, 4 renamed 1 -> 12, 3 -> 5, 4 -> 2: states,
// co-observations and apart counts follow, pairs stay ordered, the merge names its survivor by
// the new id, and labels up to 12 not given are retired.
TEST(SuperpointTrackerRenumbering, EveryRecordFollowsTheNewIds) {
  SuperpointTracker tracker{SuperpointConfig()};
  SuperpointTracker::Snapshot s;
  s.parents = {0, 1, 1, 3, 4};
  s.states[1].class_counts = {{5, 3.0}};
  s.states[3].class_counts = {{7, 1.0}};
  s.states[4].class_counts = {{9, 2.0}};
  s.co_observed = {{{1, 3}, 2}, {{3, 4}, 5}};
  s.apart = {{{1, 4}, 1}};
  s.merges = {SuperpointMerge{1, 2, 6}};
  tracker.restore(s);
  tracker.renumberSuperpoints({{1, 12}, {3, 5}, {4, 2}}, 12);
  EXPECT_EQ(tracker.states().size(), 3u);
  EXPECT_EQ(tracker.state(12)->class_counts, (std::map<int32_t, double>{{5, 3.0}}));
  EXPECT_EQ(tracker.state(5)->class_counts, (std::map<int32_t, double>{{7, 1.0}}));
  EXPECT_EQ(tracker.state(2)->class_counts, (std::map<int32_t, double>{{9, 2.0}}));
  EXPECT_EQ(tracker.state(1), nullptr);
  EXPECT_EQ(tracker.state(3), nullptr);
  EXPECT_EQ(tracker.coObservations(),
            (std::map<std::pair<int32_t, int32_t>, int>{{{5, 12}, 2}, {{2, 5}, 5}}));
  EXPECT_EQ(tracker.apartCounts(), (std::map<std::pair<int32_t, int32_t>, int>{{{2, 12}, 1}}));
  ASSERT_EQ(tracker.merges().size(), 1u);
  EXPECT_EQ(tracker.merges()[0].kept, 12);
  EXPECT_EQ(tracker.merges()[0].removed, 0);
  EXPECT_EQ(tracker.merges()[0].frame, 6);
  EXPECT_EQ(tracker.labels().size(), 12);
  EXPECT_EQ(tracker.labels().resolve(1), 0);
  EXPECT_EQ(tracker.labels().resolve(12), 12);
}

TEST(SuperpointTrackerRenumbering, IdsThatDoNotFitChangeNothing) {
  SuperpointTracker tracker{SuperpointConfig()};
  SuperpointTracker::Snapshot s;
  s.parents = {0, 1, 1, 3};
  s.states[1].class_counts = {{5, 3.0}};
  s.states[3].class_counts = {{7, 1.0}};
  s.co_observed = {{{1, 3}, 2}};
  tracker.restore(s);
  const auto same = [&tracker, &s] {
    const SuperpointTracker::Snapshot now = tracker.snapshot();
    return now.parents == s.parents && now.states.size() == s.states.size() &&
           now.co_observed == s.co_observed;
  };
  EXPECT_THROW(tracker.renumberSuperpoints({{1, 4}}, 5), Error);                  // 3 has no id
  EXPECT_THROW(tracker.renumberSuperpoints({{1, 4}, {3, 4}}, 5), Error);          // one id for two
  EXPECT_THROW(tracker.renumberSuperpoints({{1, 4}, {3, 6}}, 5), Error);          // 6 beyond 5
  EXPECT_THROW(tracker.renumberSuperpoints({{1, 4}, {2, 1}, {3, 5}}, 5), Error);  // 2 merged
  EXPECT_TRUE(same());
}

}  // namespace
}  // namespace panmap
