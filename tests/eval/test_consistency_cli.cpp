// panmap-consistency as a user runs it: two trajectories of the 7-Scenes sample scored on the
// same pixels, and the one-line failures of a missing file, a trajectory that poses no frame
// and a missing dataset.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "panmap/io/dataset_reader.h"
#include "panmap/io/tum_trajectory.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::binPath;
using test::runCommand;

std::string consistency() {
  const std::string bin = binPath("panmap-consistency");
  EXPECT_TRUE(std::filesystem::exists(bin)) << "build panmap-consistency first: " << bin;
  return bin;
}

/// The recorded poses of the 7-Scenes sample, and the same with every other frame moved 3 cm.
void writeTrajectories(const std::string& recorded, const std::string& jittered) {
  const auto reader = openDataset(test::dataDir("7scenes-200"), DatasetOptions{});
  std::vector<StampedPose> poses;
  for (size_t i = 0; i < reader->size(); ++i) {
    const DatasetFrame frame = reader->read(i);
    StampedPose p;
    p.utime = frame.rgbd.utime;
    p.T_W_C = *frame.T_W_C;
    poses.push_back(p);
  }
  writeTumTrajectory(recorded, poses);
  for (size_t i = 1; i < poses.size(); i += 2) {
    poses[i].T_W_C.translation() += Eigen::Vector3d(0.03, 0.0, 0.0);
  }
  writeTumTrajectory(jittered, poses);
}

TEST(ConsistencyCli, AJitteredTrajectoryScoresWorseOnTheSamePixels) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  writeTrajectories(dir.path("recorded.txt"), dir.path("jittered.txt"));
  const auto run =
      runCommand(consistency() + " --data " + test::dataDir("7scenes-200") +
                 " --gaps 1 --stride 8 --traj " + dir.path("recorded.txt") + " --traj " +
                 dir.path("jittered.txt") + " --json " + dir.path("out.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(dir.path("out.json"));
  const nlohmann::json out = nlohmann::json::parse(in);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0]["pairs"].get<int>(), 199);  // every consecutive pair of 200 frames
  EXPECT_EQ(out[0]["samples"], out[1]["samples"]);
  EXPECT_EQ(out[0]["frames_posed"].get<int>(), 200);
  EXPECT_GT(out[1]["median_abs"].get<double>(), out[0]["median_abs"].get<double>() + 2.0)
      << run.output;

  // --max-frames reads the first frames only: pairs among them, the rest of the poses unused.
  const auto first = runCommand(consistency() + " --data " + test::dataDir("7scenes-200") +
                                " --max-frames 20 --gaps 1 --stride 8 --traj " +
                                dir.path("recorded.txt") + " --json " + dir.path("first.json"));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  std::ifstream first_in(dir.path("first.json"));
  const nlohmann::json first_out = nlohmann::json::parse(first_in);
  EXPECT_EQ(first_out[0]["pairs"].get<int>(), 19);
  EXPECT_EQ(first_out[0]["frames_posed"].get<int>(), 20);
}

// --gaps as the README writes it (1,3) and as CLI11 lists it (1 3) give the same pairs.
TEST(ConsistencyCli, GapsTakeCommasOrSpaces) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  writeTrajectories(dir.path("recorded.txt"), dir.path("jittered.txt"));
  const std::string common = consistency() + " --data " + test::dataDir("7scenes-200") +
                             " --traj " + dir.path("recorded.txt");
  const auto commas = runCommand(common + " --stride 8 --gaps 1,3 --json " + dir.path("c.json"));
  ASSERT_EQ(commas.exit_code, 0) << commas.output;
  const auto spaces = runCommand(common + " --stride 8 --gaps 1 3 --json " + dir.path("s.json"));
  ASSERT_EQ(spaces.exit_code, 0) << spaces.output;
  std::ifstream c(dir.path("c.json")), s(dir.path("s.json"));
  const nlohmann::json with_commas = nlohmann::json::parse(c);
  EXPECT_EQ(with_commas, nlohmann::json::parse(s));
  EXPECT_EQ(with_commas[0]["pairs"].get<int>(), 199 + 197);  // gaps 1 and 3 of 200 frames
  // Samples too sparse for any pair: the message says what was missing.
  const auto sparse = runCommand(common + " --gaps 1 --stride 64");
  EXPECT_EQ(sparse.exit_code, 1);
  EXPECT_NE(sparse.output.find("200 pixels seen in both"), std::string::npos) << sparse.output;
}

TEST(ConsistencyCli, BadInputsFailWithOneLineNamingTheProblem) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  const std::string data = " --data " + test::dataDir("7scenes-200");
  const auto missing = runCommand(consistency() + data + " --traj " + dir.path("none.txt"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("panmap-consistency: error:"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("none.txt"), std::string::npos) << missing.output;

  StampedPose far_away;
  far_away.utime = 999000000000;  // no frame at that time
  writeTumTrajectory(dir.path("elsewhere.txt"), {far_away});
  const auto unposed = runCommand(consistency() + data + " --traj " + dir.path("elsewhere.txt"));
  EXPECT_EQ(unposed.exit_code, 1);
  EXPECT_NE(unposed.output.find("no frame pair"), std::string::npos) << unposed.output;

  const auto no_data = runCommand(consistency() + " --data " + dir.path("nowhere") + " --traj " +
                                  dir.path("elsewhere.txt"));
  EXPECT_EQ(no_data.exit_code, 1);
  EXPECT_NE(no_data.output.find("nowhere"), std::string::npos) << no_data.output;
}

}  // namespace
}  // namespace panmap
