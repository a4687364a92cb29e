// A loop closure's repair on its own thread while frames keep being mapped (issue 22).
#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "mapper/box_scene.h"
#include "panmap/core/error.h"
#include "panmap/loop/background_repair.h"
#include "panmap/loop/frame_store.h"
#include "panmap/loop/map_repair.h"
#include "panmap/loop/pose_correction.h"
#include "panmap/occupancy/occupancy_map.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// The TSDF of a map (distance, weight and colour of every voxel, block by block in index
// order), without the label votes: frames mapped during a repair are associated against the
// map as it was, so their votes can differ from a run that mapped them after the repair.
std::vector<std::tuple<int, int, int, std::vector<float>>> geometryOf(const TsdfMap& map) {
  std::vector<std::tuple<int, int, int, std::vector<float>>> out;
  for (const auto& block : map.blocks()) {
    std::vector<float> values;
    for (const Voxel& v : block->voxels) {
      values.push_back(v.sdf_m);
      values.push_back(v.weight);
    }
    out.emplace_back(block->index.x(), block->index.y(), block->index.z(), std::move(values));
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Holds the repair's thread at its first frame until the test opens it.
class Gate {
 public:
  void wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this] { return open_; });
  }
  void open() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      open_ = true;
    }
    cv_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
};

// Opens a gate when it goes out of scope: declared after the repair, it is destroyed first,
// so a failed assertion never leaves the repair's thread waiting at the gate.
struct OpenAtExit {
  Gate* gate;
  ~OpenAtExit() { gate->open(); }
};

class BackgroundRepairTest : public BoxScene {
 protected:
  void integrate(Mapper* mapper, int k, FrameStore* store) {
    RgbdFrame frame;
    PanopticFrame panoptic;
    frameAt(k, &frame, &panoptic);
    const FrameStats stats = mapper->integrate(frame, pose(k), &panoptic);
    store->add(frame, stats.T_W_C, mapper->lastPixelLabels());
  }
  // integrate() that also stores the frame's masks: a repair then maps the frames again.
  void integrateWithMasks(Mapper* mapper, int k, FrameStore* store) {
    RgbdFrame frame;
    PanopticFrame panoptic;
    frameAt(k, &frame, &panoptic);
    const FrameStats stats = mapper->integrate(frame, pose(k), &panoptic);
    store->add(frame, stats.T_W_C, mapper->lastPixelLabels(), &panoptic);
  }
  // A repair of `mapper` from `store` whose mapping again waits at `gate` (its occupancy pass
  // loads the frames without masks and does not wait).
  static std::unique_ptr<BackgroundRepair> gatedRepair(Mapper* mapper, FrameStore* store,
                                                       const MapRepairConfig& config, Gate* gate) {
    const PanopticFrameLoader load = storePanopticLoader(store);
    return std::make_unique<BackgroundRepair>(
        mapper, storeLoader(store), store, config,
        [gate, load](int64_t utime, RgbdFrame* frame, PanopticFrame* panoptic,
                     GeometricSegments* kept) {
          gate->wait();
          return load(utime, frame, panoptic, kept);
        });
  }
  std::unique_ptr<Mapper> mapWithStore(int frames, FrameStore* store) {
    auto mapper = std::make_unique<Mapper>(config());
    for (int k = 0; k < frames; ++k) integrate(mapper.get(), k, store);
    return mapper;
  }
  static FrameStoreConfig storeConfig(const std::string& folder) {
    FrameStoreConfig c;
    c.folder = folder;
    return c;
  }
  static Eigen::Isometry3d move(double angle_rad, const Eigen::Vector3d& t) {
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    D.linear() = Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    D.translation() = t;
    return D;
  }
  // A back-end's correction of keyframe `frame`: its pose moved by D.
  static PoseCorrection keyframeCorrection(const Mapper& mapper, size_t frame,
                                           const Eigen::Isometry3d& D, int64_t id) {
    PoseCorrection c;
    c.correction_id = id;
    c.utime = 1000000;
    StampedPose p = mapper.trajectory()[frame];
    p.T_W_C = D * p.T_W_C;
    c.poses.push_back(p);
    return c;
  }
};

// The repair holds at its first frame while two more frames are mapped; once let go it takes
// them too, and the map swapped in has the geometry of the six old frames at their corrected
// poses plus the two new ones at theirs: what a repair that blocked mapping gives.
TEST_F(BackgroundRepairTest, FramesMappedDuringTheRepairAreInTheRepairedMap) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(6, &store);
  const Eigen::Isometry3d D = move(0.03, {0.05, -0.03, 0.01});
  const PoseCorrection correction = keyframeCorrection(*mapper, 3, D, 7);

  Gate gate;
  const FrameLoader store_loader = storeLoader(&store);
  int loads = 0;  // the repair's thread only
  BackgroundRepair repair(
      mapper.get(),
      [&](int64_t utime, RgbdFrame* frame, LabelImage* labels) {
        if (loads++ == 0) gate.wait();
        store_loader(utime, frame, labels);
      },
      &store);
  const MapRepairResult started = repair.start(correction);
  EXPECT_EQ(started.matched, 1);
  EXPECT_FALSE(started.reintegration.completed);
  for (int k = 6; k < 8; ++k) {
    integrate(mapper.get(), k, &store);
    repair.frameIntegrated();
    EXPECT_FALSE(repair.poll()) << "swapped in before it had the frames";
  }
  EXPECT_TRUE(repair.running());
  EXPECT_EQ(repair.framesTotal(), 8);
  EXPECT_EQ(repair.framesDone(), 0);
  gate.open();
  const std::optional<MapRepairResult> done = repair.finish();
  ASSERT_TRUE(done);
  EXPECT_FALSE(repair.running());
  ASSERT_TRUE(done->reintegration.completed) << done->failure;
  EXPECT_EQ(done->correction_id, 7);
  EXPECT_EQ(done->reintegration.frames, 8u);
  EXPECT_EQ(done->reintegration.frames_moved, 6u);
  EXPECT_EQ(repair.framesDone(), 8);

  // The six frames the correction covered moved by D, the two mapped during it did not.
  const std::vector<StampedPose>& poses = mapper->trajectory();
  ASSERT_EQ(poses.size(), 8u);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Isometry3d expected = k < 6 ? D * pose(k) : pose(k);
    EXPECT_TRUE(poses[k].T_W_C.isApprox(expected, 1e-9)) << k;
  }
  const std::vector<StampedPose> stored = store.trajectory();
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(stored[k].T_W_C.isApprox(poses[k].T_W_C, 1e-15)) << k;

  // The same frames at the same poses, re-integrated in one go.
  test::TempDir other;
  FrameStore reference_store(storeConfig(other.path("store")));
  auto reference = mapWithStore(8, &reference_store);
  ASSERT_TRUE(reference->reintegrate(poses, storeLoader(&store)).completed);
  EXPECT_EQ(geometryOf(mapper->map()), geometryOf(reference->map()));
  EXPECT_GT(mapper->map().numBlocks(), 0u);
}

// Frames keep coming, so the repair's thread is never done at the moment the mapping thread
// asks right after handing it a frame: poll() takes the last frames itself (it once waited for
// an idle worker, and a frame every 200 ms kept it from ever swapping the repair in).
TEST_F(BackgroundRepairTest, PollSwapsTheRepairInWhenItIsAFrameBehind) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(6, &store);
  BackgroundRepair repair(mapper.get(), &store);
  repair.start(keyframeCorrection(*mapper, 3, move(0.03, {0.05, -0.03, 0.01}), 7));
  while (repair.framesDone() < 6) std::this_thread::yield();  // its thread has every frame
  integrate(mapper.get(), 6, &store);
  repair.frameIntegrated();  // one frame behind now
  const std::optional<MapRepairResult> done = repair.poll();
  ASSERT_TRUE(done);
  ASSERT_TRUE(done->reintegration.completed) << done->failure;
  EXPECT_EQ(done->reintegration.frames, 7u);
  EXPECT_EQ(mapper->trajectory().size(), 7u);
  EXPECT_FALSE(repair.running());
}

// A newer correction while a repair runs abandons it; the map is then the one the newer
// correction alone gives, bit for bit, and the older one is never applied.
TEST_F(BackgroundRepairTest, ANewerCorrectionSupersedesTheRunningRepair) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(6, &store);
  BackgroundRepair repair(mapper.get(), &store);
  repair.start(keyframeCorrection(*mapper, 2, move(0.05, {0.1, 0.0, 0.0}), 1));
  const PoseCorrection newer = keyframeCorrection(*mapper, 4, move(-0.02, {0.0, 0.04, 0.0}), 2);
  repair.start(newer);
  EXPECT_EQ(repair.superseded(), 1);
  const std::optional<MapRepairResult> done = repair.finish();
  ASSERT_TRUE(done && done->reintegration.completed);
  EXPECT_EQ(done->correction_id, 2);

  test::TempDir other;
  FrameStore reference_store(storeConfig(other.path("store")));
  auto reference = mapWithStore(6, &reference_store);
  ASSERT_TRUE(repairMap(reference.get(), &reference_store, newer).reintegration.completed);
  EXPECT_EQ(mapper->serialize(), reference->serialize());
}

// A correction that names no mapped frame is refused by name and leaves the running repair
// alone; a frame that cannot be loaded fails the repair by name and leaves the map as it was.
TEST_F(BackgroundRepairTest, BadCorrectionsAndLostFramesChangeNothing) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = mapWithStore(5, &store);
  const std::vector<uint8_t> before = mapper->serialize();
  const FrameLoader store_loader = storeLoader(&store);
  const int64_t lost = mapper->trajectory()[3].utime;
  BackgroundRepair repair(mapper.get(), [&](int64_t utime, RgbdFrame* frame, LabelImage* labels) {
    if (utime == lost) throw Error("frame store: no frame of utime " + std::to_string(utime));
    store_loader(utime, frame, labels);
  });
  repair.start(keyframeCorrection(*mapper, 1, move(0.02, {0.02, 0.0, 0.0}), 5));
  PoseCorrection stranger = keyframeCorrection(*mapper, 1, move(0.02, {0.02, 0.0, 0.0}), 6);
  stranger.poses[0].utime += 50000;  // 50 ms from every frame (frames are further apart)
  try {
    repair.start(stranger);
    FAIL() << "a correction of no mapped frame was started";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("correction 6: none of its 1 utimes"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(repair.superseded(), 0);
  const std::optional<MapRepairResult> done = repair.finish();
  ASSERT_TRUE(done);
  EXPECT_EQ(done->correction_id, 5);
  EXPECT_FALSE(done->reintegration.completed);
  EXPECT_NE(done->failure.find("no frame of utime " + std::to_string(lost)), std::string::npos)
      << done->failure;
  EXPECT_NE(describe(*done).find("abandoned: frame store"), std::string::npos) << describe(*done);
  EXPECT_EQ(mapper->serialize(), before);
  EXPECT_FALSE(repair.poll());
}

// With the segmentations stored the repair maps the frames again, and first swaps in the
// occupancy tree of the frames at their corrected poses (occupancy_first): held before it maps
// the first frame again, the map already has the tree a planner needs; the repair then commits
// the same tree. Without occupancy_first the occupancy changes only at the commit.
TEST_F(BackgroundRepairTest, TheOccupancyTreeIsSwappedInBeforeTheFramesAreMappedAgain) {
  for (const bool occupancy_first : {true, false}) {
    SCOPED_TRACE(occupancy_first ? "occupancy first" : "occupancy at the commit");
    test::TempDir dir;
    FrameStore store(storeConfig(dir.path("store")));
    auto mapper = std::make_unique<Mapper>(config());
    for (int k = 0; k < 6; ++k) integrateWithMasks(mapper.get(), k, &store);
    ASSERT_NE(mapper->occupancy(), nullptr);
    const PoseCorrection correction =
        keyframeCorrection(*mapper, 3, move(0.03, {0.05, -0.03, 0.01}), 7);
    // The tree of the six frames at their corrected poses, built here alone.
    const CorrectedTrajectory corrected = applyCorrection(mapper->trajectory(), correction);
    OccupancyMap expected(config().occupancy);
    for (int k = 0; k < 6; ++k) {
      expected.integrate(store.load(corrected.poses[k].utime).rgbd, corrected.poses[k].T_W_C);
    }
    const std::string old_tree = mapper->occupancy()->toBinaryData();
    ASSERT_NE(old_tree, expected.toBinaryData());

    MapRepairConfig repair_config;
    repair_config.occupancy_first = occupancy_first;
    Gate gate;
    const std::unique_ptr<BackgroundRepair> held =
        gatedRepair(mapper.get(), &store, repair_config, &gate);
    BackgroundRepair& repair = *held;
    const OpenAtExit open_at_exit{&gate};
    repair.start(correction);
    if (occupancy_first) {
      const OccupancyMap* before = mapper->occupancy();
      for (int64_t polls = 0; mapper->occupancy() == before; ++polls) {
        ASSERT_LT(polls, 100000000) << "the occupancy tree was never swapped in";
        ASSERT_FALSE(repair.poll()) << "committed while mapping again was held";
        std::this_thread::yield();
      }
      EXPECT_EQ(mapper->occupancy()->toBinaryData(), expected.toBinaryData());
      EXPECT_EQ(repair.framesDone(), 0);
      // The poses change at the commit, with the label-TSDF.
      EXPECT_TRUE(mapper->trajectory()[0].T_W_C.isApprox(pose(0), 1e-12));
    } else {
      EXPECT_FALSE(repair.poll());
      EXPECT_EQ(mapper->occupancy()->toBinaryData(), old_tree);
    }
    gate.open();
    const std::optional<MapRepairResult> done = repair.finish();
    ASSERT_TRUE(done);
    ASSERT_TRUE(done->reintegration.completed) << done->failure;
    EXPECT_TRUE(done->reintegration.reassociated);
    EXPECT_EQ(done->occupancy_swapped_s >= 0.0, occupancy_first);
    EXPECT_EQ(describe(*done).find("occupancy swapped in after") != std::string::npos,
              occupancy_first)
        << describe(*done);
    EXPECT_EQ(mapper->occupancy()->toBinaryData(), expected.toBinaryData());
  }
}

// With reintegrate_first the repair first re-integrates the frames at their corrected poses
// with the super-points they voted for, and swaps that map in while mapping them again is still
// held: the map is then, bit for bit, what a blocking re-integration gives, and the store
// already has the new poses. With occupancy_first too, the tree of the corrected poses comes
// before that map, the label-TSDF and the poses still the old ones. The repair then maps the
// frames again and swaps in the same geometry as one without the early map.
TEST_F(BackgroundRepairTest, TheReintegratedMapIsSwappedInBeforeTheFramesAreMappedAgain) {
  for (const bool occupancy_first : {false, true}) {
    SCOPED_TRACE(occupancy_first ? "the tree first" : "the re-integrated map alone");
    test::TempDir dir;
    FrameStore store(storeConfig(dir.path("store")));
    auto mapper = std::make_unique<Mapper>(config());
    test::TempDir other;
    FrameStore other_store(storeConfig(other.path("store")));
    auto reference = std::make_unique<Mapper>(config());
    for (int k = 0; k < 6; ++k) {
      integrateWithMasks(mapper.get(), k, &store);
      integrateWithMasks(reference.get(), k, &other_store);
    }
    ASSERT_EQ(mapper->serialize(), reference->serialize());
    const std::vector<uint8_t> unrepaired = mapper->serialize();
    const PoseCorrection correction =
        keyframeCorrection(*mapper, 3, move(0.03, {0.05, -0.03, 0.01}), 7);
    const CorrectedTrajectory corrected = applyCorrection(mapper->trajectory(), correction);
    ASSERT_TRUE(reference->reintegrate(corrected.poses, storeLoader(&store)).completed);
    const std::vector<uint8_t> reintegrated = reference->serialize();
    ASSERT_NE(unrepaired, reintegrated);
    const std::string repaired_tree = reference->occupancy()->toBinaryData();

    MapRepairConfig repair_config;
    repair_config.occupancy_first = occupancy_first;
    repair_config.reintegrate_first = true;
    Gate gate;
    const std::unique_ptr<BackgroundRepair> held =
        gatedRepair(mapper.get(), &store, repair_config, &gate);
    BackgroundRepair& repair = *held;
    const OpenAtExit open_at_exit{&gate};
    repair.start(correction);
    const OccupancyMap* tree_before = mapper->occupancy();
    bool tree_alone = false;  // seen: the repaired tree with the old poses
    // The poses change with the swap (the frame the correction names moved by 5 cm).
    for (int64_t polls = 0; mapper->trajectory()[3].T_W_C.isApprox(pose(3), 1e-12); ++polls) {
      ASSERT_LT(polls, 100000000) << "the re-integrated map was never swapped in";
      ASSERT_FALSE(repair.poll()) << "committed while mapping again was held";
      if (mapper->occupancy() != tree_before &&
          mapper->trajectory()[3].T_W_C.isApprox(pose(3), 1e-12)) {
        if (!tree_alone) {
          EXPECT_EQ(mapper->occupancy()->toBinaryData(), repaired_tree);
        }
        tree_alone = true;
      }
      std::this_thread::yield();
    }
    EXPECT_EQ(tree_alone, occupancy_first);
    EXPECT_EQ(mapper->serialize(), reintegrated);
    EXPECT_EQ(repair.framesDone(), 0);
    const std::vector<StampedPose> stored = store.trajectory();
    for (int k = 0; k < 6; ++k) {
      EXPECT_TRUE(stored[k].T_W_C.isApprox(corrected.poses[k].T_W_C, 1e-15)) << k;
    }

    gate.open();
    const std::optional<MapRepairResult> done = repair.finish();
    ASSERT_TRUE(done);
    ASSERT_TRUE(done->reintegration.completed) << done->failure;
    EXPECT_TRUE(done->reintegration.reassociated);
    EXPECT_GE(done->map_swapped_s, 0.0);
    EXPECT_GE(done->occupancy_swapped_s, 0.0);
    if (occupancy_first) {
      EXPECT_LT(done->occupancy_swapped_s, done->map_swapped_s);
    } else {
      EXPECT_EQ(done->occupancy_swapped_s, done->map_swapped_s);
    }
    const std::string line = describe(*done);
    EXPECT_NE(line.find("re-integrated map swapped in after"), std::string::npos) << line;
    EXPECT_EQ(line.find("occupancy swapped in after") != std::string::npos, occupancy_first)
        << line;

    // Mapping again from the map as it was gives the same geometry.
    test::TempDir third;
    FrameStore third_store(storeConfig(third.path("store")));
    auto plain = std::make_unique<Mapper>(config());
    for (int k = 0; k < 6; ++k) integrateWithMasks(plain.get(), k, &third_store);
    ASSERT_TRUE(repairMap(plain.get(), &third_store, correction).reintegration.reassociated);
    EXPECT_EQ(geometryOf(mapper->map()), geometryOf(plain->map()));
    EXPECT_EQ(mapper->occupancy()->toBinaryData(), plain->occupancy()->toBinaryData());
  }
}

// A frame comes, is handed to the repair, and the mapping thread asks at once: the occupancy
// pass is then busy with that frame every time. It hands its tree over anyway once at most
// two frames behind (the first version waited for an idle pass, and at 5 Hz swapped the tree in
// after 80 s instead of 2).
TEST_F(BackgroundRepairTest, TheOccupancyTreeComesWhileFramesKeepComing) {
  test::TempDir dir;
  FrameStore store(storeConfig(dir.path("store")));
  auto mapper = std::make_unique<Mapper>(config());
  for (int k = 0; k < 6; ++k) integrateWithMasks(mapper.get(), k, &store);
  Gate gate;
  const std::unique_ptr<BackgroundRepair> held =
      gatedRepair(mapper.get(), &store, MapRepairConfig{}, &gate);
  BackgroundRepair& repair = *held;
  const OpenAtExit open_at_exit{&gate};
  repair.start(keyframeCorrection(*mapper, 3, move(0.03, {0.05, -0.03, 0.01}), 7));
  const OccupancyMap* before = mapper->occupancy();
  int k = 6;
  for (; k < 46 && mapper->occupancy() == before; ++k) {
    integrateWithMasks(mapper.get(), k, &store);
    repair.frameIntegrated();
    ASSERT_FALSE(repair.poll()) << "committed while mapping again was held";
  }
  EXPECT_NE(mapper->occupancy(), before) << "no tree after " << k - 6 << " frames";
  gate.open();
  const std::optional<MapRepairResult> done = repair.finish();
  ASSERT_TRUE(done && done->reintegration.completed);
  EXPECT_GE(done->occupancy_swapped_s, 0.0);
  EXPECT_EQ(done->reintegration.frames, static_cast<size_t>(k));
}

}  // namespace
}  // namespace panmap
