// panmap-eval as a user runs it, on a procedural room's ground truth.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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

}  // namespace
}  // namespace panmap
