// panmap-import --drift: the recorded poses become the reference trajectory, the written ones
// are exactly the drift model's estimate of them, flagged as SLAM poses.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "panmap/io/dataset_reader.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/decode.h"
#include "panmap/lcm/log_import.h"
#include "panmap/sim/pose_drift.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::binPath;
using test::runCommand;

TEST(ImportDrift, ReferenceIsRecordedAndInputIsTheDriftModel) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  const auto r =
      runCommand(binPath("panmap-import") + " --quiet --max-frames 12 --drift heavy " +
                 "--seed 3 " + test::dataDir("7scenes-200") + " " + dir.path("s.lcmlog"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("s.reference.txt"), std::string::npos) << r.output;
  const std::vector<StampedPose> reference = readTumTrajectory(dir.path("s.reference.txt"));
  const std::vector<StampedPose> input = readTumTrajectory(dir.path("s.input.txt"));
  ASSERT_EQ(reference.size(), 12u);
  ASSERT_EQ(input.size(), 12u);
  const auto reader = openDataset(test::dataDir("7scenes-200"), DatasetOptions{});
  std::vector<Eigen::Isometry3d> recorded;
  for (size_t i = 0; i < 12; ++i) recorded.push_back(*reader->read(i).T_W_C);
  const std::vector<Eigen::Isometry3d> drifted =
      applyPoseDrift(recorded, PoseDriftConfig::fromPreset("heavy"), 3);
  for (size_t i = 0; i < 12; ++i) {
    // TUM files carry 9 decimals.
    EXPECT_NEAR((reference[i].T_W_C.matrix() - recorded[i].matrix()).norm(), 0.0, 1e-6) << i;
    EXPECT_NEAR((input[i].T_W_C.matrix() - drifted[i].matrix()).norm(), 0.0, 1e-6) << i;
  }
  EXPECT_GT((input[11].T_W_C.translation() - recorded[11].translation()).norm(), 1e-4);

  // The log's poses are the drifted ones, flagged slam.
  ImportOptions options;
  options.max_frames = 3;
  options.pose_source = PoseSource::kSlam;
  PoseDrift model(PoseDriftConfig::fromPreset("heavy"), 3);
  options.pose_filter = [&model](const Eigen::Isometry3d& T) { return model.next(T); };
  const ImportStats stats =
      importDataset(test::dataDir("7scenes-200"), dir.path("t.lcmlog"), options);
  ASSERT_EQ(stats.written_poses.size(), 3u);
  EXPECT_EQ(stats.written_poses[2].source, PoseSource::kSlam);
  EXPECT_TRUE(stats.written_poses[2].T_W_C.isApprox(drifted[2], 1e-12));
  EXPECT_TRUE(stats.recorded_poses[2].T_W_C.isApprox(recorded[2], 1e-12));
}

TEST(ImportDrift, TheLogEndsWithTheCorrectionABackEndWouldPublish) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  const auto r = runCommand(binPath("panmap-import") +
                            " --quiet --max-frames 12 --drift heavy --correction-every 5 " +
                            test::dataDir("7scenes-200") + " " + dir.path("s.lcmlog"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<StampedPose> reference = readTumTrajectory(dir.path("s.reference.txt"));
  lcm::LogFile log(dir.path("s.lcmlog"), "r");
  const lcm::LogEvent* last = nullptr;
  int events = 0;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    ++events;
    if (e->channel == "PANMAP_POSE_CORRECTION") {
      EXPECT_EQ(last, nullptr) << "more than one correction";
      last = e;
      break;
    }
  }
  ASSERT_NE(last, nullptr);
  EXPECT_EQ(events, 25);  // 12 poses, 12 frames, then the correction
  pose_correction_t msg;
  ASSERT_TRUE(decodeExactly(last->data, static_cast<size_t>(last->datalen), &msg));
  const PoseCorrection c = fromMessage(msg);
  // Keyframes 0, 5, 10 and the last frame, 11, at their recorded poses.
  ASSERT_EQ(c.poses.size(), 4u);
  const size_t keyframes[] = {0, 5, 10, 11};
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(c.poses[k].utime, reference[keyframes[k]].utime);
    EXPECT_NEAR((c.poses[k].T_W_C.matrix() - reference[keyframes[k]].T_W_C.matrix()).norm(), 0.0,
                1e-6);
  }
  EXPECT_EQ(c.utime, reference[11].utime + 1000000);
  EXPECT_EQ(log.readNextEvent(), nullptr);
}

TEST(ImportDrift, UnknownPresetFailsWithOneLine) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  const auto r = runCommand(binPath("panmap-import") + " --quiet --drift wobbly " +
                            test::dataDir("7scenes-200") + " " + dir.path("s.lcmlog"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(test::countLines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("wobbly"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path("s.lcmlog")));
}

}  // namespace
}  // namespace panmap
