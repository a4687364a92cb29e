// Surveys that revisit every area (SurveyConfig::laps), as a handheld ScanNet scan does.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fingerprint.h"
#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/sequence.h"
#include "panmap/sim/trajectory.h"

namespace panmap {
namespace {

const PinholeCamera kSmallCamera{131.25, 131.25, 79.375, 59.375, 160, 120};  // 640x480 / 4

/// A 5 Hz survey of `laps` laps, long enough to walk all of them.
SurveyConfig wholeWalk(const LabelledMesh& mesh, int laps, uint64_t seed) {
  SurveyConfig config;
  config.rate_hz = 5.0;
  config.laps = laps;
  const SurveyPath path = planSurveyPath(mesh, config, seed);
  config.num_frames =
      static_cast<int>(std::floor(path.length_m / config.speed_mps * config.rate_hz));
  return config;
}

/// The lap frame k of a survey walks in.
int lapOf(const SurveyConfig& config, const SurveyPath& path, size_t k) {
  const double s = std::fmod(k / config.rate_hz * config.speed_mps, path.length_m);
  return static_cast<int>(std::upper_bound(path.lap_start_m.begin(), path.lap_start_m.end(), s) -
                          path.lap_start_m.begin()) -
         1;
}

TEST(SurveyLaps, OneLapIsTheSurveyResultsWereMeasuredOn) {
  // Fingerprint taken before laps existed (x86-64, GCC 12).
  const ProceduralRoom room = generateRoom(1);
  SurveyConfig config;
  config.num_frames = 600;
  config.rate_hz = 5.0;
  EXPECT_EQ(test::fingerprint(planSurvey(room.mesh, config, 1)), 0x97f11612140a70eaull);
  const SurveyPath path = planSurveyPath(room.mesh, config, 1);
  EXPECT_EQ(path.lap_start_m, std::vector<double>{0.0});
}

TEST(SurveyLaps, LapsOutsideOneToTwentyAreRefused) {
  for (int laps : {0, -1, 21}) {
    SurveyConfig config;
    config.laps = laps;
    try {
      config.check();
      FAIL() << laps;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("laps"), std::string::npos) << e.what();
    }
  }
}

// The frame count that walks a survey's whole walk ends it back at its start, one step short.
TEST(SurveyLaps, FramesToWalkEndTheSurveyBackAtItsStart) {
  const ProceduralRoom room = generateRoom(3, RoomConfig::scanNetLike());
  SurveyConfig config;
  config.rate_hz = 5.0;
  config.laps = 2;
  const SurveyPath path = planSurveyPath(room.mesh, config, 4);
  const double step_m = config.speed_mps / config.rate_hz;
  const int frames = framesToWalk(path, config);
  EXPECT_EQ(frames, static_cast<int>(std::ceil(path.length_m / step_m)));
  // Frame frames - 1 is the last one before the walk's end; frame `frames` would start over.
  EXPECT_LT((frames - 1) * step_m, path.length_m);
  EXPECT_GE(frames * step_m, path.length_m);
  config.num_frames = frames;
  const std::vector<StampedPose> survey = planSurvey(room.mesh, config, 4);
  ASSERT_EQ(survey.size(), static_cast<size_t>(frames));
  const Eigen::Vector2d first = survey.front().T_W_C.translation().head<2>();
  const Eigen::Vector2d last = survey.back().T_W_C.translation().head<2>();
  EXPECT_LE((last - first).norm(), step_m + 1e-9);
  EXPECT_GT(path.length_m, 10 * step_m);  // the check above means something
  // More frames than that start the walk over; the first `frames` are the same poses.
  config.num_frames = frames + 20;
  const std::vector<StampedPose> longer = planSurvey(room.mesh, config, 4);
  for (int k = 0; k < frames; k += 7) {
    EXPECT_TRUE(longer[k].T_W_C.isApprox(survey[k].T_W_C, 1e-12)) << k;
  }
}

class SurveyLapsInRoom : public ::testing::TestWithParam<int> {
 protected:
  /// Box rooms for positive parameters, ScanNet-like rooms for negative ones.
  static ProceduralRoom makeRoom(int param) {
    return param > 0 ? generateRoom(param)
                     : generateRoom(static_cast<uint64_t>(-param), RoomConfig::scanNetLike());
  }
};

TEST_P(SurveyLapsInRoom, SecondLapRetracesTheFirstBackwardAndKeepsClear) {
  const ProceduralRoom room = makeRoom(GetParam());
  const SurveyConfig config = wholeWalk(room.mesh, 2, 7);
  const SurveyPath path = planSurveyPath(room.mesh, config, 7);
  ASSERT_EQ(path.lap_start_m.size(), 2u);
  // Both laps walk the same loop: about half the walk each.
  EXPECT_NEAR(path.lap_start_m[1], 0.5 * path.length_m, 0.05 * path.length_m);
  const std::vector<StampedPose> traj = planSurvey(room.mesh, config, 7);
  std::vector<Eigen::Vector2d> lap_points[2], lap_steps[2];
  for (size_t k = 0; k + 1 < traj.size(); ++k) {
    const Eigen::Vector2d p = traj[k].T_W_C.translation().head<2>();
    const int lap = lapOf(config, path, k);
    ASSERT_TRUE(lap == 0 || lap == 1) << k;
    lap_points[lap].push_back(p);
    lap_steps[lap].push_back(traj[k + 1].T_W_C.translation().head<2>() - p);
  }
  ASSERT_GT(lap_points[1].size(), lap_points[0].size() / 2);
  // Every place of lap 1 is passed again in lap 2, most of them walking the other way.
  int revisited = 0, reversed = 0;
  for (size_t a = 0; a < lap_points[0].size(); ++a) {
    double best = 1e9;
    size_t at = 0;
    for (size_t b = 0; b < lap_points[1].size(); ++b) {
      const double d = (lap_points[0][a] - lap_points[1][b]).norm();
      if (d < best) best = d, at = b;
    }
    EXPECT_LT(best, 0.5) << "frame " << a << " of lap 1 is never passed again";
    revisited += best < 0.1 ? 1 : 0;
    reversed += lap_steps[0][a].dot(lap_steps[1][at]) < 0.0 ? 1 : 0;
  }
  const double n = static_cast<double>(lap_points[0].size());
  EXPECT_GE(revisited, 0.9 * n);
  EXPECT_GE(reversed, 0.9 * n);
  // The turn between the laps keeps the clearance and the head's rate limits.
  EXPECT_GE(minClearance(traj, room.mesh), config.clearance_m);
  const double dt = 1.0 / config.rate_hz;
  const double max_rate = (config.max_yaw_rate_dps + config.max_pitch_rate_dps) * M_PI / 180.0 * dt;
  for (size_t k = 1; k < traj.size(); ++k) {
    const double turn = std::acos(std::clamp(
        traj[k].T_W_C.linear().col(2).dot(traj[k - 1].T_W_C.linear().col(2)), -1.0, 1.0));
    ASSERT_LE(turn, max_rate + 1e-9) << k;
    ASSERT_LE((traj[k].T_W_C.translation() - traj[k - 1].T_W_C.translation()).head<2>().norm(),
              config.speed_mps * dt * 1.01);
  }
}

TEST_P(SurveyLapsInRoom, ObjectsSeenInTheFirstLapAreSeenAgainInTheSecond) {
  const ProceduralRoom room = makeRoom(GetParam());
  const SurveyConfig config = wholeWalk(room.mesh, 2, 7);
  const SurveyPath path = planSurveyPath(room.mesh, config, 7);
  const std::vector<StampedPose> traj = planSurvey(room.mesh, config, 7);
  const MeshRenderer renderer(room.mesh);
  std::map<int32_t, std::set<int>> laps_seen;
  std::map<int32_t, int> pixels;
  RenderedView view;
  for (size_t k = 0; k < traj.size(); k += 2) {
    renderer.render(kSmallCamera, traj[k].T_W_C, &view);
    pixels.clear();
    for (size_t i = 0; i < view.instance.size(); ++i) {
      const int32_t id = view.instance.data()[i];
      const int32_t cls = view.semantic.data()[i];
      if (id > 0 && cls > 0 && !isStuffClass(cls)) ++pixels[id];
    }
    for (const auto& [id, count] : pixels) {
      if (count >= 12) laps_seen[id].insert(lapOf(config, path, k));  // 200 px at 640x480
    }
  }
  int in_first = 0, in_both = 0;
  for (const auto& [id, laps] : laps_seen) {
    if (!laps.count(0)) continue;
    ++in_first;
    in_both += laps.count(1) ? 1 : 0;
  }
  EXPECT_GT(in_first, 10);
  EXPECT_GE(in_both, 0.8 * in_first) << in_both << " of " << in_first;
  RecordProperty("seen_in_both_laps", std::to_string(in_both) + "/" + std::to_string(in_first));
}

TEST_P(SurveyLapsInRoom, RevisitsDoNotLowerCoverageForTheSameFrames) {
  const ProceduralRoom room = makeRoom(GetParam());
  auto coverage = [&](int laps) {
    SurveyConfig survey;
    survey.num_frames = 600;  // 2 minutes at 5 Hz
    survey.rate_hz = 5.0;
    survey.laps = laps;
    SynthConfig config;
    config.camera = kSmallCamera;
    config.min_view_px = 200 / 16;
    config.masks = SegmenterNoiseConfig::fromPreset("clean");
    config.depth.enabled = false;
    SequenceSynthesizer synth(room.mesh, planSurvey(room.mesh, survey, 7), config);
    for (size_t k = 0; k < synth.size(); k += 2) synth.frame(k);
    return synth.coverage().fractionSeenFrom3Views();
  };
  const double one = coverage(1), two = coverage(2);
  EXPECT_GE(two, one - 1e-9);
  RecordProperty("coverage_laps_1", std::to_string(one));
  RecordProperty("coverage_laps_2", std::to_string(two));
}

INSTANTIATE_TEST_SUITE_P(Rooms, SurveyLapsInRoom, ::testing::Values(1, 3, -11, -12));

}  // namespace
}  // namespace panmap
