#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "canonical_superpoints.h"
#include "mapper/box_scene.h"
#include "panmap/core/error.h"
#include "panmap/loop/frame_store.h"
#include "panmap/loop/map_repair.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// The box scene mapped with every frame kept in a frame store, as the mapper process does.
class MapRepair : public BoxScene {
 protected:
  // with_masks: the store also keeps each frame's segmentation (the mapper process does);
  // frames from `unmasked_from` on are mapped (and stored) without one, as when a mask comes
  // too late.
  std::unique_ptr<Mapper> mapWithStore(int frames, FrameStore* store, bool with_masks = false,
                                       int unmasked_from = 1 << 30) {
    auto mapper = std::make_unique<Mapper>(config());
    for (int k = 0; k < frames; ++k) {
      RgbdFrame frame;
      PanopticFrame panoptic;
      frameAt(k, &frame, &panoptic);
      const PanopticFrame* used = k < unmasked_from ? &panoptic : nullptr;
      const FrameStats stats = mapper->integrate(frame, pose(k), used);
      const GeometricSegments geometric = mapper->lastGeometricSegments();
      store->add(frame, stats.T_W_C, mapper->lastPixelLabels(), with_masks ? used : nullptr,
                 &geometric);
    }
    return mapper;
  }
  static FrameStoreConfig storeConfig(const std::string& folder) {
    FrameStoreConfig c;
    c.folder = folder;
    c.store_color = true;
    return c;
  }
  static Eigen::Isometry3d correction() {
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    D.linear() = Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    D.translation() = Eigen::Vector3d(0.05, -0.03, 0.01);
    return D;
  }
  // A back-end's correction of one keyframe: its pose moved by D.
  static PoseCorrection keyframeCorrection(const Mapper& mapper, size_t frame,
                                           const Eigen::Isometry3d& D) {
    PoseCorrection c;
    c.correction_id = 7;
    c.utime = 1000000;
    StampedPose p = mapper.trajectory()[frame];
    p.T_W_C = D * p.T_W_C;
    c.poses.push_back(p);
    return c;
  }
};

TEST_F(MapRepair, AKeyframeCorrectionRepairsTheMapFromTheStore) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(6, &store);
  const Eigen::Isometry3d D = correction();
  const MapRepairResult result = repairMap(mapper.get(), &store, keyframeCorrection(*mapper, 3, D));
  EXPECT_EQ(result.correction_id, 7);
  EXPECT_EQ(result.matched, 1);
  EXPECT_TRUE(result.unknown_utimes.empty());
  ASSERT_TRUE(result.reintegration.completed);
  EXPECT_EQ(result.reintegration.frames, 6u);
  EXPECT_EQ(result.reintegration.frames_moved, 6u);
  EXPECT_NEAR(result.max_rotation_rad, 0.03, 1e-9);

  // One corrected keyframe and nothing else: the whole trajectory moves by its D, and the map
  // is the one the same frames give at those poses, bit for bit.
  test::TempDir other;
  FrameStore reference_store(storeConfig(other.path("store")));
  auto reference = mapWithStore(6, &reference_store);
  // applyCorrection recovers D from the keyframe's two poses, to rounding.
  const std::vector<StampedPose>& poses = mapper->trajectory();
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_TRUE(poses[i].T_W_C.isApprox(D * reference->trajectory()[i].T_W_C, 1e-12)) << i;
  }
  ASSERT_TRUE(reference->reintegrate(poses, storeLoader(&reference_store)).completed);
  EXPECT_EQ(mapper->serialize(), reference->serialize());

  // The store holds the poses the frames are now integrated with, also after reopening.
  const auto reopened = FrameStore::open(dir.path("store"));
  const std::vector<StampedPose> stored = reopened->trajectory();
  ASSERT_EQ(stored.size(), 6u);
  for (size_t i = 0; i < stored.size(); ++i) {
    EXPECT_EQ(stored[i].utime, mapper->trajectory()[i].utime);
    EXPECT_TRUE(stored[i].T_W_C.isApprox(mapper->trajectory()[i].T_W_C, 1e-15)) << i;
  }
}

// With the segmentations stored, the frames are mapped again at the corrected poses (the map
// of a mapper that had those poses from the start; frames mapped without masks again
// without); told not to, the repair re-integrates.
TEST_F(MapRepair, WithTheMasksStoredTheFramesAreMappedAgain) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(6, &store, true, 4);  // the last two mapped without masks
  ASSERT_EQ(store.sizeWithPanoptic(), 4u);
  const Eigen::Isometry3d D = correction();
  const MapRepairResult result = repairMap(mapper.get(), &store, keyframeCorrection(*mapper, 3, D));
  ASSERT_TRUE(result.reintegration.completed);
  EXPECT_TRUE(result.reintegration.reassociated);
  EXPECT_NE(describe(result).find("6 frames mapped again"), std::string::npos) << describe(result);
  // The four frames stored with masks kept their geometric segments: not segmented again.
  EXPECT_EQ(result.reintegration.frames_with_kept_segments, 4u);
  EXPECT_NE(describe(result).find("kept geometric segments of 4 frames"), std::string::npos)
      << describe(result);
  // The stored frames (their colour is a JPEG) at the repaired poses.
  Mapper reference(config());
  for (const StampedPose& p : mapper->trajectory()) {
    StoredFrame stored = store.load(p.utime);
    stored.rgbd.frame_id = p.frame_id;  // not stored; the repaired trajectory keeps its own
    reference.integrate(stored.rgbd, p.T_W_C, stored.has_panoptic ? &stored.panoptic : nullptr);
  }
  // The same map, but for the super-points' ids: the repair kept the old map's.
  EXPECT_EQ(test::canonicalBytes(*mapper), test::canonicalBytes(reference));
  EXPECT_NE(describe(result).find("super-points"), std::string::npos) << describe(result);

  test::TempDir other;
  FrameStore kept(storeConfig(other.path("store")));
  auto reintegrated = mapWithStore(6, &kept, true);
  MapRepairConfig config;
  config.reassociate = false;
  const MapRepairResult plain =
      repairMap(reintegrated.get(), &kept, keyframeCorrection(*reintegrated, 3, D), config);
  ASSERT_TRUE(plain.reintegration.completed);
  EXPECT_FALSE(plain.reintegration.reassociated);
  EXPECT_NE(describe(plain).find("re-integrated"), std::string::npos);
}

TEST_F(MapRepair, UtimesAFewMicrosecondsOffMatchWithinTheDefaultTolerance) {
  // A back-end that keeps stamps as double seconds gives them back a few microseconds off.
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(4, &store);
  PoseCorrection c = keyframeCorrection(*mapper, 1, correction());
  c.poses[0].utime += 7;
  const std::vector<uint8_t> before = mapper->serialize();
  MapRepairConfig exact;
  exact.match_tolerance_us = 0;
  try {
    repairMap(mapper.get(), &store, c, exact);
    FAIL() << "a utime 7 us off matched with tolerance 0";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("7 us from the nearest mapped frame, tolerance 0 us"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(mapper->serialize(), before);
  const MapRepairResult result = repairMap(mapper.get(), &store, c);
  EXPECT_EQ(result.matched, 1);
  EXPECT_TRUE(result.unknown_utimes.empty());
  EXPECT_TRUE(result.reintegration.completed);
}

TEST_F(MapRepair, UnknownUtimesAreCountedNamedAndNeverGuessed) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(4, &store);
  PoseCorrection c = keyframeCorrection(*mapper, 1, correction());
  StampedPose stranger = c.poses[0];
  stranger.utime = 5000000;  // no frame was mapped then
  c.poses.push_back(stranger);
  const MapRepairResult result = repairMap(mapper.get(), &store, c);
  EXPECT_EQ(result.matched, 1);
  EXPECT_EQ(result.unknown_utimes, std::vector<int64_t>{5000000});
  EXPECT_NE(describe(result).find("1 of 2 poses matched (unknown utime 5000000)"),
            std::string::npos)
      << describe(result);

  // Only unknown utimes: refused, naming the correction and a utime; nothing changes.
  const std::vector<uint8_t> before = mapper->serialize();
  PoseCorrection unknown;
  unknown.correction_id = 8;
  unknown.poses.push_back(stranger);
  try {
    repairMap(mapper.get(), &store, unknown);
    FAIL() << "a correction of unknown frames was applied";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("correction 8: none of its 1 utimes is a mapped frame"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(mapper->serialize(), before);
  // An invalid correction (utimes out of order) is refused the same way.
  PoseCorrection disordered = keyframeCorrection(*mapper, 2, correction());
  disordered.poses.push_back(keyframeCorrection(*mapper, 0, correction()).poses[0]);
  EXPECT_THROW(repairMap(mapper.get(), &store, disordered), Error);
  EXPECT_EQ(mapper->serialize(), before);
}

TEST_F(MapRepair, AFrameLostFromTheStoreOrAnAbandonedRepairChangesNothing) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(5, &store);
  const std::vector<uint8_t> before = mapper->serialize();
  const PoseCorrection c = keyframeCorrection(*mapper, 4, correction());

  // Abandoned halfway (a newer correction arrived): map and stored poses as they were.
  const MapRepairResult abandoned =
      repairMap(mapper.get(), &store, c, {}, [](size_t done, size_t) { return done < 2; });
  EXPECT_FALSE(abandoned.reintegration.completed);
  EXPECT_NE(describe(abandoned).find("abandoned"), std::string::npos);
  EXPECT_EQ(mapper->serialize(), before);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_TRUE(store.trajectory()[i].T_W_C.isApprox(mapper->trajectory()[i].T_W_C, 1e-15));
  }

  // A frame's depth file is gone: the error names the frame; nothing changes.
  const int64_t lost = mapper->trajectory()[2].utime;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path("store/frames"))) {
    if (entry.path().filename().string().rfind(std::to_string(lost) + ".depth", 0) == 0) {
      std::filesystem::remove(entry.path());
    }
  }
  try {
    repairMap(mapper.get(), &store, c);
    FAIL() << "a repair with a lost frame went ahead";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(lost)), std::string::npos) << e.what();
  }
  EXPECT_EQ(mapper->serialize(), before);
}

}  // namespace
}  // namespace panmap
