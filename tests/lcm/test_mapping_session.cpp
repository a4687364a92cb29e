// The mapping session shared by the offline reader and the live process: every kind of bad
// input is refused with a counted reason and leaves the map exactly as a clean run makes it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "panmap/lcm/mapping_session.h"
#include "synthetic_stream.h"
#include "test_helpers.h"

namespace panmap {
namespace {

void feed(MappingSession* session, const std::vector<test::Encoded>& messages) {
  for (const test::Encoded& m : messages)
    session->handle(m.channel, m.bytes.data(), m.bytes.size());
  session->flush();
}

class MappingSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    stream_ = test::syntheticStream();
    Mapper mapper(test::streamMapperConfig());
    MappingSession session(SessionOptions{}, &mapper);
    feed(&session, stream_.messages());
    clean_ = test::mapBytes(mapper);
    clean_stats_ = session.stats();
  }
  test::SyntheticStream stream_;
  std::string clean_;
  SessionStats clean_stats_;
};

TEST_F(MappingSessionTest, CleanStreamMapsEveryFrame) {
  EXPECT_EQ(clean_stats_.frames_integrated, static_cast<int64_t>(stream_.frames.size()));
  EXPECT_EQ(clean_stats_.frames_received, static_cast<int64_t>(stream_.frames.size()));
  EXPECT_TRUE(clean_stats_.rejected.empty());
  EXPECT_EQ(clean_stats_.sync.geometry_only, 0);
  EXPECT_EQ(clean_stats_.timings.count("total"), 1u);
}

TEST_F(MappingSessionTest, MalformedAndTruncatedMessagesAreCounted) {
  std::vector<test::Encoded> messages = stream_.messages();
  std::vector<test::Encoded> bad;
  test::Encoded truncated = messages[2];  // the first RGB-D frame, cut short
  truncated.bytes.resize(truncated.bytes.size() / 2);
  bad.push_back(truncated);
  bad.push_back({"CAMERA_POSE", {1, 2, 3}});
  bad.push_back({"PANOPTIC", std::vector<uint8_t>(64, 0xff)});
  bad.push_back({"CAMERA_RGBD", {}});
  messages.insert(messages.begin() + 3, bad.begin(), bad.end());
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, messages);
  const SessionStats stats = session.stats();
  EXPECT_EQ(stats.rejected.at("malformed CAMERA_RGBD"), 2);
  EXPECT_EQ(stats.rejected.at("malformed CAMERA_POSE"), 1);
  EXPECT_EQ(stats.rejected.at("malformed PANOPTIC"), 1);
  EXPECT_EQ(stats.frames_integrated, clean_stats_.frames_integrated);
  EXPECT_EQ(test::mapBytes(mapper), clean_);
}

TEST_F(MappingSessionTest, NanPoseAndMismatchedDepthAreRefused) {
  std::vector<test::Encoded> messages = stream_.messages();
  // A NaN pose at a time no frame has, and a frame whose depth disagrees with its intrinsics.
  pose_t nan_msg = toMessage(stream_.poses[0]);
  nan_msg.utime += 1000;
  nan_msg.position[0] = std::numeric_limits<double>::quiet_NaN();
  // Intrinsics of a 640x480 calibration sent with the 160x120 depth image.
  RgbdFrame wrong = stream_.frames[1];
  wrong.utime += 2000;
  wrong.camera.fx = wrong.camera.fy = 525.0;
  wrong.camera.cx = 319.5;
  wrong.camera.cy = 239.5;
  const rgbd_frame_t wrong_msg = toMessage(wrong, ImageEncoding{});
  messages.insert(messages.begin() + 3, test::encodeMessage("CAMERA_POSE", nan_msg));
  messages.insert(messages.begin() + 6, test::encodeMessage("CAMERA_RGBD", wrong_msg));
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, messages);
  const SessionStats stats = session.stats();
  int64_t pose_rejects = 0, frame_rejects = 0;
  for (const auto& [reason, n] : stats.rejected) {
    if (reason.rfind("bad CAMERA_POSE", 0) == 0) pose_rejects += n;
    if (reason.rfind("bad CAMERA_RGBD", 0) == 0 || reason.rfind("frame:", 0) == 0) {
      frame_rejects += n;
    }
  }
  EXPECT_EQ(pose_rejects, 1);
  EXPECT_EQ(frame_rejects, 1);
  EXPECT_EQ(stats.frames_integrated, clean_stats_.frames_integrated);
  EXPECT_EQ(test::mapBytes(mapper), clean_);
}

TEST_F(MappingSessionTest, UnknownCategoriesBecomeUnlabelled) {
  // Clean reference: the first segment of every mask is unknown (category 0) from the start.
  test::SyntheticStream zeroed = stream_, unknown = stream_;
  for (size_t k = 0; k < stream_.masks.size(); ++k) {
    ASSERT_FALSE(stream_.masks[k].segments.empty());
    zeroed.masks[k].segments[0].category = 0;
    unknown.masks[k].segments[0].category = 9999;
  }
  Mapper reference(test::streamMapperConfig());
  MappingSession reference_session(SessionOptions{}, &reference);
  feed(&reference_session, zeroed.messages());
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, unknown.messages());
  EXPECT_EQ(session.stats().rejected.at("panoptic segment: unknown category"),
            static_cast<int64_t>(stream_.masks.size()));
  EXPECT_EQ(test::mapBytes(mapper), test::mapBytes(reference));
}

TEST_F(MappingSessionTest, FramesWithoutPoseAndAStoppedPoseStream) {
  std::vector<test::Encoded> messages = stream_.messages();
  // After the clean stream the poses stop while frames keep coming: each is refused once
  // the synchroniser has waited long enough (or at the end of the stream).
  const int64_t last = stream_.frames.back().utime;
  for (int k = 1; k <= 5; ++k) {
    RgbdFrame late = stream_.frames[static_cast<size_t>(k)];
    late.utime = last + k * 400000;
    messages.push_back(test::encodeMessage("CAMERA_RGBD", toMessage(late, ImageEncoding{})));
  }
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, messages);
  const SessionStats stats = session.stats();
  EXPECT_EQ(stats.rejected.at("frame: no pose"), 5);
  EXPECT_EQ(stats.frames_integrated, clean_stats_.frames_integrated);
  EXPECT_EQ(test::mapBytes(mapper), clean_);
}

TEST_F(MappingSessionTest, MaxFramesStopsIntegration) {
  Mapper mapper(test::streamMapperConfig());
  SessionOptions options;
  options.max_frames = 3;
  MappingSession session(options, &mapper);
  feed(&session, stream_.messages());
  EXPECT_TRUE(session.done());
  EXPECT_EQ(session.stats().frames_integrated, 3);
  EXPECT_EQ(mapper.framesIntegrated(), 3);
}

}  // namespace
}  // namespace panmap
