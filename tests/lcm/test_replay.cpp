// Replaying an imported log through LCM: in-process with LCM's file:// provider, and through
// the real lcm-logplayer over loopback UDP multicast (skipped where multicast is unavailable).
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <map>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "lcm_udp.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/log_import.h"
#include "test_helpers.h"

extern char** environ;

namespace panmap {
namespace {

// Collects every message of every channel, in arrival order.
class Recorder {
 public:
  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const auto* d = static_cast<const uint8_t*>(rbuf->data);
    received[channel].emplace_back(d, d + rbuf->data_size);
  }
  size_t total() const {
    size_t n = 0;
    for (const auto& kv : received) n += kv.second.size();
    return n;
  }
  std::map<std::string, std::vector<std::vector<uint8_t>>> received;
};

// The payloads of a log per channel, in order.
std::map<std::string, std::vector<std::vector<uint8_t>>> logPayloads(const std::string& path) {
  std::map<std::string, std::vector<std::vector<uint8_t>>> out;
  lcm::LogFile log(path, "r");
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    const auto* d = static_cast<const uint8_t*>(e->data);
    out[e->channel].emplace_back(d, d + e->datalen);
  }
  return out;
}

void expectIntactFrames(const Recorder& recorder, const std::string& log_path) {
  const auto expected = logPayloads(log_path);
  ASSERT_EQ(recorder.received.size(), expected.size());
  for (const auto& [channel, payloads] : expected) {
    const auto& got = recorder.received.at(channel);
    ASSERT_EQ(got.size(), payloads.size()) << channel;
    for (size_t i = 0; i < payloads.size(); ++i)
      EXPECT_EQ(got[i], payloads[i]) << channel << " " << i;
  }
  // And every frame decodes into a valid frame.
  for (const auto& bytes : recorder.received.at("CAMERA_RGBD")) {
    rgbd_frame_t msg;
    ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
              static_cast<int>(bytes.size()));
    EXPECT_EQ(fromMessage(msg).depth.width(), 640);
  }
}

class Replay : public ::testing::Test {
 protected:
  void SetUp() override {
    PANMAP_REQUIRE_DATA("7scenes-200");
    ImportOptions options;
    options.max_frames = max_frames_;
    importDataset(test::dataDir("7scenes-200"), log_path_, options);
  }
  size_t max_frames_ = 0;  // all 200
  test::TempDir dir_;
  std::string log_path_ = dir_.path("7s.lcmlog");
};

TEST_F(Replay, FileProviderDeliversEveryFrame) {
  lcm::LCM lcm("file://" + log_path_ + "?speed=0");
  ASSERT_TRUE(lcm.good());
  Recorder recorder;
  lcm.subscribe(".*", &Recorder::onMessage, &recorder);
  // Bounded: stops at the expected count, or after a second with no message.
  while (recorder.total() < 400 && lcm.handleTimeout(1000) > 0) {
  }
  expectIntactFrames(recorder, log_path_);
}

TEST_F(Replay, LcmLogplayerOverLoopbackUdp) {
  // A non-default port keeps this test away from any live LCM traffic on the machine.
  const std::string url = "udpm://239.255.76.67:7671?ttl=0&recv_buf_size=16777216";
  if (!test::multicastWorks(url)) {
    GTEST_SKIP() << test::kNoMulticast;
  }
  lcm::LCM lcm(url);
  Recorder recorder;
  lcm.subscribe("CAMERA_.*", &Recorder::onMessage, &recorder);

  std::vector<std::string> args = {"lcm-logplayer", "-s", "10", "-l", url, log_path_};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawnp(&pid, "lcm-logplayer", nullptr, nullptr, argv.data(), environ), 0)
      << "cannot start lcm-logplayer";
  // Bounded loop: at most 60 s; after the player exits, one quiet second ends it.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  bool player_done = false;
  int status = 0;
  while (recorder.total() < 400 && std::chrono::steady_clock::now() < deadline) {
    const int handled = lcm.handleTimeout(1000);
    if (!player_done) player_done = waitpid(pid, &status, WNOHANG) == pid;
    if (handled == 0 && player_done) break;
  }
  if (!player_done) {
    kill(pid, SIGTERM);
    waitpid(pid, &status, 0);
  }
  expectIntactFrames(recorder, log_path_);
}

}  // namespace
}  // namespace panmap
