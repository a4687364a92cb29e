// panmap-synth as a user runs it: outputs, determinism, decodable logs, clear errors.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "panmap/io/image_codec.h"
#include "panmap/io/ply.h"
#include "panmap/io/scannet_ground_truth.h"
#include "panmap/lcm/log_info.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/trajectory.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::binPath;
using test::runCommand;

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(SynthCli, RoomOutputsAreCompleteAndDeterministic) {
  test::TempDir dir;
  const std::string args = " --room 3 --frames 24 --masks m2f --poses slam --seed 9 --quiet --out ";
  const auto a = runCommand(binPath("panmap-synth") + args + dir.path("a"));
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const auto b = runCommand(binPath("panmap-synth") + args + dir.path("b"));
  ASSERT_EQ(b.exit_code, 0) << b.output;
  // Same seed: bit-identical log and ground truth.
  for (const char* file : {"sequence.lcmlog", "gt/mesh.ply", "gt/instances.txt",
                           "gt/trajectory_gt.txt", "gt/trajectory_input.txt"}) {
    EXPECT_EQ(readFileBytes(dir.path("a/") + file), readFileBytes(dir.path("b/") + file)) << file;
  }
  const LogInfo info = inspectLog(dir.path("a/sequence.lcmlog"), true);
  EXPECT_TRUE(info.allDecoded());
  ASSERT_EQ(info.channels.size(), 3u);
  for (const ChannelInfo& c : info.channels) EXPECT_EQ(c.count, 24u) << c.channel;
  EXPECT_NEAR(info.channels[0].rateHz(), 30.0, 0.01);

  const LabelledMesh mesh = readPly(dir.path("a/gt/mesh.ply"));
  const std::vector<int32_t> gt = readScanNetInstanceFile(dir.path("a/gt/instances.txt"));
  ASSERT_EQ(gt.size(), mesh.numVertices());
  for (size_t v = 0; v < gt.size(); v += 97) {
    const int32_t expected = mesh.instance[v] > 0 && mesh.semantic[v] > 0
                                 ? mesh.semantic[v] * 1000 + mesh.instance[v]
                                 : 0;
    EXPECT_EQ(gt[v], expected);
  }
  const auto gt_traj = readTumTrajectory(dir.path("a/gt/trajectory_gt.txt"));
  const auto in_traj = readTumTrajectory(dir.path("a/gt/trajectory_input.txt"));
  ASSERT_EQ(gt_traj.size(), 24u);
  EXPECT_EQ(gt_traj[0].T_W_C.translation(), in_traj[0].T_W_C.translation());
  EXPECT_GE(minClearance(gt_traj, mesh), 0.3 - 0.03);

  const auto json = readJson(dir.path("a/info.json"));
  EXPECT_EQ(json["seed"], 9);
  EXPECT_EQ(json["frames"], 24);
  EXPECT_EQ(json["masks"]["preset"], "m2f");
  EXPECT_EQ(json["poses"]["preset"], "slam");
  EXPECT_GT(json["mesh"]["faces"].get<int>(), 10000);

  // Another seed gives another sequence.
  const auto c = runCommand(binPath("panmap-synth") +
                            " --room 3 --frames 24 --seed 10 --quiet --out " + dir.path("c"));
  ASSERT_EQ(c.exit_code, 0) << c.output;
  EXPECT_NE(readFileBytes(dir.path("a/sequence.lcmlog")),
            readFileBytes(dir.path("c/sequence.lcmlog")));
}

TEST(SynthCli, ScanNetGroundTruthWithAGivenTrajectory) {
  test::TempDir dir;
  // The tiny fixture scene, its labels and a quiet 5-frame run: what every command shares.
  const std::string synth = binPath("panmap-synth") + " --quiet --frames 5 --scannet " +
                            test::fixtureDir("scannet_gt_tiny") + " --scannet-labels " +
                            test::dataDir("scannet-meta/scannetv2-labels.combined.tsv");
  // The scene has no room to walk in: the planner says so in one line...
  const auto no_room = runCommand(synth + " --out " + dir.path("s"));
  if (!std::filesystem::is_directory(test::dataDir("scannet-meta")))
    GTEST_SKIP() << "no scannet-meta";
  EXPECT_EQ(no_room.exit_code, 1) << no_room.output;
  EXPECT_EQ(test::countLines(no_room.output), 1) << no_room.output;
  EXPECT_NE(no_room.output.find("survey"), std::string::npos) << no_room.output;
  // ... and a given TUM trajectory renders it.
  std::ofstream(dir.path("traj.txt")) << "0.0 0 0 3 0 0 0 1\n0.033333 0 0 3.01 0 0 0 1\n";
  const std::string along = synth + " --trajectory " + dir.path("traj.txt") + " --poses gt";
  const auto ok = runCommand(along + " --out " + dir.path("s"));
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_EQ(inspectLog(dir.path("s/sequence.lcmlog"), true).channels[0].count, 2u);
  EXPECT_FALSE(readJson(dir.path("s/info.json"))["source"].contains("joined_parts"));
  // --join-parts lists its joins (the fixture's instances are not stacked: none).
  const auto joined = runCommand(along + " --join-parts --out " + dir.path("j"));
  ASSERT_EQ(joined.exit_code, 0) << joined.output;
  const auto parts = readJson(dir.path("j/info.json"))["source"]["joined_parts"];
  EXPECT_TRUE(parts.is_array());
  EXPECT_TRUE(parts.empty());
  // A recorded trajectory is rendered whole without --frames (300 by default cut ScanNet's
  // thousands of poses to the first 10 s in silence), and a cut asked for is named.
  {
    std::ofstream long_traj(dir.path("long.txt"));
    for (int k = 0; k < 305; ++k) long_traj << k / 30.0 << " 0 0 3 0 0 0 1\n";
  }
  const std::string whole = binPath("panmap-synth") + " --quiet --image-scale 0.25 --scannet " +
                            test::fixtureDir("scannet_gt_tiny") + " --scannet-labels " +
                            test::dataDir("scannet-meta/scannetv2-labels.combined.tsv") +
                            " --poses gt --trajectory " + dir.path("long.txt");
  const auto all = runCommand(whole + " --out " + dir.path("all"));
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_EQ(readJson(dir.path("all/info.json"))["frames"].get<int>(), 305);
  EXPECT_EQ(all.output.find("rendering the first"), std::string::npos) << all.output;
  const auto cut = runCommand(whole + " --frames 7 --out " + dir.path("cut"));
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  EXPECT_EQ(readJson(dir.path("cut/info.json"))["frames"].get<int>(), 7);
  EXPECT_NE(cut.output.find("panmap-synth: rendering the first 7 of the trajectory's 305 poses"),
            std::string::npos)
      << cut.output;
}

TEST(SynthCli, BadArgumentsFailClearly) {
  test::TempDir dir;
  const auto none = runCommand(binPath("panmap-synth") + " --out " + dir.path("x"));
  EXPECT_NE(none.exit_code, 0);
  const auto bad =
      runCommand(binPath("panmap-synth") + " --room 1 --masks perfect --out " + dir.path("x"));
  EXPECT_NE(bad.exit_code, 0);
  const auto traj = runCommand(binPath("panmap-synth") + " --room 1 --trajectory " +
                               dir.path("none.txt") + " --out " + dir.path("x"));
  EXPECT_EQ(traj.exit_code, 1);
  EXPECT_NE(traj.output.find("none.txt"), std::string::npos) << traj.output;
  // A negative seed used to mean "no room" and fell through to a ScanNet scene with no folder.
  const auto negative = runCommand(binPath("panmap-synth") + " --room -1 --out " + dir.path("x"));
  EXPECT_NE(negative.exit_code, 0);
  EXPECT_NE(negative.output.find("--room: a seed is an integer >= 0, not -1"), std::string::npos)
      << negative.output;
  const auto join =
      runCommand(binPath("panmap-synth") + " --room 1 --join-parts --out " + dir.path("x"));
  EXPECT_EQ(join.exit_code, 1);
  EXPECT_EQ(test::countLines(join.output), 1) << join.output;
  EXPECT_NE(join.output.find("--join-parts needs --scannet"), std::string::npos) << join.output;
  const auto scene = runCommand(binPath("panmap-synth") + " --scannet " + dir.path("none") +
                                " --out " + dir.path("x"));
  EXPECT_EQ(scene.exit_code, 1);
  EXPECT_NE(scene.output.find("--scannet " + dir.path("none") + ": no such folder"),
            std::string::npos)
      << scene.output;
  // A scene folder with no label table near it, run from a folder with no shipped copy: named
  // (it was "cannot open ../shared/data/scannet-meta/...", a path the user never gave).
  const std::string lone = dir.path("scans/scene0001_00");
  std::filesystem::create_directories(lone);
  const auto no_table = runCommand("cd " + dir.path("scans") + " && " + binPath("panmap-synth") +
                                   " --scannet " + lone + " --out " + dir.path("x"));
  EXPECT_EQ(no_table.exit_code, 1);
  EXPECT_EQ(test::countLines(no_table.output), 1) << no_table.output;
  EXPECT_NE(no_table.output.find("--scannet " + lone +
                                 ": no scannetv2-labels.combined.tsv in it, its parent or its "
                                 "grandparent; give it with --scannet-labels"),
            std::string::npos)
      << no_table.output;
  // -1 wrapped to 2^64 - 1 as a seed; ranges printed DBL_MAX in 300 digits.
  const auto seed =
      runCommand(binPath("panmap-synth") + " --room 1 --seed -1 --out " + dir.path("x"));
  EXPECT_NE(seed.exit_code, 0);
  EXPECT_NE(seed.output.find("--seed: a number >= 0, not -1"), std::string::npos) << seed.output;
  const auto autosave =
      runCommand(binPath("panmap-mapper") + " --autosave-s nan --out " + dir.path("x"));
  EXPECT_NE(autosave.exit_code, 0);
  EXPECT_NE(autosave.output.find("--autosave-s: a period in seconds >= 0 (0: never), not nan"),
            std::string::npos)
      << autosave.output;
  // A trajectory whose times repeat was synthesised, and the mapper then refused its frames.
  std::ofstream(dir.path("repeat.txt")) << "0.0 0 0 1 0 0 0 1\n0.1 0 0 1 0 0 0 1\n"
                                           "0.1 0.1 0 1 0 0 0 1\n";
  const auto repeat = runCommand(binPath("panmap-synth") + " --room 1 --trajectory " +
                                 dir.path("repeat.txt") + " --out " + dir.path("x"));
  EXPECT_EQ(repeat.exit_code, 1);
  EXPECT_NE(repeat.output.find("repeat.txt: pose 3's timestamp is not after the one before"),
            std::string::npos)
      << repeat.output;
}

// A survey cut short by --frames left what lay beyond its end unseen, and said nothing: a
// 150 m2 floor rendered for 600 frames at 5 Hz was walked to 40 % and scored as if mapped.
TEST(SynthCli, ASurveyCutShortIsNamedAndCoverWalkWalksAllOfIt) {
  test::TempDir dir;
  const std::string synth =
      binPath("panmap-synth") + " --quiet --room 3 --rate-hz 0.5 --masks clean --poses gt ";
  SurveyConfig config;
  config.rate_hz = 0.5;
  const int needed = framesToWalk(planSurveyPath(generateRoom(3).mesh, config, 1), config);
  ASSERT_GT(needed, 3);
  const auto cut = runCommand(synth + "--frames 3 --out " + dir.path("cut"));
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  EXPECT_NE(cut.output.find("panmap-synth: 3 frames walk " +
                            std::to_string(std::lround(300.0 / needed)) + " % of the survey's "),
            std::string::npos)
      << cut.output;
  EXPECT_NE(cut.output.find("--cover-walk or --frames " + std::to_string(needed)),
            std::string::npos)
      << cut.output;
  EXPECT_NEAR(readJson(dir.path("cut/info.json"))["trajectory"]["walk_covered"].get<double>(),
              3.0 / needed, 1e-12);
  const auto whole = runCommand(synth + "--frames 3 --cover-walk --out " + dir.path("whole"));
  ASSERT_EQ(whole.exit_code, 0) << whole.output;
  EXPECT_EQ(whole.output.find("% of the survey"), std::string::npos) << whole.output;
  const auto info = readJson(dir.path("whole/info.json"));
  EXPECT_EQ(info["frames"].get<int>(), needed);
  EXPECT_EQ(info["trajectory"]["walk_covered"].get<double>(), 1.0);
  // A room of 28 m^2 of free floor keeps 10 stops; --area-per-stop 2 spreads one per 2 m^2.
  EXPECT_EQ(info["trajectory"]["stops"].get<int>(), 10);
  const double free_m2 = info["trajectory"]["free_area_m2"].get<double>();
  EXPECT_GT(free_m2, 20.0);
  const auto dense = runCommand(synth + "--frames 2 --area-per-stop 2 --out " + dir.path("dense"));
  ASSERT_EQ(dense.exit_code, 0) << dense.output;
  EXPECT_EQ(readJson(dir.path("dense/info.json"))["trajectory"]["stops"].get<int>(),
            static_cast<int>(std::ceil(free_m2 / 2.0)));
  // --frames stays the least: a walk shorter than it is walked again.
  const auto more = runCommand(synth + "--frames " + std::to_string(needed + 2) +
                               " --cover-walk --out " + dir.path("more"));
  ASSERT_EQ(more.exit_code, 0) << more.output;
  EXPECT_EQ(readJson(dir.path("more/info.json"))["frames"].get<int>(), needed + 2);
}

// Previews of an earlier run into the same folder were left beside the new run's.
TEST(SynthCli, PreviewsOfAnEarlierRunAreRemoved) {
  test::TempDir dir;
  const std::string synth = binPath("panmap-synth") + " --quiet --preview-every 1 --out " +
                            dir.path("x") + " --room 2 --frames ";
  ASSERT_EQ(runCommand(synth + "4").exit_code, 0);
  auto previews = [&] {
    size_t n = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.path("x/preview"))) {
      n += e.path().extension() == ".png";
    }
    return n;
  };
  const size_t per_frame = previews() / 4;
  ASSERT_GT(per_frame, 0u);
  ASSERT_EQ(runCommand(synth + "2").exit_code, 0);
  EXPECT_EQ(previews(), 2 * per_frame);
}

}  // namespace
}  // namespace panmap
