// Crash recovery end to end: panmap-mapper killed with SIGKILL while it maps, then
// `--resume`: the final map equals an uninterrupted run's over the frames it kept. Live over
// loopback UDP (skipped where multicast is unavailable), an optimiser started late or
// restarted still answers the final graph.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "child_process.h"
#include "lcm_udp.h"
#include "panmap/command_t.hpp"
#include "panmap/recovery/autosave.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;
using test::binPath;

constexpr double kPeriodS = 0.3;  // autosave period, stream time (9 frames at 30 Hz)

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Polls (not a timing assert) until the folder holds a snapshot or the child has exited.
bool waitForSnapshot(const std::string& dir, test::ChildProcess* child) {
  for (int i = 0; i < 3000; ++i) {
    if (!listAutosaves(dir).empty()) return true;
    if (child->wait(0.02)) return false;
  }
  return false;
}

class CrashRecovery : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    const test::CommandResult r =
        test::runCommand(binPath("panmap-synth") + " --room 2 --frames 90 --masks m2f " +
                         "--poses gt --seed 11 -q --out " + dir_->path("seq"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const test::CommandResult full =
        test::runCommand(binPath("panmap-mapper") + " -q --no-snapshots --voxel-size 0.04 --log " +
                         log() + " --out " + dir_->path("full"));
    ASSERT_EQ(full.exit_code, 0) << full.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string log() { return dir_->path("seq/sequence.lcmlog"); }
  static test::TempDir* dir_;
};
test::TempDir* CrashRecovery::dir_ = nullptr;

TEST_F(CrashRecovery, OfflineKillThenResumeEqualsTheUninterruptedRun) {
  const std::string out = dir_->path("crash");
  test::ChildProcess mapper(
      {binPath("panmap-mapper"), "-q", "--no-snapshots", "--voxel-size", "0.04", "--log", log(),
       "--out", out, "--autosave-s", std::to_string(kPeriodS)},
      dir_->path("crash.log"));
  ASSERT_TRUE(mapper.started());
  ASSERT_TRUE(waitForSnapshot(out + "/autosave", &mapper))
      << test::fileBytes(dir_->path("crash.log"));
  mapper.signal(SIGKILL);
  ASSERT_TRUE(mapper.wait(10));
  ASSERT_FALSE(fs::exists(out + "/report.json")) << "the run ended before the kill";

  // Run again into the same folder without --resume: refused, the snapshots untouched (a new
  // run cleared them with its own at its end, and hours of map went without a word).
  const std::vector<std::string> snapshots = listResumeCandidates(out + "/autosave");
  const test::CommandResult fresh =
      test::runCommand(binPath("panmap-mapper") + " -q --no-snapshots --log " + log() + " --out " +
                       out + " --autosave-s " + std::to_string(kPeriodS));
  EXPECT_EQ(fresh.exit_code, 1) << fresh.output;
  EXPECT_NE(fresh.output.find("holds snapshots of a run that did not finish"), std::string::npos)
      << fresh.output;
  EXPECT_NE(fresh.output.find("continue it with --resume " + out), std::string::npos)
      << fresh.output;
  EXPECT_EQ(listResumeCandidates(out + "/autosave"), snapshots);

  const test::CommandResult resumed = test::runCommand(
      binPath("panmap-mapper") + " -q --no-snapshots --resume " + out + " --log " + log());
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resumed from " + out + "/autosave/autosave-"), std::string::npos)
      << resumed.output;
  EXPECT_EQ(test::fileBytes(out + "/map.panmap"), test::fileBytes(dir_->path("full/map.panmap")));
  EXPECT_EQ(test::fileBytes(out + "/mesh_instance.ply"),
            test::fileBytes(dir_->path("full/mesh_instance.ply")));
  const nlohmann::json report = readJson(out + "/report.json");
  EXPECT_EQ(report["rejected"]["frame: mapped before the resume point"],
            report["resumed"]["frames"]);
  // Their masks went with them: no "masks matched no frame" warning about timestamps.
  EXPECT_EQ(report["unmatched_panoptic"], 0);
  EXPECT_EQ(report["panoptic_of_skipped_frames"], report["resumed"]["frames"]);
  // Lost: what was mapped after the snapshot resumed from, at most one period (frames are 1/30 s
  // apart; a snapshot streamed but not yet renamed counts when its checksum holds).
  EXPECT_LE(report["resumed"]["lost_frame_ids"].size(), static_cast<size_t>(kPeriodS * 30 + 1));
  // Cleared once the outputs are safe, journal and folder included.
  EXPECT_FALSE(fs::exists(out + "/autosave"));
}

TEST_F(CrashRecovery, LiveKillThenResumeMapsOnFromTheSnapshot) {
  const std::string url = "udpm://239.255.76.67:7685?ttl=0&recv_buf_size=16777216";
  if (!test::multicastWorks(url)) GTEST_SKIP() << test::kNoMulticast;
  const std::string out = dir_->path("live");
  const std::vector<std::string> live = {binPath("panmap-mapper"),
                                         "--lcm-url",
                                         url,
                                         "--voxel-size",
                                         "0.04",
                                         "--queue-frames",
                                         "256",
                                         "--no-snapshots",
                                         "--optimizer-timeout-s",
                                         "0",
                                         "--autosave-s",
                                         std::to_string(kPeriodS)};
  lcm::LCM lcm(url);
  test::StatusWatch watch;
  lcm.subscribe("PANMAP_STATUS", &test::StatusWatch::onStatus, &watch);
  std::string snapshot_copy;
  {
    std::vector<std::string> args = live;
    args.insert(args.end(), {"--out", out});
    test::ChildProcess mapper(args, dir_->path("live1.log"));
    for (int i = 0; i < 100 && watch.received == 0; ++i) lcm.handleTimeout(100);
    ASSERT_GT(watch.received, 0) << test::fileBytes(dir_->path("live1.log"));
    test::ChildProcess player({"lcm-logplayer", "-l", url, log()});
    ASSERT_TRUE(waitForSnapshot(out + "/autosave", &mapper));
    mapper.signal(SIGKILL);
    ASSERT_TRUE(mapper.wait(10));
    ASSERT_TRUE(player.wait(60));
  }
  // The snapshot the resume will take, kept to map the same frames offline afterwards.
  const std::string newest = listAutosaves(out + "/autosave").front();
  fs::create_directories(dir_->path("reference/autosave"));
  fs::copy_file(newest, dir_->path("reference/autosave/") + fs::path(newest).filename().string());
  {
    std::vector<std::string> args = live;
    args.insert(args.end(), {"--resume", out});
    watch.received = 0;
    test::ChildProcess mapper(args, dir_->path("live2.log"));
    for (int i = 0; i < 100 && watch.received == 0; ++i) lcm.handleTimeout(100);
    ASSERT_GT(watch.received, 0) << test::fileBytes(dir_->path("live2.log"));
    test::ChildProcess player({"lcm-logplayer", "-l", url, log()});
    ASSERT_TRUE(player.wait(60));
    command_t finish;
    finish.utime = 0;
    finish.command = command_t::COMMAND_FINISH;
    finish.argument = "";
    lcm.publish("PANMAP_COMMAND", &finish);
    ASSERT_TRUE(mapper.wait(120));
    ASSERT_EQ(mapper.exitCode(), 0) << test::fileBytes(dir_->path("live2.log"));
  }
  const std::string text = test::fileBytes(dir_->path("live2.log"));
  EXPECT_NE(text.find("resumed from " + newest), std::string::npos) << text;
  const nlohmann::json report = readJson(out + "/report.json");
  const int64_t before = report["resumed"]["frames"].get<int64_t>();
  EXPECT_GT(before, 0);
  EXPECT_EQ(report["rejected"]["frame: mapped before the resume point"].get<int64_t>(), before);
  EXPECT_LE(report["resumed"]["lost_frame_ids"].size(), static_cast<size_t>(kPeriodS * 30 + 1));
  EXPECT_FALSE(fs::exists(out + "/autosave"));  // snapshots, journal and folder: all cleared

  // The same snapshot continued offline over the log maps the same frames; when UDP delivered
  // every frame of the second replay the two maps are byte-identical.
  const test::CommandResult offline =
      test::runCommand(binPath("panmap-mapper") + " -q --no-snapshots --resume " +
                       dir_->path("reference") + " --log " + log());
  ASSERT_EQ(offline.exit_code, 0) << offline.output;
  if (report["frames_received"].get<int64_t>() == 90 && report["frames_dropped_behind"] == 0) {
    EXPECT_EQ(test::fileBytes(out + "/map.panmap"),
              test::fileBytes(dir_->path("reference/map.panmap")));
  }
  EXPECT_EQ(report["frames_total"], readJson(dir_->path("reference/report.json"))["frames_total"]);
}

TEST_F(CrashRecovery, AnOptimiserStartedAfterTheRequestStillAnswers) {
  const std::string url = "udpm://239.255.76.67:7686?ttl=0&recv_buf_size=16777216";
  if (!test::multicastWorks(url)) GTEST_SKIP() << test::kNoMulticast;
  const std::string out = dir_->path("late_optimiser");
  lcm::LCM lcm(url);
  test::StatusWatch watch;
  lcm.subscribe("PANMAP_STATUS", &test::StatusWatch::onStatus, &watch);
  // An optimiser that dies before the end: its replacement comes up only after the mapper
  // has asked for the labels.
  auto first = std::make_unique<test::ChildProcess>(
      std::vector<std::string>{binPath("panmap-optimizer"), "--lcm-url", url});
  test::ChildProcess mapper(
      {binPath("panmap-mapper"), "--lcm-url", url, "--voxel-size", "0.04", "--no-snapshots",
       "--out", out, "--optimizer-timeout-s", "60", "--optimizer-retry-s", "0.5"},
      dir_->path("late.log"));
  for (int i = 0; i < 100 && watch.received == 0; ++i) lcm.handleTimeout(100);
  ASSERT_GT(watch.received, 0);
  test::ChildProcess player({"lcm-logplayer", "-l", url, log()});
  ASSERT_TRUE(player.wait(60));
  first->signal(SIGKILL);
  ASSERT_TRUE(first->wait(10));
  command_t finish;
  finish.utime = 0;
  finish.command = command_t::COMMAND_FINISH;
  finish.argument = "";
  lcm.publish("PANMAP_COMMAND", &finish);
  for (int i = 0; i < 600 && watch.state != "optimising"; ++i) lcm.handleTimeout(100);
  ASSERT_EQ(watch.state, "optimising");
  test::ChildProcess second({binPath("panmap-optimizer"), "--lcm-url", url});
  ASSERT_TRUE(mapper.wait(120));
  ASSERT_EQ(mapper.exitCode(), 0) << test::fileBytes(dir_->path("late.log"));
  const nlohmann::json report = readJson(out + "/report.json");
  EXPECT_TRUE(report["graph"]["optimised"].get<bool>());
  // The copies sent while no optimiser listened were lost; a later one was answered.
  EXPECT_GE(report["graph_requests_sent"].get<int64_t>(), 2);
}

}  // namespace
}  // namespace panmap
