// panmap-occupancy-probe as a planner would run it: on a .bt file, and on PANMAP_OCTOMAP
// messages replayed from an LCM log through LCM's file:// provider.
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "panmap/occupancy/occupancy_map.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// test_occupancy does not depend on the probe's target: build it first or the tests skip.
#define REQUIRE_PROBE()                                                        \
  do {                                                                         \
    if (!std::filesystem::exists(probe_)) {                                    \
      GTEST_SKIP() << probe_ << " is not built (make panmap-occupancy-probe)"; \
    }                                                                          \
  } while (0)

void putBigEndian(std::string* out, uint64_t value, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

// A panmap.octomap_t message encoded as lcm-gen's C++ code does (big-endian fields after the
// type's fingerprint), without linking the generated types.
std::string encodeOctomapMessage(int64_t utime, double resolution_m, const std::string& type,
                                 bool binary, const std::string& data) {
  const uint64_t base = 0x40ec50f7a417408cULL;  // lcm-gen's hash of octomap_t's fields
  std::string out;
  putBigEndian(&out, (base << 1) + ((base >> 63) & 1), 8);
  putBigEndian(&out, static_cast<uint64_t>(utime), 8);
  uint64_t bits = 0;
  std::memcpy(&bits, &resolution_m, sizeof(bits));
  putBigEndian(&out, bits, 8);
  putBigEndian(&out, type.size() + 1, 4);
  out += type;
  out.push_back('\0');
  out.push_back(binary ? 1 : 0);
  putBigEndian(&out, data.size(), 4);
  return out + data;
}

// One event of an LCM log file (LCM's eventlog format: sync word, event number, time,
// channel and data lengths, channel, data; big-endian).
std::string logEvent(int64_t number, const std::string& channel, const std::string& data) {
  std::string out;
  putBigEndian(&out, 0xEDA1DA01u, 4);
  putBigEndian(&out, static_cast<uint64_t>(number), 8);
  putBigEndian(&out, static_cast<uint64_t>(1000000 + number), 8);
  putBigEndian(&out, channel.size(), 4);
  putBigEndian(&out, data.size(), 4);
  return out + channel + data;
}

// The wall of test_occupancy_map.cpp: a wall at x = 2.01 seen head-on from (0.02, 0.01, 0.03).
class ProbeCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    LabelledMesh mesh;
    test::addQuad(&mesh, {2.01f, -3, -3}, {2.01f, 3, -3}, {2.01f, 3, 3}, {2.01f, -3, 3}, 1, 1, 4);
    const MeshRenderer renderer(mesh);
    DepthNoiseConfig exact;
    exact.enabled = false;
    const Eigen::Isometry3d T = test::lookAt({0.02, 0.01, 0.03}, {1.02, 0.01, 0.03});
    map_ = new OccupancyMap();
    map_->integrate(simulateDepth(renderer.render(test::kinectCamera(), T), exact, 0), 0.001,
                    test::kinectCamera(), T);
  }
  static void TearDownTestSuite() { delete map_; }

  void writeLog(const std::string& path, const std::vector<std::string>& events) {
    std::ofstream out(path, std::ios::binary);
    for (const std::string& e : events) out << e;
  }
  test::CommandResult probe(const std::string& args) {
    return test::runCommand(probe_ + " " + args);
  }
  // stdout only (stderr carries progress).
  test::CommandResult answers(const std::string& args) {
    return test::runCommand("{ " + probe_ + " " + args + " 2>/dev/null; }");
  }

  static OccupancyMap* map_;
  const std::string probe_ = test::binPath("panmap-occupancy-probe");
  test::TempDir dir_;
};
OccupancyMap* ProbeCli::map_ = nullptr;

TEST_F(ProbeCli, AnswersPointsAndSegmentsFromABtFile) {
  REQUIRE_PROBE();
  const std::string bt = dir_.path("occupancy.bt");
  map_->writeBt(bt);
  auto ask = [&](const std::string& question) {
    const test::CommandResult r = answers("--file " + bt + " " + question);
    EXPECT_EQ(r.exit_code, 0) << question << ": " << r.output;
    return r.output;
  };
  EXPECT_EQ(ask("--point 1.0 0.4 -0.3"), "free\n");
  EXPECT_EQ(ask("--point 2.01 0.4 -0.3"), "occupied\n");
  EXPECT_EQ(ask("--point 2.3 0.4 -0.3"), "unknown\n");
  EXPECT_EQ(ask("--segment 0.02 0.01 0.03 1.99 0.01 0.03"), "free\n");
  EXPECT_EQ(ask("--segment 0.02 0.01 0.03 3 0.01 0.03"), "blocked at 2.025 0.025 0.025\n");
  EXPECT_EQ(ask("--segment 2.6 0.01 0.03 0.02 0.01 0.03"), "unknown at 2.575 0.025 0.025\n");
  EXPECT_EQ(ask("--point 2.01 0.4 -0.3 --segment 0.02 0.01 0.03 1.99 0.01 0.03"),
            "occupied\nfree\n");
}

TEST_F(ProbeCli, AnswersFromAPanmapOctomapMessage) {
  REQUIRE_PROBE();
  const std::string log = dir_.path("octomap.lcmlog");
  writeLog(log, {logEvent(0, "OTHER", "not for us"),
                 logEvent(1, "PANMAP_OCTOMAP",
                          encodeOctomapMessage(42, 0.05, "OcTree", true, map_->toBinaryData()))});
  const std::string url = "--lcm-url 'file://" + log + "?speed=0' --timeout-s 5";
  test::CommandResult r =
      answers(url + " --point 2.01 0.4 -0.3 --segment 0.02 0.01 0.03 3 0.01 0.03");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "occupied\nblocked at 2.025 0.025 0.025\n");
  // Another channel name.
  writeLog(log, {logEvent(0, "MY_TREE",
                          encodeOctomapMessage(42, 0.05, "OcTree", true, map_->toBinaryData()))});
  r = answers(url + " --channel MY_TREE --point 1.0 0.4 -0.3");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "free\n");
}

TEST_F(ProbeCli, FailsWithOneLineOnBadInput) {
  REQUIRE_PROBE();
  auto expectFailure = [&](const std::string& args, const std::string& reason) {
    const test::CommandResult r = probe(args);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(test::countLines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find(reason), std::string::npos) << r.output;
  };
  expectFailure("--file " + dir_.path("missing.bt") + " --point 0 0 0", "missing.bt");
  const std::string garbage = dir_.path("garbage.bt");
  std::ofstream(garbage) << "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.05\ndata\nxyz";
  expectFailure("--file " + garbage + " --point 0 0 0", "malformed or truncated");
  expectFailure("--file " + garbage, "nothing to ask");
  expectFailure("--file " + dir_.path("") + " --point 0 0 0", "is a folder, not a .bt file");
  // Trees that share no known cell do not "agree on 100 % of 0 cells".
  const std::string bt = dir_.path("occupancy.bt"), empty = dir_.path("empty.bt");
  map_->writeBt(bt);
  OccupancyMap().writeBt(empty);
  expectFailure("--file " + bt + " --compare " + empty, "no cell is known in both trees");

  const std::string log = dir_.path("bad.lcmlog");
  const std::string url = "--lcm-url 'file://" + log + "?speed=0' --point 0 0 0";
  writeLog(log, {logEvent(0, "PANMAP_OCTOMAP", "garbage")});
  expectFailure(url, "malformed message on PANMAP_OCTOMAP");
  const std::string data = map_->toBinaryData();
  writeLog(log, {logEvent(0, "PANMAP_OCTOMAP",
                          encodeOctomapMessage(1, 0.05, "OcTree", true, data.substr(0, 99)))});
  expectFailure(url, "malformed octree data");
  writeLog(log,
           {logEvent(0, "PANMAP_OCTOMAP", encodeOctomapMessage(1, 0.05, "OcTree", false, data))});
  expectFailure(url, "non-binary");
  writeLog(log, {logEvent(0, "PANMAP_OCTOMAP",
                          encodeOctomapMessage(1, 0.05, "ColorOcTree", true, data))});
  expectFailure(url, "ColorOcTree");
  // Nothing on the channel: the log ends, or (in-process provider, nobody publishing) the
  // bounded wait runs out.
  writeLog(log, {logEvent(0, "OTHER", "x")});
  expectFailure(url, "no message on PANMAP_OCTOMAP before LCM stopped");
  expectFailure("--lcm-url memq:// --timeout-s 0.3 --point 0 0 0",
                "no message on PANMAP_OCTOMAP within 0.3 s");
}

TEST_F(ProbeCli, HelpDescribesTheQuestions) {
  REQUIRE_PROBE();
  const test::CommandResult r = probe("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* word : {"--point", "--segment", "--file", "--lcm-url", "--channel",
                           "--timeout-s", "PANMAP_OCTOMAP"}) {
    EXPECT_NE(r.output.find(word), std::string::npos) << word;
  }
}

}  // namespace
}  // namespace panmap
