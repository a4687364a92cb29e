// panmap-import --drift: the recorded poses become the reference trajectory, the written ones
// are exactly the drift model's estimate of them, flagged as SLAM poses.
#include <gtest/gtest.h>

#include "panmap/io/dataset_reader.h"
#include "panmap/io/tum_trajectory.h"
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
