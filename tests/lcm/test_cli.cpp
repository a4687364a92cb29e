// The command-line tools as a user runs them: exit codes, one-line errors, --help, --json.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "panmap/core/memory_policy.h"
#include "panmap/io/image_codec.h"
#include "scannet_sens_fixture.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::binPath;
using test::runCommand;

// Imports the first `frames` frames of 7scenes-200 into dir/s.lcmlog; a failed import fails the
// test.
void importSevenScenes(const test::TempDir& dir, int frames) {
  const auto imp =
      runCommand(binPath("panmap-import") + " --quiet --max-frames " + std::to_string(frames) +
                 " " + test::dataDir("7scenes-200") + " " + dir.path("s.lcmlog"));
  EXPECT_EQ(imp.exit_code, 0) << imp.output;
}

TEST(Cli, HelpExitsZero) {
  for (const char* tool : {"panmap-import", "panmap-loginfo"}) {
    const auto r = runCommand(binPath(tool) + " --help");
    EXPECT_EQ(r.exit_code, 0) << tool;
    EXPECT_NE(r.output.find("Usage"), std::string::npos) << r.output;
  }
}

TEST(Cli, ImportOfAMissingFolderFailsWithOneLine) {
  test::TempDir dir;
  const auto r =
      runCommand(binPath("panmap-import") + " " + dir.path("absent") + " " + dir.path("x.lcmlog"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(test::countLines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find(dir.path("absent")), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path("x.lcmlog")));
}

TEST(Cli, MapperRefusesAGridShiftWithAFrameStoreInOneLine) {
  test::TempDir dir;
  const auto r = runCommand(binPath("panmap-mapper") + " --grid-shift 0.01,0,0 --frame-store " +
                            dir.path("store") + " --log " + dir.path("absent.lcmlog") + " --out " +
                            dir.path("out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(test::countLines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("--grid-shift"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path("store")));
}

// The output folder is checked before any mapping: a long run must not end in "cannot write".
// The optimiser listened on its own answer channel (or none) and waited forever in silence.
TEST(Cli, OptimizerRefusesChannelsThatCannotWork) {
  for (const std::string args : {"--channel-graph G --channel-labels G", "--channel-graph ''"}) {
    const auto r = runCommand(binPath("panmap-optimizer") + " " + args);
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_EQ(test::countLines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("--channel-graph and --channel-labels"), std::string::npos) << r.output;
  }
}

TEST(Cli, MapperChecksTheOutputFolderFirst) {
  test::TempDir dir;
  std::ofstream(dir.path("file")) << "x";
  for (const std::string& out : {dir.path("file"), dir.path("file/map")}) {
    const auto r = runCommand(binPath("panmap-mapper") + " --log " + dir.path("absent.lcmlog") +
                              " --out " + out);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(test::countLines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find(dir.path("file") + " is a file, not a folder"), std::string::npos)
        << r.output;
  }
}

TEST(Cli, MapperRefusesNoOptimiseLiveInOneLine) {
  test::TempDir dir;
  const auto r = runCommand(binPath("panmap-mapper") + " --no-optimise --out " + dir.path("out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(test::countLines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("--no-optimise"), std::string::npos) << r.output;
}

// Offline --no-optimise writes the outputs a live mapper writes without an optimiser, and says
// so in report.json; --export-only of its map with the optimisation says the opposite.
TEST(Cli, MapperWithoutTheOptimisationSaysSo) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  importSevenScenes(dir, 3);
  if (HasFailure()) return;
  const std::string common = binPath("panmap-mapper") + " -q --voxel-size 0.05 --no-snapshots ";
  const auto mapped = runCommand(common + "--no-optimise --log " + dir.path("s.lcmlog") +
                                 " --out " + dir.path("a"));
  ASSERT_EQ(mapped.exit_code, 0) << mapped.output;
  auto optimised = [&](const std::string& out) {
    std::ifstream in(dir.path(out + "/report.json"));
    return nlohmann::json::parse(in)["graph"]["optimised"].get<bool>();
  };
  EXPECT_FALSE(optimised("a"));
  EXPECT_TRUE(std::filesystem::exists(dir.path("a/objects.json")));
  const auto exported = runCommand(common + "--export-only --load " + dir.path("a/map.panmap") +
                                   " --out " + dir.path("b"));
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  EXPECT_TRUE(optimised("b"));
}

// panmap-mapper runs itself again with its heap on transparent huge pages where the kernel
// gives them on request and glibc can ask (core/memory_policy.h), says so in report.json, and
// leaves them off when told to (PANMAP_HUGE_PAGES=0) or when GLIBC_TUNABLES already chose.
// The output of a run that restarted is the usual one line of a failure, not two.
TEST(Cli, MapperPutsItsHeapOnHugePagesWhereTheSystemAllows) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  importSevenScenes(dir, 2);
  if (HasFailure()) return;
  auto hugePages = [&](const std::string& env, const std::string& out) {
    const auto mapped =
        runCommand("env -u GLIBC_TUNABLES -u PANMAP_HUGE_PAGES " + env + " " +
                   binPath("panmap-mapper") + " -q --voxel-size 0.05 --no-snapshots --log " +
                   dir.path("s.lcmlog") + " --out " + dir.path(out));
    EXPECT_EQ(mapped.exit_code, 0) << mapped.output;
    std::ifstream in(dir.path(out + "/report.json"));
    return nlohmann::json::parse(in)["heap_huge_pages"].get<bool>();
  };
  const bool available = cLibraryCanAskForHugePages() && transparentHugePageMode() == "madvise";
  EXPECT_EQ(hugePages("", "a"), available);
  EXPECT_FALSE(hugePages("PANMAP_HUGE_PAGES=0", "b"));
  EXPECT_FALSE(hugePages("GLIBC_TUNABLES=glibc.malloc.hugetlb=0", "c"));
  // The same frames give the same map, restarted or not.
  std::ifstream a(dir.path("a/mesh_instance.ply"), std::ios::binary);
  std::ifstream b(dir.path("b/mesh_instance.ply"), std::ios::binary);
  EXPECT_TRUE(std::equal(std::istreambuf_iterator<char>(a), std::istreambuf_iterator<char>(),
                         std::istreambuf_iterator<char>(b), std::istreambuf_iterator<char>()));
  const auto failed = runCommand(binPath("panmap-mapper") + " -q --log " + dir.path("absent") +
                                 " --out " + dir.path("d"));
  EXPECT_EQ(failed.exit_code, 1);
  EXPECT_EQ(test::countLines(failed.output), 1) << failed.output;
}

// An output that cannot be written (a folder where objects.json goes) fails the run in one
// line, and report.json, which says what was mapped and written, is still there and names it.
TEST(Cli, MapperReportsAnOutputThatCouldNotBeWritten) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  importSevenScenes(dir, 2);
  if (HasFailure()) return;
  std::filesystem::create_directories(dir.path("a/objects.json"));
  const auto mapped =
      runCommand(binPath("panmap-mapper") + " -q --voxel-size 0.05 --no-snapshots --log " +
                 dir.path("s.lcmlog") + " --out " + dir.path("a"));
  EXPECT_EQ(mapped.exit_code, 1);
  EXPECT_EQ(test::countLines(mapped.output), 1) << mapped.output;
  EXPECT_NE(mapped.output.find("objects.json"), std::string::npos) << mapped.output;
  std::ifstream in(dir.path("a/report.json"));
  ASSERT_TRUE(in.good());
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["frames_integrated"].get<int64_t>(), 2);
  ASSERT_EQ(report["outputs_failed"].size(), 1u);
  EXPECT_NE(report["outputs_failed"][0].get<std::string>().find("objects.json"), std::string::npos);
}

// `--load MAP --log LOG` continues the map: the frames it holds are not mapped twice, and
// mapping flags that the map would ignore are refused, naming the setting.
TEST(Cli, ALoadedMapSkipsItsFramesAndKeepsItsSettings) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  importSevenScenes(dir, 4);
  if (HasFailure()) return;
  const std::string common = binPath("panmap-mapper") + " -q --voxel-size 0.05 --no-snapshots " +
                             "--log " + dir.path("s.lcmlog") + " ";
  ASSERT_EQ(runCommand(common + "--max-frames 2 --out " + dir.path("a")).exit_code, 0);
  const auto go_on =
      runCommand(common + "--load " + dir.path("a/map.panmap") + " --out " + dir.path("b"));
  ASSERT_EQ(go_on.exit_code, 0) << go_on.output;
  EXPECT_NE(go_on.output.find("2 frames; frames of the log up to its newest"), std::string::npos)
      << go_on.output;
  std::ifstream in(dir.path("b/report.json"));
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["frames_integrated"].get<int64_t>(), 2);
  EXPECT_EQ(report["rejected"]["frame: mapped before the resume point"].get<int64_t>(), 2);
  std::ifstream trajectory(dir.path("b/trajectory.txt"));
  int poses = 0;
  for (std::string line; std::getline(trajectory, line);) poses += !line.empty() && line[0] != '#';
  EXPECT_EQ(poses, 4);
  EXPECT_EQ(go_on.output.find("is it the log the map was made from"), std::string::npos)
      << go_on.output;
  // Another log (the same frames at another rate: other utimes) would be mapped onto the map
  // without a word; it is warned of.
  const auto other_log =
      runCommand(binPath("panmap-import") + " --quiet --max-frames 4 --rate 10 " +
                 test::dataDir("7scenes-200") + " " + dir.path("t.lcmlog"));
  ASSERT_EQ(other_log.exit_code, 0) << other_log.output;
  const auto onto = runCommand(binPath("panmap-mapper") + " -q --voxel-size 0.05 --no-snapshots " +
                               "--log " + dir.path("t.lcmlog") + " --load " +
                               dir.path("a/map.panmap") + " --out " + dir.path("d"));
  EXPECT_EQ(onto.exit_code, 0) << onto.output;
  EXPECT_NE(onto.output.find("has no frame at the loaded map's newest utime (100000): is it the "
                             "log the map was made from?"),
            std::string::npos)
      << onto.output;

  const auto other =
      runCommand(binPath("panmap-mapper") + " -q --voxel-size 0.02 --log " + dir.path("s.lcmlog") +
                 " --load " + dir.path("a/map.panmap") + " --out " + dir.path("c"));
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_EQ(test::countLines(other.output), 1) << other.output;
  EXPECT_NE(other.output.find("map.voxel_size_m: 0.05, this run asks for 0.02"), std::string::npos)
      << other.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path("c")));
}

// Depth in the wrong units (here read as metres per unit: every point kilometres away) mapped
// into an empty map with exit 0 and no word; it says so now, and exits 1 (a script checking
// the exit code took the empty map for a success).
TEST(Cli, MapperFailsWhenFramesGiveNoSurface) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  const auto imp =
      runCommand(binPath("panmap-import") + " --quiet --max-frames 2 --depth-scale 1 " +
                 test::dataDir("7scenes-200") + " " + dir.path("s.lcmlog"));
  ASSERT_EQ(imp.exit_code, 0) << imp.output;
  const auto mapped =
      runCommand(binPath("panmap-mapper") + " -q --voxel-size 0.05 " + "--no-snapshots --log " +
                 dir.path("s.lcmlog") + " --out " + dir.path("a"));
  EXPECT_EQ(mapped.exit_code, 1) << mapped.output;
  EXPECT_NE(mapped.output.find("error: 2 frames mapped but no surface came of them"),
            std::string::npos)
      << mapped.output;
  EXPECT_TRUE(std::filesystem::exists(dir.path("a/report.json")));  // written, for a look
  importSevenScenes(dir, 2);                                        // the right units: no warning
  const auto good = runCommand(binPath("panmap-mapper") + " -q --voxel-size 0.05 " +
                               "--no-snapshots --grid-shift 0.01,0,0 --log " +
                               dir.path("s.lcmlog") + " --out " + dir.path("b"));
  EXPECT_EQ(good.exit_code, 0) << good.output;
  EXPECT_EQ(good.output.find("no surface"), std::string::npos) << good.output;
  // The outputs of a shifted grid are in the moved frame, and the report says so.
  std::ifstream in(dir.path("b/report.json"));
  EXPECT_EQ(nlohmann::json::parse(in)["grid_shift_m"], nlohmann::json::array({0.01, 0.0, 0.0}));
}

// A log that gives no frame is an error, not an empty map: an empty file, bytes that are no LCM
// log, and a log whose frames are on another channel than the one asked for.
TEST(Cli, MapperRefusesALogWithoutFramesInOneLine) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  writeFileBytes(dir.path("empty.lcmlog"), {});
  std::vector<uint8_t> noise(4096);
  for (size_t i = 0; i < noise.size(); ++i)
    noise[i] = static_cast<uint8_t>((i * 2654435761u) >> 13);
  writeFileBytes(dir.path("noise.lcmlog"), noise);
  importSevenScenes(dir, 2);
  if (HasFailure()) return;
  const std::string mapper = binPath("panmap-mapper") + " -q --voxel-size 0.05 --no-snapshots ";
  const std::pair<std::string, std::string> cases[] = {
      {"--log " + dir.path("empty.lcmlog"), "the log is empty"},
      {"--log " + dir.path("noise.lcmlog"), "no LCM event in the log"},
      {"--channel-rgbd RGBD --log " + dir.path("s.lcmlog"),
       "no event on the RGB-D channel RGBD; the log has CAMERA_POSE (2), CAMERA_RGBD (2)"}};
  for (const auto& [arguments, reason] : cases) {
    const auto r = runCommand(mapper + arguments + " --out " + dir.path("out"));
    EXPECT_EQ(r.exit_code, 1) << arguments;
    EXPECT_EQ(test::countLines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("no frame mapped from"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(reason), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.path("out"))) << arguments;
  }
}

// A cut log is mapped up to its last whole event, with a warning and the damage in report.json.
TEST(Cli, MapperMapsTheReadablePartOfACutLogAndSaysSo) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  importSevenScenes(dir, 3);
  if (HasFailure()) return;
  auto bytes = readFileBytes(dir.path("s.lcmlog"));
  bytes.resize(bytes.size() - 1000);  // into the last frame's depth
  writeFileBytes(dir.path("cut.lcmlog"), bytes);
  const auto r =
      runCommand(binPath("panmap-mapper") + " -q --voxel-size 0.05 --no-snapshots --log " +
                 dir.path("cut.lcmlog") + " --out " + dir.path("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: log " + dir.path("cut.lcmlog") + ": unreadable after byte"),
            std::string::npos)
      << r.output;
  std::ifstream in(dir.path("out/report.json"));
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["frames_integrated"], 2);
  EXPECT_NE(report["log_damage"].get<std::string>().find("of " + std::to_string(bytes.size())),
            std::string::npos)
      << report["log_damage"];
}

TEST(Cli, ImportThenLogInfoJson) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  const auto imp = runCommand(binPath("panmap-import") + " --quiet --max-frames 5 " +
                              test::dataDir("7scenes-200") + " " + dir.path("s.lcmlog"));
  ASSERT_EQ(imp.exit_code, 0) << imp.output;
  EXPECT_NE(imp.output.find("5 frames, 5 poses"), std::string::npos) << imp.output;
  const auto info = runCommand(binPath("panmap-loginfo") + " --json " + dir.path("s.lcmlog"));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const auto json = nlohmann::json::parse(info.output);
  EXPECT_EQ(json["events"], 10);
  EXPECT_EQ(json["channels"][0]["channel"], "CAMERA_POSE");
  EXPECT_EQ(json["channels"][0]["decode_failures"], 0);
  EXPECT_EQ(json["channels"][1]["type"], "rgbd_frame_t");

  // A truncated copy makes loginfo exit non-zero.
  auto bytes = readFileBytes(dir.path("s.lcmlog"));
  bytes.resize(bytes.size() - 1000);
  writeFileBytes(dir.path("cut.lcmlog"), bytes);
  const auto cut = runCommand(binPath("panmap-loginfo") + " --quiet " + dir.path("cut.lcmlog"));
  EXPECT_EQ(cut.exit_code, 1);
  EXPECT_NE(cut.output.find("unreadable after byte"), std::string::npos) << cut.output;
}

TEST(Cli, ImportNamesTheBadFile) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  namespace fs = std::filesystem;
  fs::copy_file(test::dataDir("7scenes-200/camera-intrinsics.txt"),
                dir.path("camera-intrinsics.txt"));
  for (const char* kind : {".color.jpg", ".depth.png"}) {
    fs::create_symlink(test::dataDir(std::string("7scenes-200/frame-000000") + kind),
                       dir.path(std::string("frame-000000") + kind));
  }
  std::ofstream(dir.path("frame-000000.pose.txt")) << "1 0 0 0\n0 1 0 0\n0 0 1 nan\n0 0 0 1\n";
  const auto r =
      runCommand(binPath("panmap-import") + " --quiet " + dir.path() + " " + dir.path("x.lcmlog"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(test::countLines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("frame-000000.pose.txt"), std::string::npos) << r.output;
  const auto bad_option = runCommand(binPath("panmap-import") + " --layout nope " + dir.path() +
                                     " " + dir.path("x.lcmlog"));
  EXPECT_NE(bad_option.exit_code, 0);
}

// A ScanNet .sens recording imports as it is, and a cut-off one stops the import in one line
// naming the file and the frame, leaving no log behind.
TEST(Cli, ImportReadsAScanNetRecording) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  test::TempDir dir;
  test::writeScanNetExportAsSens(dir.path("scene0707_00.sens"));
  const auto r = runCommand(binPath("panmap-import") + " --quiet " + dir.path("scene0707_00.sens") +
                            " " + dir.path("s.lcmlog"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(scannet-sens layout): 3 frames, 3 poses"), std::string::npos)
      << r.output;
  const auto info = runCommand(binPath("panmap-loginfo") + " --json " + dir.path("s.lcmlog"));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_EQ(nlohmann::json::parse(info.output)["events"], 6);

  const std::string sens = dir.path("scene0707_00.sens");
  std::filesystem::resize_file(sens, std::filesystem::file_size(sens) - 1000);
  const auto cut = runCommand(binPath("panmap-import") + " --quiet " + dir.path() + " " +
                              dir.path("cut.lcmlog"));
  EXPECT_EQ(cut.exit_code, 1);
  EXPECT_EQ(test::countLines(cut.output), 1) << cut.output;
  EXPECT_NE(cut.output.find("scene0707_00.sens frame 2 of 3: the file ends inside it"),
            std::string::npos)
      << cut.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path("cut.lcmlog")));
}

}  // namespace
}  // namespace panmap
