// End to end: panmap-synth makes a short log; lcm-logplayer replays it over loopback UDP into
// panmap-mapper and panmap-optimizer (skipped where multicast is unavailable); the offline
// mode gives byte-identical outputs run after run; a dead optimiser costs the labels, not the
// map.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>

#include <nlohmann/json.hpp>

#include "child_process.h"
#include "lcm_udp.h"
#include "panmap/io/ply.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mapper/objects.h"
#include "panmap/object_list_t.hpp"
#include "panmap/status_t.hpp"
#include "test_helpers.h"

namespace panmap {
namespace {

struct ObjectsInbox {
  object_list_t last;
  void onObjects(const lcm::ReceiveBuffer*, const std::string&, const object_list_t* msg) {
    last = *msg;
  }
};

// Non-default port: away from any live LCM traffic on the machine and from the replay test.
const char* kUrl = "udpm://239.255.76.67:7683?ttl=0&recv_buf_size=16777216";

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

class LiveCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    const test::CommandResult r =
        test::runCommand(test::binPath("panmap-synth") + " --room 2 --frames 30 --masks m2f " +
                         "--poses gt --seed 5 -q --out " + dir_->path("seq"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string log() { return dir_->path("seq/sequence.lcmlog"); }
  // Waits for a mapper's first status on `url`, then replays the log into it.
  static void replayOnceListening(const std::string& url) {
    lcm::LCM lcm(url);
    test::StatusWatch watch;
    lcm.subscribe("PANMAP_STATUS", &test::StatusWatch::onStatus, &watch);
    for (int i = 0; i < 100 && watch.received == 0; ++i) lcm.handleTimeout(100);
    ASSERT_GT(watch.received, 0) << "no mapper status on " << url;
    test::ChildProcess player({"lcm-logplayer", "-l", url, log()});
    ASSERT_TRUE(player.wait(60)) << "lcm-logplayer did not finish";
  }
  static test::TempDir* dir_;
};
test::TempDir* LiveCli::dir_ = nullptr;

TEST_F(LiveCli, OfflineRunsAreByteIdentical) {
  for (const char* out : {"a", "b"}) {
    const test::CommandResult r =
        test::runCommand(test::binPath("panmap-mapper") + " -q --log " + log() +
                         " --voxel-size 0.02 --out " + dir_->path(out));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  int compared = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir_->path("a"))) {
    const std::string name = entry.path().filename().string();
    if (name == "report.json") continue;  // holds wall-clock timings
    EXPECT_EQ(test::fileBytes(entry.path().string()), test::fileBytes(dir_->path("b/" + name)))
        << name;
    ++compared;
  }
  EXPECT_GE(compared, 9);  // three meshes, map, config, four snapshots (and more as added)
  const nlohmann::json report = readJson(dir_->path("a/report.json"));
  EXPECT_EQ(report["frames_integrated"], 30);
  EXPECT_EQ(report["mode"], "offline");
}

TEST_F(LiveCli, LogplayerToMapperAndOptimiserOverUdp) {
  if (!test::multicastWorks(kUrl)) GTEST_SKIP() << test::kNoMulticast;
  const std::string out = dir_->path("live");
  test::ChildProcess optimiser({test::binPath("panmap-optimizer"), "--lcm-url", kUrl},
                               dir_->path("optimizer.log"));
  test::ChildProcess mapper(
      {test::binPath("panmap-mapper"), "--lcm-url", kUrl, "--out", out, "--voxel-size", "0.02",
       "--queue-frames", "64", "--optimizer-timeout-s", "60"},
      dir_->path("mapper.log"));
  ASSERT_TRUE(optimiser.started() && mapper.started());
  // The mapper is up once its status arrives.
  lcm::LCM lcm(kUrl);
  test::StatusWatch watch;
  lcm.subscribe("PANMAP_STATUS", &test::StatusWatch::onStatus, &watch);
  ObjectsInbox objects;
  lcm.subscribe("PANMAP_OBJECTS", &ObjectsInbox::onObjects, &objects);
  for (int i = 0; i < 100 && watch.received == 0; ++i) lcm.handleTimeout(100);
  ASSERT_GT(watch.received, 0) << test::fileBytes(dir_->path("mapper.log"));

  test::ChildProcess player({"lcm-logplayer", "-l", kUrl, log()}, dir_->path("player.log"));
  ASSERT_TRUE(player.wait(60)) << "lcm-logplayer did not finish";
  ASSERT_EQ(player.exitCode(), 0);
  // A planner's view: the probe takes the next PANMAP_OCTOMAP and answers from the tree. Half
  // a metre in front of the camera's last position is free space it looked through; far
  // outside the room nothing was seen.
  const StampedPose last = readTumTrajectory(dir_->path("seq/gt/trajectory_gt.txt")).back();
  const Eigen::Vector3d ahead_W = last.T_W_C * Eigen::Vector3d(0.0, 0.0, 0.5);
  char point[256];
  std::snprintf(point, sizeof(point), " --point %.3f %.3f %.3f --segment %.3f %.3f %.3f 0 0 -100",
                ahead_W.x(), ahead_W.y(), ahead_W.z(), ahead_W.x(), ahead_W.y(), ahead_W.z());
  const test::CommandResult probe = test::runCommand(
      test::binPath("panmap-occupancy-probe") + " --lcm-url '" + kUrl + "' --timeout-s 30" + point);
  EXPECT_EQ(probe.exit_code, 0) << probe.output;
  EXPECT_NE(probe.output.find("\nfree\n"), std::string::npos) << probe.output;
  // The way down through the floor is not free: blocked by it (or unknown below it).
  EXPECT_TRUE(probe.output.find("\nblocked at") != std::string::npos ||
              probe.output.find("\nunknown at") != std::string::npos)
      << probe.output;
  // A command returns with its result: a save that cannot be written fails, naming why,
  // and an export returns once its files exist.
  const std::string command = test::binPath("panmap-command") + " -q --lcm-url '" + kUrl + "' ";
  const test::CommandResult bad_save =
      test::runCommand(command + "save " + dir_->path("none/map.panmap"));
  EXPECT_EQ(bad_save.exit_code, 1) << bad_save.output;
  EXPECT_EQ(test::countLines(bad_save.output), 1) << bad_save.output;
  EXPECT_NE(bad_save.output.find("panmap-command: error: save failed: "), std::string::npos)
      << bad_save.output;
  EXPECT_NE(bad_save.output.find("none/map.panmap"), std::string::npos) << bad_save.output;
  const test::CommandResult exported = test::runCommand(command + "export " + dir_->path("midway"));
  EXPECT_EQ(exported.exit_code, 0) << exported.output;
  EXPECT_NE(exported.output.find("export: outputs written to " + dir_->path("midway")),
            std::string::npos)
      << exported.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_->path("midway/mesh_instance.ply")));
  // Its objects.json is stamped with the newest frame mapped, as the final one is (an export
  // wrote utime 0: a planner could not tell which map state it held).
  int64_t objects_utime = 0;
  readObjectsJson(dir_->path("midway/objects.json"), &objects_utime);
  EXPECT_EQ(objects_utime, readTumTrajectory(dir_->path("midway/trajectory.txt")).back().utime);
  // As a user ends a replay: finish returns when the outputs are written. (What queued up on
  // this socket meanwhile is read first: a full receive buffer would drop what comes next.)
  while (lcm.handleTimeout(0) > 0) {
  }
  const test::CommandResult finish = test::runCommand(command + "finish");
  EXPECT_EQ(finish.exit_code, 0) << finish.output;
  EXPECT_NE(finish.output.find("panmap-command: finish: outputs written to " + out +
                               "; panmap-mapper is done"),
            std::string::npos)
      << finish.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(out + "/report.json"));
  // The last PANMAP_OBJECTS is the final map's, as objects.json holds it (the channel's last
  // objects were those of the last publish period, with other ids).
  while (lcm.handleTimeout(200) > 0) {
  }
  int64_t final_utime = 0;
  const std::vector<MappedObject> written = readObjectsJson(out + "/objects.json", &final_utime);
  EXPECT_EQ(objects.last.utime, final_utime);
  std::vector<int32_t> sent_ids, written_ids;
  for (const object_t& o : objects.last.objects) sent_ids.push_back(o.id);
  for (const MappedObject& o : written) written_ids.push_back(o.id);
  EXPECT_EQ(sent_ids, written_ids);
  ASSERT_TRUE(mapper.wait(120)) << test::fileBytes(dir_->path("mapper.log"));
  ASSERT_EQ(mapper.exitCode(), 0) << test::fileBytes(dir_->path("mapper.log"));
  optimiser.signal(SIGTERM);
  ASSERT_TRUE(optimiser.wait(10));

  const nlohmann::json report = readJson(out + "/report.json");
  EXPECT_EQ(report["mode"], "live");
  EXPECT_TRUE(report["graph"]["optimised"].get<bool>());
  EXPECT_EQ(report["frames_received"], 30);
  // UDP may lose datagrams under load, but every received frame is integrated or counted.
  EXPECT_GE(report["frames_integrated"].get<int>(), 20);
  const LabelledMesh mesh = readPly(out + "/mesh_instance.ply");
  ASSERT_GT(mesh.numVertices(), 1000u);
  const std::set<int32_t> classes(mesh.semantic.begin(), mesh.semantic.end());
  const std::set<int32_t> instances(mesh.instance.begin(), mesh.instance.end());
  EXPECT_GE(classes.size(), 3u);    // wall, floor and furniture at least
  EXPECT_GE(instances.size(), 3u);  // with 0 (stuff)
  const std::unique_ptr<Mapper> map = Mapper::load(out + "/map.panmap");
  EXPECT_EQ(map->framesIntegrated(), report["frames_integrated"].get<int64_t>());
}

// LCM publishes whether anyone listens or not: a command nobody confirms is an error, unless
// the user asked only to send it.
TEST(CommandCli, ACommandNoMapperConfirmsFailsInOneLine) {
  const std::string url = "udpm://239.255.76.67:7685?ttl=0";
  if (!test::multicastWorks(url)) GTEST_SKIP() << test::kNoMulticast;
  const std::string command =
      test::binPath("panmap-command") + " --lcm-url '" + url + "' --timeout-s 1 optimise";
  const test::CommandResult unheard = test::runCommand(command);
  EXPECT_EQ(unheard.exit_code, 1);
  EXPECT_EQ(test::countLines(unheard.output), 1) << unheard.output;
  EXPECT_NE(unheard.output.find("sent optimise on PANMAP_COMMAND, but no panmap-mapper status "
                                "came on PANMAP_STATUS within 1.0 s"),
            std::string::npos)
      << unheard.output;
  const test::CommandResult sent = test::runCommand(command + " --no-wait");
  EXPECT_EQ(sent.exit_code, 0) << sent.output;
  EXPECT_EQ(sent.output, "");
}

TEST_F(LiveCli, DeadOptimiserCostsTheLabelsNotTheMap) {
  const std::string url = "udpm://239.255.76.67:7684?ttl=0&recv_buf_size=16777216";
  if (!test::multicastWorks(url)) GTEST_SKIP() << test::kNoMulticast;
  const std::string out = dir_->path("dead");
  test::ChildProcess optimiser({test::binPath("panmap-optimizer"), "--lcm-url", url});
  test::ChildProcess mapper(
      {test::binPath("panmap-mapper"), "--lcm-url", url, "--out", out, "--voxel-size", "0.04",
       "--queue-frames", "64", "--optimizer-timeout-s", "1"},
      dir_->path("dead.log"));
  replayOnceListening(url);
  if (HasFatalFailure()) return;
  optimiser.signal(SIGKILL);  // the optimiser dies mid-run
  ASSERT_TRUE(optimiser.wait(10));
  mapper.signal(SIGINT);  // Ctrl-C finishes like the command
  ASSERT_TRUE(mapper.wait(120));
  EXPECT_EQ(mapper.exitCode(), 0);
  const std::string log_text = test::fileBytes(dir_->path("dead.log"));
  EXPECT_NE(log_text.find("writing unoptimised outputs"), std::string::npos) << log_text;
  const nlohmann::json report = readJson(out + "/report.json");
  EXPECT_FALSE(report["graph"]["optimised"].get<bool>());
  const std::unique_ptr<Mapper> map = Mapper::load(out + "/map.panmap");
  EXPECT_EQ(map->framesIntegrated(), report["frames_integrated"].get<int64_t>());
  EXPECT_GT(map->framesIntegrated(), 0);
  EXPECT_GT(readPly(out + "/mesh_instance.ply").numVertices(), 1000u);
}

// The output folder gone when the live mapper finishes (a full disk does the same): the map
// lived only in the process and was lost with it. It is kept now: save and export to another
// place are served, and finish tries again.
TEST_F(LiveCli, AFinishThatCannotWriteKeepsTheMap) {
  const std::string url = "udpm://239.255.76.67:7686?ttl=0&recv_buf_size=16777216";
  if (!test::multicastWorks(url)) GTEST_SKIP() << test::kNoMulticast;
  const std::string out = dir_->path("kept");
  test::ChildProcess mapper(
      {test::binPath("panmap-mapper"), "--lcm-url", url, "--out", out, "--voxel-size", "0.04",
       "--queue-frames", "64", "--optimizer-timeout-s", "0.5"},
      dir_->path("kept.log"));
  replayOnceListening(url);
  if (HasFatalFailure()) return;
  std::filesystem::remove_all(out);
  std::ofstream(out) << "a file where the folder was";
  const std::string command = test::binPath("panmap-command") + " -q --lcm-url '" + url + "' ";
  const test::CommandResult failed = test::runCommand(command + "finish");
  EXPECT_EQ(failed.exit_code, 1) << failed.output;
  EXPECT_NE(failed.output.find("finish failed: "), std::string::npos) << failed.output;
  EXPECT_NE(failed.output.find("the map is kept"), std::string::npos) << failed.output;
  const test::CommandResult saved =
      test::runCommand(command + "save " + dir_->path("rescued.panmap"));
  EXPECT_EQ(saved.exit_code, 0) << saved.output;
  std::filesystem::remove(out);
  const test::CommandResult again = test::runCommand(command + "finish");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  ASSERT_TRUE(mapper.wait(60)) << test::fileBytes(dir_->path("kept.log"));
  EXPECT_EQ(mapper.exitCode(), 0) << test::fileBytes(dir_->path("kept.log"));
  const std::unique_ptr<Mapper> rescued = Mapper::load(dir_->path("rescued.panmap"));
  EXPECT_GT(rescued->framesIntegrated(), 0);
  EXPECT_EQ(Mapper::load(out + "/map.panmap")->framesIntegrated(), rescued->framesIntegrated());
}

// A live mapper that never got a frame (a wrong URL, or started after the camera stopped)
// wrote an empty map and exited 0 after waiting for labels of an empty graph; as offline, it
// now ends with exit 1 and one line saying why, and writes nothing.
TEST_F(LiveCli, AFinishWithoutAFrameMappedFailsAndSaysWhy) {
  const std::string url = "udpm://239.255.76.67:7687?ttl=0&recv_buf_size=16777216";
  if (!test::multicastWorks(url)) GTEST_SKIP() << test::kNoMulticast;
  const std::string out = dir_->path("empty");
  test::ChildProcess mapper(
      {test::binPath("panmap-mapper"), "--lcm-url", url, "--out", out, "--voxel-size", "0.04"},
      dir_->path("empty.log"));
  lcm::LCM lcm(url);
  test::StatusWatch watch;
  lcm.subscribe("PANMAP_STATUS", &test::StatusWatch::onStatus, &watch);
  for (int i = 0; i < 100 && watch.received == 0; ++i) lcm.handleTimeout(100);
  ASSERT_GT(watch.received, 0) << test::fileBytes(dir_->path("empty.log"));
  const std::string command = test::binPath("panmap-command") + " -q --lcm-url '" + url + "' ";
  const test::CommandResult finish = test::runCommand(command + "finish");
  EXPECT_EQ(finish.exit_code, 1) << finish.output;
  EXPECT_NE(finish.output.find("no frame mapped (0 frames received on CAMERA_RGBD)"),
            std::string::npos)
      << finish.output;
  ASSERT_TRUE(mapper.wait(30)) << test::fileBytes(dir_->path("empty.log"));
  EXPECT_EQ(mapper.exitCode(), 1);
  const std::string log_text = test::fileBytes(dir_->path("empty.log"));
  EXPECT_EQ(log_text.find("waiting up to"), std::string::npos) << log_text;  // no labels asked
  EXPECT_FALSE(std::filesystem::exists(out + "/map.panmap"));
  EXPECT_FALSE(std::filesystem::exists(out + "/autosave"));
}

}  // namespace
}  // namespace panmap
