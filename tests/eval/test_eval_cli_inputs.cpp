// panmap-eval as a user runs it on ScanNet ground truth (scene folder or benchmark file),
// with --classes and --confidences, and on trajectories alone.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "panmap/core/pose.h"
#include "panmap/io/ply.h"
#include "panmap/io/tum_trajectory.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::binPath;
using test::runCommand;

const char kTable[] = "scannet-meta/scannetv2-labels.combined.tsv";

std::string tinyDir() { return test::fixtureDir("scannet_gt_tiny"); }

std::string eval() {
  const std::string bin = binPath("panmap-eval");
  EXPECT_TRUE(std::filesystem::exists(bin)) << "build panmap-eval first: " << bin;
  return bin;
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The tiny scene's GT (tests/io/test_scannet_ground_truth.cpp): chair = vertices 0-2,
// cabinet = 3-7, trash bin = 8, vertex 9 an unknown label, 10 in no group. The prediction
// finds the chair (10) and the cabinet (20) exactly and calls the trash bin a chair (31).
void writePrediction(const std::string& path) {
  LabelledMesh pred = readPly(tinyDir() + "/scene0000_00_vh_clean_2.ply");
  pred.semantic = {5, 5, 5, 3, 3, 3, 3, 3, 5, 0, 0};
  pred.instance = {10, 10, 10, 20, 20, 20, 20, 20, 31, 0, 0};
  pred.superpoint.assign(pred.numVertices(), 0);
  writePly(path, pred);
}

// objects.json as panmap-mapper writes it (writeObjectsJson), only ids and confidences matter.
void writeObjects(const std::string& path, double chair, double false_chair) {
  auto object = [](int id, int cls, double confidence) {
    return nlohmann::json{{"id", id},
                          {"class", cls},
                          {"class_name", "x"},
                          {"confidence", confidence},
                          {"num_voxels", 10},
                          {"centroid", {0, 0, 0}},
                          {"aabb_min", {0, 0, 0}},
                          {"aabb_max", {1, 1, 1}},
                          {"obb_center", {0.5, 0.5, 0.5}},
                          {"obb_orientation_wxyz", {1, 0, 0, 0}},
                          {"obb_extent", {1, 1, 1}},
                          {"superpoints", {1, 2}}};
  };
  const nlohmann::json j = {
      {"utime", 5},
      {"objects", {object(10, 5, chair), object(20, 3, 0.8), object(31, 5, false_chair)}}};
  std::ofstream(path) << j.dump(2);
}

TEST(EvalCliInputs, ScanNetSceneFolderAndBenchmarkFileAgree) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  test::TempDir dir;
  writePrediction(dir.path("pred.ply"));
  writeObjects(dir.path("objects.json"), 0.9, 0.3);
  const std::string common = eval() + " --pred " + dir.path("pred.ply") +
                             " --min-region-size 1 --confidences " + dir.path("objects.json");
  const auto scene = runCommand(common + " --gt-scannet " + tinyDir() + " --scannet-labels " +
                                test::dataDir(kTable) + " --json " + dir.path("scene.json"));
  ASSERT_EQ(scene.exit_code, 0) << scene.output;
  // The unknown raw labels are reported on one line.
  EXPECT_NE(scene.output.find("2 raw labels of scene0000_00 match no NYU40 class"),
            std::string::npos)
      << scene.output;
  // AP50 per class: chair 1 (its true positive outranks the false one), cabinet 1, trash bin
  // (otherfurniture) 0: no prediction. The other 15 classes have no GT (NaN, skipped).
  const nlohmann::json a = readJson(dir.path("scene.json"));
  EXPECT_NEAR(a["map50"].get<double>(), 2.0 / 3.0, 1e-12);
  EXPECT_EQ(a["ntp50"].get<int>(), 2);
  EXPECT_EQ(a["num_gt_vertices"].get<int>(), 11);
  EXPECT_EQ(a["classes"].size(), 18u);

  // The same GT as a benchmark file (class * 1000 + instance) with the bare mesh.
  std::ofstream(dir.path("gt.txt"))
      << "5001\n5001\n5001\n3002\n3002\n3002\n3002\n3002\n39003\n0\n0\n";
  const auto bench =
      runCommand(common + " --gt " + tinyDir() + "/scene0000_00_vh_clean_2.ply" +
                 " --gt-instances " + dir.path("gt.txt") + " --json " + dir.path("bench.json"));
  ASSERT_EQ(bench.exit_code, 0) << bench.output;
  const nlohmann::json b = readJson(dir.path("bench.json"));
  EXPECT_EQ(b["map50"], a["map50"]);
  EXPECT_EQ(b["map"], a["map"]);
  EXPECT_EQ(b["ntp50"], a["ntp50"]);

  // The false chair ranked first: ScanNet's curve gives the chair AP50 0.25 (precision
  // [0.5, 0, 1] times step widths [0.5, 0.5, 0]).
  writeObjects(dir.path("objects.json"), 0.9, 0.95);
  const std::string scannet =
      common + " --gt-scannet " + tinyDir() + " --scannet-labels " + test::dataDir(kTable);
  const auto ranked = runCommand(scannet + " --json " + dir.path("ranked.json"));
  ASSERT_EQ(ranked.exit_code, 0) << ranked.output;
  const nlohmann::json r = readJson(dir.path("ranked.json"));
  EXPECT_NEAR(r["map50"].get<double>(), (0.25 + 1.0 + 0.0) / 3.0, 1e-12);
  // --classes chair: the trash bin is no longer evaluated, so it is void and the false chair
  // lying on it is ignored, as in ScanNet's script.
  const auto chair = runCommand(scannet + " --classes chair --json " + dir.path("chair.json"));
  ASSERT_EQ(chair.exit_code, 0) << chair.output;
  const nlohmann::json c = readJson(dir.path("chair.json"));
  ASSERT_EQ(c["classes"].size(), 1u);
  EXPECT_EQ(c["classes"][0]["class_id"].get<int>(), 5);
  EXPECT_DOUBLE_EQ(c["map50"].get<double>(), 1.0);
}

// In ScanNet's own layout (the table above scans/<scene>/) no --scannet-labels is needed.
TEST(EvalCliInputs, TheLabelTableIsFoundInScanNetsLayout) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  test::TempDir dir;
  writePrediction(dir.path("pred.ply"));
  namespace fs = std::filesystem;
  fs::create_directories(dir.path("scans"));
  fs::create_directory_symlink(tinyDir(), dir.path("scans/scene0000_00"));
  fs::copy_file(test::dataDir(kTable), dir.path("scannetv2-labels.combined.tsv"));
  const std::string common = eval() + " --pred " + dir.path("pred.ply") + " --min-region-size 1";
  const auto found = runCommand(common + " --gt-scannet " + dir.path("scans/scene0000_00") +
                                " --json " + dir.path("found.json"));
  ASSERT_EQ(found.exit_code, 0) << found.output;
  const auto given = runCommand(common + " --gt-scannet " + tinyDir() + " --scannet-labels " +
                                test::dataDir(kTable) + " --json " + dir.path("given.json"));
  ASSERT_EQ(given.exit_code, 0) << given.output;
  EXPECT_EQ(readJson(dir.path("found.json"))["map50"], readJson(dir.path("given.json"))["map50"]);
  EXPECT_EQ(readJson(dir.path("found.json"))["num_gt_vertices"].get<int>(), 11);
}

TEST(EvalCliInputs, BadCombinationsExitWithOneLine) {
  test::TempDir dir;
  writePrediction(dir.path("pred.ply"));
  const std::string pred = " --pred " + dir.path("pred.ply");
  auto expectFailure = [](const test::CommandResult& r, const std::string& part) {
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(part), std::string::npos) << r.output;
  };
  expectFailure(runCommand(eval()), "nothing to evaluate");
  expectFailure(runCommand(eval() + pred), "--pred needs ground truth");
  expectFailure(runCommand(eval() + pred + " --gt-scannet " + tinyDir()),
                "scannet_gt_tiny: no scannetv2-labels.combined.tsv in it, its parent or its "
                "grandparent; give it with --scannet-labels");
  expectFailure(runCommand(eval() + " --gt " + dir.path("pred.ply")), "need --pred");
  expectFailure(runCommand(eval() + " --traj " + dir.path("t.txt")), "--gt-traj");
  const auto classes =
      runCommand(eval() + pred + " --gt " + dir.path("pred.ply") + " --classes chair,spaceship");
  expectFailure(classes, "'spaceship'");
  EXPECT_EQ(test::countLines(classes.output), 1) << classes.output;
  std::filesystem::create_directory(dir.path("scene0123_00"));
  const auto missing = runCommand(eval() + pred + " --gt-scannet " + dir.path("scene0123_00") +
                                  " --scannet-labels " + dir.path("labels.tsv"));
  expectFailure(missing, "scene0123_00: expected one *_vh_clean_2.ply mesh, found 0");
  EXPECT_EQ(test::countLines(missing.output), 1) << missing.output;
}

// Inputs that would score a meaningless 0 (or a wrong number) with exit 0: a mesh without
// labels, meshes that do not overlap, another map's confidences.
TEST(EvalCliInputs, WrongPredictionsAreNamedNotScored) {
  test::TempDir dir;
  writePrediction(dir.path("pred.ply"));
  const std::string gt = " --gt " + dir.path("pred.ply");  // the prediction scores itself
  LabelledMesh plain = readPly(dir.path("pred.ply"));
  plain.semantic.clear();
  plain.instance.clear();
  plain.superpoint.clear();
  writePly(dir.path("plain.ply"), plain);
  const auto unlabelled = runCommand(eval() + " --pred " + dir.path("plain.ply") + gt);
  EXPECT_EQ(unlabelled.exit_code, 1) << unlabelled.output;
  EXPECT_EQ(test::countLines(unlabelled.output), 1) << unlabelled.output;
  EXPECT_NE(unlabelled.output.find("plain.ply: needs semantic and instance vertex properties"),
            std::string::npos)
      << unlabelled.output;

  // The same mesh 10 m away (another scene, or a map in another frame) overlaps nothing.
  LabelledMesh far = readPly(dir.path("pred.ply"));
  for (Eigen::Vector3f& p : far.vertices) p.x() += 10.0f;
  writePly(dir.path("mm.ply"), far);
  const auto apart = runCommand(eval() + " --pred " + dir.path("mm.ply") + gt);
  EXPECT_EQ(apart.exit_code, 1) << apart.output;
  EXPECT_NE(apart.output.find("no ground-truth vertex has a predicted vertex within 0.05 m"),
            std::string::npos)
      << apart.output;

  // Half of it moved away: scored, with a warning and the share in the JSON.
  LabelledMesh half = readPly(dir.path("pred.ply"));
  for (size_t i = 0; i < half.numVertices(); i += 2) half.vertices[i].x() += 10.0f;
  writePly(dir.path("half.ply"), half);
  const auto partly =
      runCommand(eval() + " --pred " + dir.path("half.ply") + gt + " --json " + dir.path("h.json"));
  EXPECT_EQ(partly.exit_code, 0) << partly.output;
  EXPECT_NE(partly.output.find("warning: only 45.5 % of the predicted vertices lie within"),
            std::string::npos)
      << partly.output;
  EXPECT_NEAR(readJson(dir.path("h.json"))["pred_near_gt_share"].get<double>(), 5.0 / 11.0, 1e-12);

  // Confidences of another map: none of the scored instances (at --min-region-size 1) is in it.
  nlohmann::json other = {{"objects", {{{"id", 7}, {"confidence", 0.5}}}}};
  std::ofstream(dir.path("other.json")) << other.dump();
  const auto foreign = runCommand(eval() + " --pred " + dir.path("pred.ply") + gt +
                                  " --min-region-size 1 --confidences " + dir.path("other.json"));
  EXPECT_EQ(foreign.exit_code, 0) << foreign.output;
  EXPECT_NE(foreign.output.find("warning: 3 of the 3 scored instances"), std::string::npos)
      << foreign.output;
  writeObjects(dir.path("objects.json"), 0.9, 0.1);
  const auto own = runCommand(eval() + " --pred " + dir.path("pred.ply") + gt +
                              " --min-region-size 1 --confidences " + dir.path("objects.json"));
  EXPECT_EQ(own.output.find("warning"), std::string::npos) << own.output;
  std::ofstream(dir.path("text_id.json")) << R"({"objects": [{"id": "10", "confidence": 0.5}]})";
  const auto text_id = runCommand(eval() + " --pred " + dir.path("pred.ply") + gt +
                                  " --confidences " + dir.path("text_id.json"));
  EXPECT_EQ(text_id.exit_code, 1);
  EXPECT_NE(text_id.output.find("an object's id is \"10\", not an integer instance id"),
            std::string::npos)
      << text_id.output;
}

TEST(EvalCliInputs, TrajectoriesAlone) {
  // Two laps of a box's corners, the second 0.5 m off: ATE RMSE 0.25 m after alignment
  // (tests/eval/test_trajectory_error.cpp explains why).
  std::vector<StampedPose> gt, estimate;
  for (int k = 0; k < 16; ++k) {
    const int c = k % 8;
    StampedPose p;
    p.utime = 1000000 + k * 100000;
    p.T_W_C.translation() =
        Eigen::Vector3d(c & 1 ? 2.0 : 0.0, c & 2 ? 1.0 : 0.0, c & 4 ? 0.5 : 0.0);
    gt.push_back(p);
    if (k >= 8) p.T_W_C.translation() += Eigen::Vector3d(0.3, 0.4, 0.0);
    p.utime += 10000;  // 10 ms later: still associated
    estimate.push_back(p);
  }
  test::TempDir dir;
  writeTumTrajectory(dir.path("gt.txt"), gt);
  writeTumTrajectory(dir.path("est.txt"), estimate);
  const auto run = runCommand(eval() + " --traj " + dir.path("est.txt") + " --gt-traj " +
                              dir.path("gt.txt") + " --rpe-delta 0.8 --json " + dir.path("t.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("ATE [m]"), std::string::npos) << run.output;
  const nlohmann::json j = readJson(dir.path("t.json"));
  EXPECT_FALSE(j.contains("map50"));
  const nlohmann::json& t = j["trajectory"];
  EXPECT_EQ(t["num_associated"].get<int>(), 16);
  EXPECT_NEAR(t["ate_m"]["rmse"].get<double>(), 0.25, 1e-6);
  EXPECT_NEAR(t["ate_m"]["max"].get<double>(), 0.25, 1e-6);
  // 0.8 s apart = 8 steps: pose k and k + 8 are the same corner on different laps, so every
  // relative error is the offset itself.
  EXPECT_EQ(t["rpe_translation_m"]["count"].get<int>(), 8);
  EXPECT_NEAR(t["rpe_translation_m"]["rmse"].get<double>(), 0.5, 1e-6);
  EXPECT_NEAR(t["rpe_rotation_deg"]["max"].get<double>(), 0.0, 1e-6);
  const auto far = runCommand(eval() + " --traj " + dir.path("est.txt") + " --gt-traj " +
                              dir.path("gt.txt") + " --max-time-difference 0.005");
  EXPECT_EQ(far.exit_code, 1);
  EXPECT_NE(far.output.find("only 0 estimated poses"), std::string::npos) << far.output;
}

}  // namespace
}  // namespace panmap
