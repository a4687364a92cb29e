#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "box_scene.h"
#include "canonical_superpoints.h"
#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mapper/objects.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// What a frame store would keep of each integrated frame: the frame and its pixel labels.
struct Recorded {
  RgbdFrame frame;
  LabelImage labels;
  PanopticFrame panoptic;
  GeometricSegments geometric;
};

class Reintegration : public BoxScene {
 protected:
  // Maps `frames` frames, keeping each one as a frame store would.
  // The first `frames` frames mapped and stored; the first `off_frames` of them at
  // off * pose(k) instead of pose(k) (a drift the repair then corrects).
  std::unique_ptr<Mapper> record(int frames, int off_frames = 0,
                                 const Eigen::Isometry3d& off = Eigen::Isometry3d::Identity()) {
    auto mapper = std::make_unique<Mapper>(config());
    for (int k = 0; k < frames; ++k) {
      Recorded r;
      frameAt(k, &r.frame, &r.panoptic);
      mapper->integrate(r.frame, k < off_frames ? off * pose(k) : pose(k), &r.panoptic);
      r.labels = mapper->lastPixelLabels();
      r.geometric = mapper->lastGeometricSegments();
      stored_[r.frame.utime] = r;
    }
    return mapper;
  }
  // The centroids of the box scene's cabinet and fridge, world frame.
  const Eigen::Vector3d cabinet_W{1.1, -0.4, 0.45};
  const Eigen::Vector3d fridge_W{1.1, 0.35, 0.8};
  // Where the first three frames of recordWithGhosts() were mapped: 1.6 m off along y.
  static Eigen::Isometry3d ghostOffset() {
    Eigen::Isometry3d off = Eigen::Isometry3d::Identity();
    off.translation() = Eigen::Vector3d(0.0, 1.6, 0.0);
    return off;
  }
  // Eight frames, the first three mapped ghostOffset() off, so that they leave ghost copies of
  // the cabinet and the fridge; `corrected` receives the trajectory with those three put back.
  std::unique_ptr<Mapper> recordWithGhosts(std::vector<StampedPose>* corrected) {
    std::unique_ptr<Mapper> mapper = record(8, 3, ghostOffset());
    *corrected = mapper->trajectory();
    for (int k = 0; k < 3; ++k) (*corrected)[k].T_W_C = pose(k);
    return mapper;
  }
  // With `kept`, each frame's geometric segments come back with it, as a frame store gives them.
  PanopticFrameLoader panopticLoader(bool kept = false) const {
    return [this, kept](int64_t utime, RgbdFrame* frame, PanopticFrame* panoptic,
                        GeometricSegments* geometric) {
      const auto it = stored_.find(utime);
      if (it == stored_.end()) throw Error("no stored frame of utime " + std::to_string(utime));
      *frame = it->second.frame;
      *panoptic = it->second.panoptic;
      if (kept) *geometric = it->second.geometric;
      return true;
    };
  }
  FrameLoader loader() const {
    return [this](int64_t utime, RgbdFrame* frame, LabelImage* labels) {
      const auto it = stored_.find(utime);
      if (it == stored_.end()) throw Error("no stored frame of utime " + std::to_string(utime));
      *frame = it->second.frame;
      *labels = it->second.labels;
    };
  }
  // The trajectory moved by a world-frame correction D (new pose = D * old pose).
  static std::vector<StampedPose> moved(const Mapper& mapper, const Eigen::Isometry3d& D) {
    std::vector<StampedPose> poses = mapper.trajectory();
    for (StampedPose& p : poses) p.T_W_C = D * p.T_W_C;
    return poses;
  }
  static std::vector<uint8_t> bytes(const Mapper& mapper) { return mapper.serialize(); }

  std::map<int64_t, Recorded> stored_;
};

// The voxel at global voxel coordinates, or null when its block is not allocated.
// The block holding the voxel at global grid index `global` (null when not allocated) and the
// voxel's index in it.
const Block* blockAt(const TsdfMap& map, const Eigen::Vector3i& global, int* i) {
  auto floorDiv = [](int a) {
    return a >= 0 ? a / kBlockSide : -((-a + kBlockSide - 1) / kBlockSide);
  };
  const BlockIndex block(floorDiv(global.x()), floorDiv(global.y()), floorDiv(global.z()));
  const Eigen::Vector3i local = global - block * kBlockSide;
  *i = Block::linear(local.x(), local.y(), local.z());
  return map.findBlock(block);
}

// Whether two voxels' votes are the same (both without votes, or equal slots).
bool sameVotes(const VoxelVotes* a, const VoxelVotes* b) {
  if (!a || !b) return a == b;
  return std::memcmp(a, b, sizeof(VoxelVotes)) == 0;
}

TEST_F(Reintegration, AtTheSamePosesTheMapIsRebuiltBitForBit) {
  auto mapper = record(6);
  const std::vector<uint8_t> before = bytes(*mapper);
  const ReintegrationStats stats = mapper->reintegrate(mapper->trajectory(), loader());
  EXPECT_TRUE(stats.completed);
  EXPECT_EQ(stats.frames, 6u);
  EXPECT_EQ(stats.frames_moved, 0u);
  EXPECT_EQ(stats.blocks_after, stats.blocks_before);
  // Same TSDF, votes, colours, occupancy, super-points and trajectory: the same map file.
  EXPECT_EQ(bytes(*mapper), before);
}

// Tracking had learnt a correction of the given poses (they were 2 cm off from the 7th frame
// on); after a repair the map sits at the back-end's corrected poses, so the correction starts
// again from identity instead of pushing the next frames off by the old drift.
TEST_F(Reintegration, ARepairRestartsTheCorrectionOfTrackedPoses) {
  MapperConfig c = config();
  c.tracking_mode = MapperConfig::TrackingMode::kOn;
  Mapper mapper(c);
  Eigen::Isometry3d off = Eigen::Isometry3d::Identity();
  off.translation() = Eigen::Vector3d(0.02, 0.0, 0.0);
  for (int k = 0; k < 9; ++k) {
    Recorded r;
    PanopticFrame panoptic;
    frameAt(k, &r.frame, &panoptic);
    mapper.integrate(r.frame, k < 6 ? pose(k) : off * pose(k), &panoptic);
    r.labels = mapper.lastPixelLabels();
    stored_[r.frame.utime] = r;
  }
  ASSERT_GT(mapper.poseCorrection().translation().norm(), 0.005)
      << "tracking did not learn the offset";
  ASSERT_TRUE(mapper.reintegrate(mapper.trajectory(), loader()).completed);
  EXPECT_TRUE(mapper.poseCorrection().isApprox(Eigen::Isometry3d::Identity(), 0.0));
  EXPECT_EQ(mapper.poseCorrection().matrix(), Eigen::Matrix4d::Identity());
}

TEST_F(Reintegration, ARigidCorrectionMovesExactlyTheSurfaces) {
  auto mapper = record(6);
  auto reference = record(6);
  const float voxel_m = mapper->map().voxelSize();
  // One block (8 voxels) along x: every voxel's content should reappear one block further (a
  // shift by part of a block would change which blocks the truncation band allocates).
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.translation() = Eigen::Vector3d(kBlockSide * voxel_m, 0.0, 0.0);
  const ReintegrationStats stats = mapper->reintegrate(moved(*mapper, D), loader());
  ASSERT_TRUE(stats.completed);
  EXPECT_EQ(stats.frames_moved, 6u);
  // Every observed voxel one block on, with the same distance, weight and votes up to float
  // noise: the shift changes the rounding of each voxel centre, so a voxel at the edge of a
  // pixel or a point at the face of a voxel may land next door (0.4 % here, bound 1 %).
  size_t compared = 0, missing = 0, sdf_off = 0, weight_off = 0, votes_off = 0;
  for (const auto& block : reference->map().blocks()) {
    for (int i = 0; i < kBlockVoxels; ++i) {
      const Voxel& a = block->voxels[i];
      if (a.weight <= 0.0f) continue;
      const Eigen::Vector3i local(i % kBlockSide, (i / kBlockSide) % kBlockSide,
                                  i / (kBlockSide * kBlockSide));
      int j = 0;
      const Block* moved_block = blockAt(
          mapper->map(), block->index * kBlockSide + local + Eigen::Vector3i(kBlockSide, 0, 0), &j);
      const Voxel* b = moved_block ? &moved_block->voxels[j] : nullptr;
      ++compared;
      if (!b) {
        ++missing;
      } else if (std::abs(b->sdf_m - a.sdf_m) > 1e-4f) {
        ++sdf_off;
      } else if (std::abs(b->weight - a.weight) > 1e-4f * a.weight) {
        ++weight_off;
      } else if (!sameVotes(block->votes(i), moved_block->votes(j))) {
        ++votes_off;
      }
    }
  }
  EXPECT_GT(compared, 10000u);
  const size_t differing = missing + sdf_off + weight_off + votes_off;
  EXPECT_EQ(missing, 0u);
  EXPECT_LE(differing, compared / 100)
      << compared << " voxels: " << missing << " missing, " << sdf_off << " distance, "
      << weight_off << " weight, " << votes_off << " votes";
  // The mesh moved with the voxels, its super-points and classes with it.
  const LabelledMesh a = reference->extractMesh(), b = mapper->extractMesh();
  std::map<std::array<int, 3>, std::array<int32_t, 2>> shifted;
  for (size_t v = 0; v < a.numVertices(); ++v) {
    const Eigen::Vector3f p = a.vertices[v] + Eigen::Vector3f(kBlockSide * voxel_m, 0.0f, 0.0f);
    shifted[{static_cast<int>(std::lround(p.x() / 1e-4f)),
             static_cast<int>(std::lround(p.y() / 1e-4f)),
             static_cast<int>(std::lround(p.z() / 1e-4f))}] = {a.superpoint[v], a.semantic[v]};
  }
  size_t found = 0, same_labels = 0;
  for (size_t v = 0; v < b.numVertices(); ++v) {
    const auto it = shifted.find({static_cast<int>(std::lround(b.vertices[v].x() / 1e-4f)),
                                  static_cast<int>(std::lround(b.vertices[v].y() / 1e-4f)),
                                  static_cast<int>(std::lround(b.vertices[v].z() / 1e-4f))});
    if (it == shifted.end()) continue;
    ++found;
    same_labels += it->second == std::array<int32_t, 2>{b.superpoint[v], b.semantic[v]};
  }
  EXPECT_GE(found, b.numVertices() * 999 / 1000) << found << " of " << b.numVertices();
  EXPECT_GE(same_labels, found * 99 / 100);
  // The trajectory now holds the corrected poses.
  for (size_t i = 0; i < mapper->trajectory().size(); ++i) {
    EXPECT_TRUE(
        mapper->trajectory()[i].T_W_C.isApprox(D * reference->trajectory()[i].T_W_C, 1e-12));
  }
}

TEST_F(Reintegration, TheLiveMeshDropsWhatMovedAway) {
  auto mapper = record(6);
  std::map<std::array<int, 3>, LabelledMesh> view;
  auto apply = [&view](const MeshUpdate& update) {
    for (size_t i = 0; i < update.blocks.size(); ++i) {
      const BlockIndex& b = update.blocks[i];
      view[{b.x(), b.y(), b.z()}] = update.mesh(i);
    }
  };
  apply(mapper->updateMesh());
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);  // half a metre up: most blocks change
  ASSERT_TRUE(mapper->reintegrate(moved(*mapper, D), loader()).completed);
  apply(mapper->updateMesh());
  // What the viewer holds is exactly the new mesh: nothing left where the surfaces were.
  std::set<std::array<float, 3>> held, exported;
  for (const auto& [key, mesh] : view) {
    for (const Eigen::Vector3f& p : mesh.vertices) held.insert({p.x(), p.y(), p.z()});
  }
  const LabelledMesh whole = mapper->extractMesh();
  for (const Eigen::Vector3f& p : whole.vertices) exported.insert({p.x(), p.y(), p.z()});
  EXPECT_GT(exported.size(), 1000u);
  EXPECT_EQ(held, exported);
}

TEST_F(Reintegration, FailureOrAbandonLeavesTheMapAsItWas) {
  auto mapper = record(5);
  const std::vector<uint8_t> before = bytes(*mapper);
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.translation() = Eigen::Vector3d(0.1, 0.0, 0.0);
  const std::vector<StampedPose> poses = moved(*mapper, D);

  // Abandoned after 3 of 5 frames (a newer correction arrived).
  std::vector<size_t> seen;
  const ReintegrationStats abandoned =
      mapper->reintegrate(poses, loader(), [&seen](size_t done, size_t total) {
        EXPECT_EQ(total, 5u);
        seen.push_back(done);
        return done < 3;
      });
  EXPECT_FALSE(abandoned.completed);
  EXPECT_EQ(seen, (std::vector<size_t>{1, 2, 3}));
  EXPECT_EQ(bytes(*mapper), before);

  // A frame that cannot be loaded: the error names it.
  stored_.erase(std::next(stored_.begin(), 2));
  try {
    mapper->reintegrate(poses, loader());
    FAIL() << "a missing frame was not reported";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("utime 66666"), std::string::npos) << e.what();
  }
  EXPECT_EQ(bytes(*mapper), before);

  // Poses that do not match the trajectory, or are not rigid.
  std::vector<StampedPose> short_list(poses.begin(), poses.end() - 1);
  EXPECT_THROW(mapper->reintegrate(short_list, loader()), Error);
  std::vector<StampedPose> renamed = poses;
  renamed[1].utime += 1;
  EXPECT_THROW(mapper->reintegrate(renamed, loader()), Error);
  std::vector<StampedPose> scaled = poses;
  scaled[0].T_W_C.linear() *= 1.5;
  EXPECT_THROW(mapper->reintegrate(scaled, loader()), Error);
  EXPECT_THROW(mapper->reintegrate(poses, FrameLoader()), Error);
  EXPECT_EQ(bytes(*mapper), before);
}

TEST_F(Reintegration, ASavedMapKeepsWhatTheNextRepairNeeds) {
  auto mapper = record(5);
  test::TempDir dir;
  mapper->save(dir.path("map.panmap"));
  auto loaded = Mapper::load(dir.path("map.panmap"));
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  D.translation() = Eigen::Vector3d(0.04, -0.02, 0.0);
  ASSERT_TRUE(mapper->reintegrate(moved(*mapper, D), loader()).completed);
  ASSERT_TRUE(loaded->reintegrate(moved(*loaded, D), loader()).completed);
  EXPECT_EQ(bytes(*loaded), bytes(*mapper));
}

// Mapping the frames again at new poses gives the map of a mapper that got them with those
// poses in the first place (TSDF, votes, super-points, graph, trajectory: the same map file),
// and the mapper maps on from there on the new map.
TEST_F(Reintegration, ARemapIsTheMapOfTheFramesMappedAtTheNewPoses) {
  auto mapper = record(6);
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.linear() = Eigen::AngleAxisd(0.04, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  D.translation() = Eigen::Vector3d(0.05, -0.03, 0.01);
  const std::vector<StampedPose> poses = moved(*mapper, D);
  // A remap with the frames' kept geometric segments skips the depth stages and gives the
  // same map as one that segments every frame again.
  auto again = record(6);
  const ReintegrationStats segmented = again->remap(poses, panopticLoader(false));
  EXPECT_EQ(segmented.frames_with_kept_segments, 0u);
  const ReintegrationStats stats = mapper->remap(poses, panopticLoader(true));
  ASSERT_TRUE(stats.completed);
  EXPECT_TRUE(stats.reassociated);
  EXPECT_EQ(stats.frames, 6u);
  EXPECT_EQ(stats.frames_moved, 6u);
  EXPECT_EQ(stats.frames_with_kept_segments, 6u);
  EXPECT_EQ(bytes(*mapper), bytes(*again));
  // Where the remap's time went: every stage of a frame once, in the pipeline's order, with
  // the samples for the carried-over ids last; no tracking (the poses are the back-end's).
  std::vector<std::string> stages;
  for (const auto& [name, ms] : stats.stage_median_ms) {
    stages.push_back(name);
    EXPECT_GE(ms, 0.0) << name;
  }
  EXPECT_EQ(stages, (std::vector<std::string>{"segmentation", "superpoints", "integration", "graph",
                                              "occupancy", "total", "instance samples"}));
  EXPECT_GE(stats.carry_over_s, 0.0);

  // The same map, but for the super-points' ids (the remap kept the old map's).
  Mapper reference(config());
  for (int k = 0; k < 6; ++k) {
    const Recorded& r = std::next(stored_.begin(), k)->second;
    reference.integrate(r.frame, D * pose(k), &r.panoptic);
  }
  EXPECT_EQ(test::canonicalBytes(*mapper), test::canonicalBytes(reference));
  // Mapping goes on with the new state (its thread pool came with it).
  RgbdFrame frame;
  PanopticFrame panoptic;
  frameAt(6, &frame, &panoptic);
  mapper->integrate(frame, D * pose(6), &panoptic);
  reference.integrate(frame, D * pose(6), &panoptic);
  EXPECT_EQ(test::canonicalBytes(*mapper), test::canonicalBytes(reference));
  EXPECT_EQ(mapper->extractMesh().vertices, reference.extractMesh().vertices);
}

// The id of the object of class c whose centroid is within 0.3 m of p_W (0: none).
int32_t objectNear(const std::vector<MappedObject>& objects, int32_t c,
                   const Eigen::Vector3d& p_W) {
  for (const MappedObject& o : objects) {
    if (o.class_id == c && (o.centroid_W - p_W).norm() < 0.3) return o.id;
  }
  return 0;
}

// The first three frames came 1.6 m off along y: they left a cabinet and a fridge beside the
// real ones, which the later frames then met as new instances. The correction puts those frames
// where they were; a remap maps every frame again and meets the real objects first, yet they
// keep the ids the map had given them (a planner knows them by those), the ghosts are gone,
// and no id names another object than before.
TEST_F(Reintegration, ARemapKeepsTheIdsOfTheObjectsItFindsAgain) {
  std::vector<StampedPose> corrected;
  const std::unique_ptr<Mapper> recorded = recordWithGhosts(&corrected);
  Mapper& mapper = *recorded;
  const Eigen::Isometry3d off = ghostOffset();
  const std::vector<MappedObject> before = computeObjects(mapper);
  const int32_t cabinet = objectNear(before, 3, cabinet_W);
  const int32_t fridge = objectNear(before, 24, fridge_W);
  ASSERT_GT(objectNear(before, 3, off * cabinet_W), 0) << "no ghost: nothing to show";
  ASSERT_GT(cabinet, 0);
  ASSERT_GT(fridge, 0);
  // A remap that numbered its instances afresh would call the real ones 1 and 2.
  ASSERT_GT(std::min(cabinet, fridge), 2);
  const int32_t instances_before = mapper.superpoints().numInstances();

  const ReintegrationStats stats = mapper.remap(corrected, panopticLoader(true));
  ASSERT_TRUE(stats.completed);
  EXPECT_EQ(stats.frames_moved, 3u);
  const std::vector<MappedObject> after = computeObjects(mapper);
  EXPECT_EQ(objectNear(after, 3, cabinet_W), cabinet);
  EXPECT_EQ(objectNear(after, 24, fridge_W), fridge);
  EXPECT_EQ(objectNear(after, 3, off * cabinet_W), 0);
  for (const MappedObject& o : after) {
    if (o.id != cabinet && o.id != fridge) {
      EXPECT_GT(o.id, instances_before) << o.id;
    }
  }
  EXPECT_GE(mapper.superpoints().numInstances(), instances_before);
  // Saved and loaded, the map keeps the ids and where new instances start.
  const std::unique_ptr<Mapper> loaded =
      Mapper::deserialize(mapper.serialize(), "the repaired map");
  EXPECT_EQ(computeObjects(*loaded), after);
  EXPECT_EQ(loaded->superpoints().numInstances(), mapper.superpoints().numInstances());
  // A second repair (here to the same poses) finds the same objects and keeps their ids again,
  // though mapping the frames afresh numbers them 1 and 2 once more.
  ASSERT_TRUE(mapper.remap(corrected, panopticLoader(true)).completed);
  EXPECT_EQ(computeObjects(mapper), after);
}

// Re-integrated at the corrected poses, the ghosts' frames vote again on the real cabinet and
// fridge, for the super-points association gave them 1.6 m away: two super-points (and two
// objects) on one surface, until they rejoin. Then each object is there once, with its class,
// and the super-points of the ghosts resolve to those of the real objects.
TEST_F(Reintegration, ReintegratedSuperpointsRejoinTheOnesTheyCoincideWith) {
  std::vector<StampedPose> corrected;
  const std::unique_ptr<Mapper> recorded = recordWithGhosts(&corrected);
  Mapper& mapper = *recorded;
  const std::vector<MappedObject> before = computeObjects(mapper);
  const int32_t ghost = objectNear(before, 3, ghostOffset() * cabinet_W);
  ASSERT_GT(ghost, 0) << "no ghost: nothing to show";
  const size_t superpoints_before = mapper.superpoints().states().size();

  const ReintegrationStats stats = mapper.reintegrate(corrected, loader());
  ASSERT_TRUE(stats.completed);
  EXPECT_GT(stats.superpoints_rejoined, 0u);
  EXPECT_EQ(mapper.superpoints().states().size(), superpoints_before - stats.superpoints_rejoined);
  const std::vector<MappedObject> after = computeObjects(mapper);
  const auto count = [&after](int32_t c) {
    return std::count_if(after.begin(), after.end(), [c](const MappedObject& o) {
      return o.class_id == c && o.num_voxels >= 50;
    });
  };
  EXPECT_EQ(count(3), 1);
  EXPECT_EQ(count(24), 1);
  EXPECT_GT(objectNear(after, 3, cabinet_W), 0);
  EXPECT_GT(objectNear(after, 24, fridge_W), 0);
  EXPECT_EQ(objectNear(after, 3, ghostOffset() * cabinet_W), 0);
  // The graph follows: no score is left on a super-point that rejoined another.
  for (const auto& [label, scores] : mapper.graphAccumulator().snapshot().scores) {
    EXPECT_EQ(mapper.superpoints().labels().resolve(label), label) << label;
  }
  // Saved and loaded, the map is the same map.
  const std::unique_ptr<Mapper> loaded =
      Mapper::deserialize(mapper.serialize(), "the re-integrated map");
  EXPECT_EQ(computeObjects(*loaded), after);
}

// The super-point holding most mesh vertices within 0.35 m of p_W (0: none there): of an
// object's centroid, its front face.
int32_t superpointNear(const LabelledMesh& mesh, const Eigen::Vector3d& p_W) {
  std::map<int32_t, int> count;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    if ((mesh.vertices[i].cast<double>() - p_W).norm() < 0.35 && mesh.superpoint[i] > 0) {
      ++count[mesh.superpoint[i]];
    }
  }
  int32_t best = 0;
  int most = 0;
  for (const auto& [label, n] : count) {
    if (n > most) std::tie(best, most) = std::make_pair(label, n);
  }
  return best;
}

// The scene of the test above: the super-points a remap finds again keep their ids (the graph
// and the optimiser's labels know them by those), the ghosts' ids are retired, every other
// super-point gets an id the map never gave before, and the map is otherwise the one a remap
// without the renaming makes (but where a tie is broken by the smaller id).
TEST_F(Reintegration, ARemapKeepsTheIdsOfTheSuperpointsItFindsAgain) {
  std::vector<StampedPose> corrected;
  const std::unique_ptr<Mapper> recorded = recordWithGhosts(&corrected);
  Mapper& mapper = *recorded;
  const Eigen::Isometry3d off = ghostOffset();
  const LabelledMesh before = mapper.extractMesh();
  const int32_t cabinet = superpointNear(before, cabinet_W);
  const int32_t fridge = superpointNear(before, fridge_W);
  const int32_t ghost = superpointNear(before, off * cabinet_W);
  ASSERT_GT(cabinet, 0);
  ASSERT_GT(fridge, 0);
  ASSERT_GT(ghost, 0);
  const std::vector<int32_t> live_before = mapper.liveSuperpoints();
  const int32_t size_before = mapper.superpoints().labels().size();

  ReintegrationStats stats = mapper.remap(corrected, panopticLoader(true));
  ASSERT_TRUE(stats.completed);
  const LabelledMesh after = mapper.extractMesh();
  EXPECT_EQ(superpointNear(after, cabinet_W), cabinet);
  EXPECT_EQ(superpointNear(after, fridge_W), fridge);
  EXPECT_EQ(superpointNear(after, off * cabinet_W), 0);
  EXPECT_EQ(mapper.superpoints().labels().resolve(ghost), 0);
  EXPECT_FALSE(mapper.superpoints().labels().isRoot(ghost));
  size_t kept = 0;
  for (const int32_t label : mapper.liveSuperpoints()) {
    const bool old_id = label <= size_before;
    kept += old_id ? 1 : 0;
    if (old_id) {
      EXPECT_TRUE(std::binary_search(live_before.begin(), live_before.end(), label)) << label;
    }
    EXPECT_EQ(mapper.superpoints().labels().resolve(label), label);
  }
  EXPECT_EQ(stats.superpoints, mapper.liveSuperpoints().size());
  EXPECT_EQ(stats.superpoints_kept, kept);
  EXPECT_GE(kept, 2u);
  EXPECT_LT(kept, stats.superpoints);  // the ghosts' and the smallest pieces' are new
  // Most of the surface the frames see kept its super-point's id; the rest is the ghosts'
  // (the first three frames saw them from where they were then).
  EXPECT_GT(stats.superpoint_surface_kept, 0.5);
  EXPECT_LT(stats.superpoint_surface_kept, 1.0);
  // Numbered afresh, the remap's super-points would not keep the ids: the renumbering did
  // something, and nothing else.
  Mapper fresh(config());
  for (int k = 0; k < 8; ++k) {
    const Recorded& r = std::next(stored_.begin(), k)->second;
    fresh.integrate(r.frame, corrected[k].T_W_C, &r.panoptic);
  }
  EXPECT_NE(superpointNear(fresh.extractMesh(), cabinet_W), cabinet);
  // The same surfaces and labels up to the renaming, but where a voxel's votes tie: argmax
  // then takes the smaller id, and a renaming can change which that is (a handful of vertices
  // here; ARemapIsTheMapOfTheFramesMappedAtTheNewPoses compares the stored maps themselves).
  const LabelledMesh fresh_mesh = fresh.extractMesh();
  ASSERT_EQ(after.vertices, fresh_mesh.vertices);
  std::map<std::pair<int32_t, int32_t>, size_t> pairs;
  size_t semantic_differs = 0;
  for (size_t i = 0; i < after.vertices.size(); ++i) {
    ++pairs[{after.superpoint[i], fresh_mesh.superpoint[i]}];
    semantic_differs += after.semantic[i] != fresh_mesh.semantic[i] ? 1 : 0;
  }
  // Each super-point's largest counterpart; the vertices off it are the ties.
  std::map<int32_t, std::pair<size_t, int32_t>> largest;
  for (const auto& [pair, n] : pairs) {
    auto& best = largest[pair.first];
    if (n > best.first) best = {n, pair.second};
  }
  std::set<int32_t> images;
  size_t on_counterpart = 0;
  for (const auto& [label, best] : largest) {
    EXPECT_TRUE(images.insert(best.second).second) << "two super-points became " << best.second;
    on_counterpart += best.first;
  }
  EXPECT_GT(on_counterpart, after.vertices.size() * 999 / 1000);
  EXPECT_LT(semantic_differs, after.vertices.size() / 1000);
  // Saved and loaded, the ids and the retired ones stay; new super-points start above them.
  const std::unique_ptr<Mapper> loaded =
      Mapper::deserialize(mapper.serialize(), "the repaired map");
  EXPECT_EQ(loaded->liveSuperpoints(), mapper.liveSuperpoints());
  EXPECT_EQ(loaded->superpoints().labels().resolve(ghost), 0);
  EXPECT_GE(loaded->superpoints().labels().size(), size_before);
  // A second repair to the same poses keeps them again.
  ASSERT_TRUE(mapper.remap(corrected, panopticLoader(true)).completed);
  EXPECT_EQ(superpointNear(mapper.extractMesh(), cabinet_W), cabinet);
  EXPECT_EQ(superpointNear(mapper.extractMesh(), fridge_W), fridge);
}

// Ids that do not fit the map's super-points change nothing: one missing, two alike, one
// outside the size, one for a merged-away label.
TEST_F(Reintegration, SuperpointIdsThatDoNotFitChangeNothing) {
  auto mapper = record(5);
  const std::vector<uint8_t> before = bytes(*mapper);
  const std::vector<int32_t> live = mapper->liveSuperpoints();
  ASSERT_GE(live.size(), 3u);
  std::map<int32_t, int32_t> ids;
  for (size_t i = 0; i < live.size(); ++i) ids[live[i]] = static_cast<int32_t>(101 + i);
  const int32_t size = static_cast<int32_t>(100 + live.size());
  std::map<int32_t, int32_t> missing = ids;
  missing.erase(live[1]);
  EXPECT_THROW(mapper->renumberSuperpoints(missing, size), Error);
  std::map<int32_t, int32_t> alike = ids;
  alike[live[2]] = alike[live[0]];
  EXPECT_THROW(mapper->renumberSuperpoints(alike, size), Error);
  EXPECT_THROW(mapper->renumberSuperpoints(ids, size - 1), Error);
  EXPECT_EQ(bytes(*mapper), before);
  // And ids that fit rename every super-point, with the map the same up to the names.
  mapper->renumberSuperpoints(ids, size);
  EXPECT_NE(bytes(*mapper), before);
  EXPECT_EQ(mapper->liveSuperpoints().front(), 101);
  EXPECT_EQ(test::canonicalBytes(*mapper), test::canonicalBytes(*record(5)));
}

TEST_F(Reintegration, AFailedOrAbandonedRemapLeavesTheMapAsItWas) {
  auto mapper = record(5);
  const std::vector<uint8_t> before = bytes(*mapper);
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.translation() = Eigen::Vector3d(0.1, 0.0, 0.0);
  const std::vector<StampedPose> poses = moved(*mapper, D);
  const ReintegrationStats abandoned =
      mapper->remap(poses, panopticLoader(), [](size_t done, size_t) { return done < 2; });
  EXPECT_FALSE(abandoned.completed);
  EXPECT_EQ(bytes(*mapper), before);
  stored_.erase(std::next(stored_.begin(), 3));
  try {
    mapper->remap(poses, panopticLoader());
    FAIL() << "a missing frame was not reported";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no stored frame"), std::string::npos) << e.what();
  }
  EXPECT_EQ(bytes(*mapper), before);
  std::vector<StampedPose> renamed = poses;
  renamed[1].utime += 1;
  EXPECT_THROW(mapper->remap(renamed, panopticLoader()), Error);
  EXPECT_THROW(mapper->remap(poses, PanopticFrameLoader()), Error);
  EXPECT_EQ(bytes(*mapper), before);
  // The mapper still maps.
  RgbdFrame frame;
  PanopticFrame panoptic;
  frameAt(5, &frame, &panoptic);
  EXPECT_NO_THROW(mapper->integrate(frame, pose(5), &panoptic));
}

}  // namespace
}  // namespace panmap
