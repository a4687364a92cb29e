// Inputs on which fuzz/fuzz_lcm_messages and fuzz/fuzz_lcm_session once failed
// (tests/fixtures/fuzz_regressions/), and the same faults built by hand for other message
// types: each must be refused as a malformed message, by the decoder's own length checks
// (decode returns -1, nothing thrown), or by the mapper with a counted reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <string>
#include <vector>

#include "panmap/graph/optimiser.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/decode.h"
#include "panmap/lcm/graph_conversions.h"
#include "panmap/lcm/mapping_session.h"
#include "panmap/lcm/message_types.h"
#include "panmap/panoptic_t.hpp"
#include "panmap/pose_t.hpp"
#include "panmap/rgbd_frame_t.hpp"
#include "panmap/status_t.hpp"
#include "panmap/superpoint_graph_t.hpp"
#include "test_helpers.h"

namespace panmap {
namespace {

std::vector<uint8_t> withFingerprint(int64_t hash, const uint8_t* body, size_t size) {
  std::vector<uint8_t> bytes;
  bytes.reserve(8 + size);
  for (int i = 0; i < 8; ++i) {
    bytes.push_back(static_cast<uint8_t>(static_cast<uint64_t>(hash) >> (56 - 8 * i)));
  }
  bytes.insert(bytes.end(), body, body + size);
  return bytes;
}

// A fuzz_lcm_messages input is a type selector byte and the body after the fingerprint.
std::vector<uint8_t> messageOfFuzzInput(const std::string& fixture, int64_t hash) {
  const std::string input = test::fileBytes(test::fixtureDir("fuzz_regressions/" + fixture));
  EXPECT_FALSE(input.empty()) << fixture;
  if (input.empty()) return {};
  return withFingerprint(hash, reinterpret_cast<const uint8_t*>(input.data()) + 1,
                         input.size() - 1);
}

template <typename Msg>
void expectRefused(const std::vector<uint8_t>& bytes, const std::string& type) {
  Msg msg;
  int used = 0;
  EXPECT_NO_THROW(used = msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())));
  EXPECT_EQ(used, -1);
  EXPECT_FALSE(decodeExactly(bytes.data(), bytes.size(), &msg));
  const MessageCheck check = checkMessage(bytes.data(), bytes.size(), true);
  EXPECT_EQ(check.type, type);
  EXPECT_FALSE(check.ok);
}

template <typename Msg>
std::vector<uint8_t> encode(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

void putBigEndian32(std::vector<uint8_t>* bytes, size_t at, int32_t value) {
  for (int i = 0; i < 4; ++i) {
    (*bytes)[at + i] = static_cast<uint8_t>(static_cast<uint32_t>(value) >> (24 - 8 * i));
  }
}

TEST(LcmFuzzRegressions, ArrayLengthBeyondTheMessageIsRefusedBeforeAllocating) {
  // A 163-byte status_t claimed a string array of ~10^9 entries: the generated decoder
  // resized the array first (gigabytes) and only then found the message short.
  expectRefused<status_t>(
      messageOfFuzzInput("lcm_messages/status_huge_array_length", status_t::getHash()), "status_t");
}

TEST(LcmFuzzRegressions, StringLengthOfInt32MinIsRefused) {
  // The decoder computed length - 1 for the string copy: signed overflow at INT32_MIN.
  expectRefused<status_t>(
      messageOfFuzzInput("lcm_messages/status_string_length_int_min", status_t::getHash()),
      "status_t");
}

TEST(LcmFuzzRegressions, GraphWithInstanceInt32MaxIsRefusedByTheOptimiser) {
  // A superpoint_graph_t whose vertex carried instance INT32_MAX: refinement numbered new
  // instances from max + 1 (signed overflow). panmap-optimizer converts and optimises it.
  const std::vector<uint8_t> bytes =
      messageOfFuzzInput("lcm_messages/graph_instance_int32_max", superpoint_graph_t::getHash());
  superpoint_graph_t msg;
  ASSERT_TRUE(decodeExactly(bytes.data(), bytes.size(), &msg));
  test::expectError([&] { optimise(fromMessage(msg), OptimiserConfig{}); }, {"instance", "2^30"});
}

TEST(LcmFuzzRegressions, ImageSizeFieldBeyondTheMessageIsRefused) {
  // rgbd_frame_t: the colour image's byte count is the last field before its data.
  rgbd_frame_t msg{};  // LCM types leave plain fields uninitialised
  msg.camera = "x";
  std::vector<uint8_t> bytes = encode(msg);
  // fingerprint 8, utime 8, frame_id 8, camera 4 + 2, five doubles 40, then the image
  // header: width 4, height 4, row_stride 4, pixel_format 1, compression 1, size 4.
  const size_t size_at = 8 + 8 + 8 + 6 + 40 + 14;
  for (int32_t claimed : {INT32_MAX, 1 << 30, -1}) {
    putBigEndian32(&bytes, size_at, claimed);
    expectRefused<rgbd_frame_t>(bytes, "rgbd_frame_t");
  }
}

TEST(LcmFuzzRegressions, VertexCountBeyondTheMessageIsRefused) {
  superpoint_graph_t msg{};
  std::vector<uint8_t> bytes = encode(msg);
  // fingerprint 8, utime 8, request_id 8, voxel_size_m 8, num_classes 4, num_background 4.
  putBigEndian32(&bytes, 8 + 8 + 8 + 8 + 4 + 4, 1 << 28);
  expectRefused<superpoint_graph_t>(bytes, "superpoint_graph_t");
}

TEST(LcmFuzzRegressions, EmptyStringLengthIsRefused) {
  // LCM strings carry their NUL, so a length of 0 is malformed (the decoder copied 2^64 - 1).
  rgbd_frame_t msg{};  // LCM types leave plain fields uninitialised
  msg.camera = "x";
  std::vector<uint8_t> bytes = encode(msg);
  putBigEndian32(&bytes, 8 + 8 + 8, 0);
  expectRefused<rgbd_frame_t>(bytes, "rgbd_frame_t");
}

// Replays a fuzz_lcm_session input the way the target does: entries [channel][length, 2 bytes
// little-endian][body], the channel type's fingerprint put in front unless bit 7 is set, fed
// to a MappingSession over the target's mapper; nothing may escape.
SessionStats replaySession(const std::string& fixture) {
  const std::string input = test::fileBytes(test::fixtureDir("fuzz_regressions/" + fixture));
  EXPECT_FALSE(input.empty()) << fixture;
  MapperConfig config;
  config.num_threads = 1;
  config.map.voxel_size_m = 0.05f;
  config.occupancy.resolution_m = 0.2;
  Mapper mapper(config);
  MappingSession session(SessionOptions{}, &mapper);
  const auto* data = reinterpret_cast<const uint8_t*>(input.data());
  size_t pos = 0;
  while (pos < input.size()) {
    const uint8_t name = data[pos++];
    size_t len = pos < input.size() ? data[pos++] : 0;
    if (pos < input.size()) len |= static_cast<size_t>(data[pos++]) << 8;
    len = std::min(len, input.size() - pos);
    const uint8_t* body = data + pos;
    pos += len;
    const int channel = name & 3;
    const bool raw = (name & 0x80) != 0;
    const int64_t hashes[] = {rgbd_frame_t::getHash(), pose_t::getHash(), panoptic_t::getHash()};
    const char* channels[] = {"CAMERA_RGBD", "CAMERA_POSE", "PANOPTIC", "PANMAP_STATUS"};
    const std::vector<uint8_t> bytes = raw || channel == 3
                                           ? std::vector<uint8_t>(body, body + len)
                                           : withFingerprint(hashes[channel], body, len);
    EXPECT_NO_THROW(session.handle(channels[channel], bytes.data(), bytes.size()));
  }
  EXPECT_NO_THROW(session.flush());
  return session.stats();
}

TEST(LcmFuzzRegressions, FrameReachingBeyondTheMapIsRefusedByTheSession) {
  // Two frames with poses and masks, the second with depth_scale_m 3.6e52: its points reached
  // the voxel lookup as NaN (UBSan: float to int). The first frame's depth PNG is corrupt
  // (refused as a bad message); the second decodes and the mapper refuses it.
  const SessionStats stats = replaySession("lcm_session/depth_scale_3e52");
  EXPECT_EQ(stats.frames_received, 1);
  EXPECT_EQ(stats.frames_integrated, 0);
  EXPECT_EQ(stats.rejected.count("frame: extent"), 1u) << ::testing::PrintToString(stats.rejected);
}

TEST(LcmFuzzRegressions, HugeFocalLengthIsRefusedByTheSession) {
  // The first frame says fx = 2.2e233: the integrator's ray stride overflowed an int.
  const SessionStats stats = replaySession("lcm_session/focal_length_2e233");
  EXPECT_EQ(stats.rejected.count("frame: intrinsics"), 1u)
      << ::testing::PrintToString(stats.rejected);
}

TEST(LcmFuzzRegressions, PoseAtInt64MinIsRefusedByTheSession) {
  // A pose with utime INT64_MIN: the synchroniser's time differences overflowed int64.
  const SessionStats stats = replaySession("lcm_session/pose_utime_int64_min");
  EXPECT_GE(stats.rejected.count("bad CAMERA_POSE: pose"), 1u)
      << ::testing::PrintToString(stats.rejected);
  pose_t msg{};
  msg.utime = INT64_MIN;
  msg.orientation[0] = 1.0;
  test::expectError([&] { fromMessage(msg); }, {"utime", "out of range"});
  msg.utime = 1700000000000000;  // 2023 in microseconds
  EXPECT_NO_THROW(fromMessage(msg));
}

TEST(LcmFuzzRegressions, MapperRefusesFramesBeyondItsExtent) {
  Mapper mapper(MapperConfig{});
  RgbdFrame frame;
  frame.camera = PinholeCamera{10.0, 10.0, 3.5, 2.5, 8, 6};
  frame.depth = DepthImage(8, 6, 1000);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation().x() = 1e9;
  test::expectError([&] { mapper.integrate(frame, far, nullptr); }, {"extent", "reaches"});
  frame.depth_scale_m = 1e30;
  test::expectError([&] { mapper.integrate(frame, Eigen::Isometry3d::Identity(), nullptr); },
                    {"extent"});
  frame.depth_scale_m = 0.001;
  frame.camera.fx = 1e-300;
  test::expectError([&] { mapper.integrate(frame, Eigen::Isometry3d::Identity(), nullptr); },
                    {"extent"});
  frame.camera.fx = 2.2e233;
  test::expectError([&] { mapper.integrate(frame, Eigen::Isometry3d::Identity(), nullptr); },
                    {"intrinsics"});
  frame.camera.fx = 10.0;
  EXPECT_NO_THROW(mapper.integrate(frame, Eigen::Isometry3d::Identity(), nullptr));
  EXPECT_EQ(mapper.framesIntegrated(), 1);
}

}  // namespace
}  // namespace panmap
