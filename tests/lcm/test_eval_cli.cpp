// panmap-eval as a user runs it, on a procedural room's ground truth.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "panmap/io/ply.h"
#include "panmap/io/tum_trajectory.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::binPath;
using test::runCommand;

TEST(EvalCli, GroundTruthAgainstItselfScoresOne) {
  test::TempDir dir;
  const auto synth =
      runCommand(binPath("panmap-synth") + " --room 4 --frames 2 --quiet --out " + dir.path("r"));
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string mesh = dir.path("r/gt/mesh.ply");
  const auto eval = runCommand(binPath("panmap-eval") + " --pred " + mesh + " --gt " + mesh +
                               " --json " + dir.path("e.json"));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  std::ifstream in(dir.path("e.json"));
  const auto json = nlohmann::json::parse(in);
  EXPECT_DOUBLE_EQ(json["map50"].get<double>(), 1.0) << json.dump(1).substr(0, 2000);
  EXPECT_DOUBLE_EQ(json["map75"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(json["miou"].get<double>(), 1.0);
  EXPECT_EQ(json["num_transferred"], json["num_gt_vertices"]);
  EXPECT_EQ(json["paper_compatible"], false);
  // The same through the ScanNet benchmark file of the ground truth.
  const auto scannet = runCommand(binPath("panmap-eval") + " --pred " + mesh + " --gt " + mesh +
                                  " --gt-instances " + dir.path("r/gt/instances.txt"));
  EXPECT_EQ(scannet.exit_code, 0) << scannet.output;
  const auto missing =
      runCommand(binPath("panmap-eval") + " --pred " + dir.path("none.ply") + " --gt " + mesh);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("none.ply"), std::string::npos) << missing.output;
}

// A map built from estimated poses sits in the estimate's world frame. Moved rigidly by 8 cm
// and 3 degrees (beyond the 5 cm label transfer), it scores nothing as it is and everything
// once --align-pred moves it by the trajectory's alignment.
TEST(EvalCli, AlignPredMovesTheMapIntoTheGroundTruthFrame) {
  test::TempDir dir;
  const auto synth =
      runCommand(binPath("panmap-synth") + " --room 4 --frames 20 --quiet --out " + dir.path("r"));
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const Eigen::Isometry3d T_est_gt =
      Eigen::Translation3d(0.08, -0.02, 0.01) *
      Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d(0.2, 0.3, 1.0).normalized());
  std::vector<StampedPose> trajectory = readTumTrajectory(dir.path("r/gt/trajectory_gt.txt"));
  ASSERT_GE(trajectory.size(), 3u);
  for (StampedPose& p : trajectory) p.T_W_C = T_est_gt * p.T_W_C;
  writeTumTrajectory(dir.path("est.txt"), trajectory);
  LabelledMesh mesh = readPly(dir.path("r/gt/mesh.ply"));
  for (Eigen::Vector3f& v : mesh.vertices) v = T_est_gt.cast<float>() * v;
  writePly(dir.path("moved.ply"), mesh);

  const std::string eval = binPath("panmap-eval") + " --pred " + dir.path("moved.ply") + " --gt " +
                           dir.path("r/gt/mesh.ply") + " --traj " + dir.path("est.txt") +
                           " --gt-traj " + dir.path("r/gt/trajectory_gt.txt");
  const auto as_is = runCommand(eval + " --json " + dir.path("as_is.json"));
  ASSERT_EQ(as_is.exit_code, 0) << as_is.output;
  const auto aligned = runCommand(eval + " --align-pred --json " + dir.path("aligned.json"));
  ASSERT_EQ(aligned.exit_code, 0) << aligned.output;
  std::ifstream in_as_is(dir.path("as_is.json")), in_aligned(dir.path("aligned.json"));
  const auto j_as_is = nlohmann::json::parse(in_as_is);
  const auto j_aligned = nlohmann::json::parse(in_aligned);
  EXPECT_LT(j_as_is["map50"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j_aligned["map50"].get<double>(), 1.0);
  EXPECT_EQ(j_aligned["num_transferred"], j_aligned["num_gt_vertices"]);
  EXPECT_EQ(j_aligned["pred_aligned_by_trajectory"], true);
  // Without a trajectory there is nothing to align by.
  const auto no_traj = runCommand(binPath("panmap-eval") + " --pred " + dir.path("moved.ply") +
                                  " --gt " + dir.path("r/gt/mesh.ply") + " --align-pred");
  EXPECT_NE(no_traj.exit_code, 0);
}

}  // namespace
}  // namespace panmap
