// Garbage on the wire (issue 21): every input channel takes random bytes, messages of the
// wrong type, truncated arrays, sizes that disagree with the data, NaN/inf poses, repeated and
// out-of-order timestamps and frames whose pose never comes; each is counted by reason and the
// map is byte-identical to the clean run's.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "panmap/lcm/decode.h"
#include "panmap/lcm/mapping_session.h"
#include "synthetic_stream.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::Encoded;

const char* const kChannels[] = {"CAMERA_RGBD", "CAMERA_POSE", "PANOPTIC"};

class WireGarbage : public ::testing::Test {
 protected:
  void SetUp() override {
    messages_ = stream().messages();
    clean_ = run(messages_, &clean_stats_);
    ASSERT_TRUE(clean_stats_.rejected.empty());
  }
  static const test::SyntheticStream& stream() { return test::syntheticStream(); }

  // Maps a message list; returns the map's bytes.
  static std::string run(const std::vector<Encoded>& messages, SessionStats* stats) {
    Mapper mapper(test::streamMapperConfig());
    MappingSession session(SessionOptions{}, &mapper);
    for (const Encoded& m : messages) session.handle(m.channel, m.bytes.data(), m.bytes.size());
    session.flush();
    *stats = session.stats();
    return test::mapBytes(mapper);
  }

  // Runs with the garbage and checks the map and the frames mapped against the clean run.
  SessionStats expectCleanMap(const std::vector<Encoded>& messages) {
    SessionStats stats;
    EXPECT_EQ(run(messages, &stats), clean_);
    EXPECT_EQ(stats.frames_integrated, clean_stats_.frames_integrated);
    return stats;
  }

  std::vector<Encoded> messages_;
  std::string clean_;
  SessionStats clean_stats_;
};

TEST_F(WireGarbage, RandomBytesOnEveryChannel) {
  std::mt19937 rng(7);
  std::vector<Encoded> messages;
  for (const Encoded& m : messages_) {
    messages.push_back(m);
    for (const char* channel : kChannels) {
      std::vector<uint8_t> junk(std::uniform_int_distribution<size_t>(0, 300)(rng));
      for (uint8_t& b : junk) b = static_cast<uint8_t>(rng());
      messages.push_back({channel, junk});
    }
  }
  const SessionStats stats = expectCleanMap(messages);
  for (const char* channel : kChannels) {
    EXPECT_EQ(stats.rejected.at(std::string("malformed ") + channel),
              static_cast<int64_t>(messages_.size()))
        << channel;
  }
}

TEST_F(WireGarbage, MessagesOfTheWrongType) {
  // Each real message also arrives on the two other input channels.
  std::vector<Encoded> messages;
  for (const Encoded& m : messages_) {
    messages.push_back(m);
    for (const char* channel : kChannels) {
      if (m.channel != channel) messages.push_back({channel, m.bytes});
    }
  }
  const SessionStats stats = expectCleanMap(messages);
  const int64_t per_channel = 2 * static_cast<int64_t>(stream().frames.size());
  for (const char* channel : kChannels) {
    EXPECT_EQ(stats.rejected.at(std::string("malformed ") + channel), per_channel) << channel;
  }
}

TEST_F(WireGarbage, TruncatedArrays) {
  // Every message cut inside its arrays (and one byte short), before the real one.
  std::vector<Encoded> messages;
  int64_t cut = 0;
  for (const Encoded& m : messages_) {
    for (size_t keep : {m.bytes.size() / 3, m.bytes.size() - 1}) {
      messages.push_back(
          {m.channel, std::vector<uint8_t>(m.bytes.begin(), m.bytes.begin() + keep)});
      ++cut;
    }
    messages.push_back(m);
  }
  const SessionStats stats = expectCleanMap(messages);
  int64_t malformed = 0;
  for (const char* channel : kChannels)
    malformed += stats.rejected.at(std::string("malformed ") + channel);
  EXPECT_EQ(malformed, cut);
}

TEST_F(WireGarbage, SizesThatDisagreeWithTheData) {
  std::vector<Encoded> messages;
  const size_t n = stream().frames.size();
  ImageEncoding raw;
  raw.color = raw.depth = raw.labels = image_t::COMPRESSION_NONE;
  for (size_t k = 0; k < n; ++k) {
    // A raw depth image one pixel wider than its bytes, at a utime of its own.
    RgbdFrame f = stream().frames[k];
    f.utime += 1000;
    rgbd_frame_t wide = toMessage(f, raw);
    wide.depth.width += 1;
    messages.push_back(test::encodeMessage("CAMERA_RGBD", wide));
    // A mask whose segment count claims more segments than the message holds.
    Encoded mask = test::encodeMessage("PANOPTIC", toMessage(stream().masks[k], raw));
    panoptic_t decoded;
    ASSERT_TRUE(decodeExactly(mask.bytes.data(), mask.bytes.size(), &decoded));
    const size_t count_at = 8 + 16 + 18 + static_cast<size_t>(decoded.segment_ids.size);
    mask.bytes[count_at] = 0x7f;  // big-endian int32: now > 2e9 segments
    messages.push_back(mask);
    messages.push_back(messages_[3 * k]);
    messages.push_back(messages_[3 * k + 1]);
    messages.push_back(messages_[3 * k + 2]);
  }
  const SessionStats stats = expectCleanMap(messages);
  int64_t bad_frames = 0;
  for (const auto& [reason, count] : stats.rejected) {
    if (reason.rfind("bad CAMERA_RGBD", 0) == 0) bad_frames += count;
  }
  EXPECT_EQ(bad_frames, static_cast<int64_t>(n));
  EXPECT_EQ(stats.rejected.at("malformed PANOPTIC"), static_cast<int64_t>(n));
}

TEST_F(WireGarbage, NanAndInfinitePoses) {
  // Before each real pose, NaN and infinite ones at the same utime: refused, so the real one
  // is the one kept.
  std::vector<Encoded> messages;
  const double kBad[] = {std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()};
  for (const Encoded& m : messages_) {
    if (m.channel == std::string("CAMERA_POSE")) {
      pose_t pose;
      ASSERT_TRUE(decodeExactly(m.bytes.data(), m.bytes.size(), &pose));
      for (double bad : kBad) {
        pose_t position = pose, orientation = pose;
        position.position[1] = bad;
        orientation.orientation[0] = bad;
        messages.push_back(test::encodeMessage("CAMERA_POSE", position));
        messages.push_back(test::encodeMessage("CAMERA_POSE", orientation));
      }
    }
    messages.push_back(m);
  }
  const SessionStats stats = expectCleanMap(messages);
  int64_t bad_poses = 0;
  for (const auto& [reason, count] : stats.rejected) {
    if (reason.rfind("bad CAMERA_POSE", 0) == 0) bad_poses += count;
  }
  EXPECT_EQ(bad_poses, 4 * static_cast<int64_t>(stream().frames.size()));
  EXPECT_EQ(stats.rejected.count("pose: repeated timestamp"), 0u);
}

TEST_F(WireGarbage, RepeatedTimestamps) {
  // Every message twice; then each frame's utime again with other content.
  std::vector<Encoded> messages;
  for (const Encoded& m : messages_) {
    messages.push_back(m);
    messages.push_back(m);
  }
  const size_t n = stream().frames.size();
  for (size_t k = 0; k + 1 < n; ++k) {
    RgbdFrame other = stream().frames[k + 1];
    other.utime = stream().frames[k].utime;
    StampedPose pose = stream().poses[k + 1];
    pose.utime = stream().poses[k].utime;
    // Inserted after the originals of frame k (messages 6k..6k+5), before frame k+1.
    const auto at = messages.begin() + static_cast<long>(6 * (k + 1) + 2 * k);
    messages.insert(at, {test::encodeMessage("CAMERA_POSE", toMessage(pose)),
                         test::encodeMessage("CAMERA_RGBD", toMessage(other, ImageEncoding{}))});
  }
  const SessionStats stats = expectCleanMap(messages);
  EXPECT_EQ(stats.rejected.at("frame: repeated timestamp"), static_cast<int64_t>(2 * n - 1));
  EXPECT_EQ(stats.rejected.at("pose: repeated timestamp"), static_cast<int64_t>(2 * n - 1));
  EXPECT_EQ(stats.rejected.at("panoptic: repeated timestamp"), static_cast<int64_t>(n));
}

TEST_F(WireGarbage, OutOfOrderTimestamps) {
  // After the clean stream, old frames, poses and masks arrive again, late.
  std::vector<Encoded> messages = messages_;
  const size_t n = stream().frames.size();
  for (size_t k = 0; k + 2 < n; k += 3) {
    messages.push_back(messages_[3 * k + 2]);  // frame k
    messages.push_back(messages_[3 * k + 1]);  // its mask
    messages.push_back(messages_[3 * k]);      // its pose
  }
  // And one frame older than the newest mapped one in the middle of the stream.
  messages.insert(messages.begin() + 3 * 8, messages_[3 * 2 + 2]);
  const SessionStats stats = expectCleanMap(messages);
  EXPECT_EQ(stats.rejected.at("frame: out of order"), 5);
  EXPECT_EQ(stats.rejected.at("panoptic: arrived after its frame was mapped"), 4);
}

TEST_F(WireGarbage, FramesWhosePoseNeverComes) {
  // Between each pair of real frames, a frame 100 ms later with no pose (and no mask).
  std::vector<Encoded> messages;
  const size_t n = stream().frames.size();
  for (size_t k = 0; k < n; ++k) {
    messages.push_back(messages_[3 * k]);
    messages.push_back(messages_[3 * k + 1]);
    messages.push_back(messages_[3 * k + 2]);
    RgbdFrame orphan = stream().frames[k];
    orphan.utime += 100000;
    messages.push_back(test::encodeMessage("CAMERA_RGBD", toMessage(orphan, ImageEncoding{})));
  }
  const SessionStats stats = expectCleanMap(messages);
  // Between two frames' poses (333 ms apart, beyond sync.max_pose_gap_ms) but the last.
  EXPECT_EQ(stats.rejected.at("frame: poses around it too far apart to interpolate"),
            static_cast<int64_t>(n - 1));
  EXPECT_EQ(stats.rejected.at("frame: no pose"), 1);
}

}  // namespace
}  // namespace panmap
