// The pose-correction message a SLAM back-end publishes: round trip and refusals.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/message_types.h"
#include "test_helpers.h"

namespace panmap {
namespace {

PoseCorrection twoKeyframes() {
  PoseCorrection c;
  c.utime = 5000000;
  c.correction_id = 3;
  for (int i = 0; i < 2; ++i) {
    StampedPose p;
    p.utime = 1000000 + 500000 * i;
    p.T_W_C.linear() =
        Eigen::AngleAxisd(0.3 * (i + 1), Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    p.T_W_C.translation() = Eigen::Vector3d(1.5 * i, -0.25, 2.0);
    p.source = PoseSource::kSlam;
    c.poses.push_back(p);
  }
  return c;
}

std::vector<uint8_t> encode(const pose_correction_t& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  return bytes;
}

TEST(CorrectionConversions, RoundTripThroughTheWire) {
  const PoseCorrection c = twoKeyframes();
  const std::vector<uint8_t> bytes = encode(toMessage(c));
  pose_correction_t msg;
  ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  const PoseCorrection back = fromMessage(msg);
  EXPECT_EQ(back.utime, 5000000);
  EXPECT_EQ(back.correction_id, 3);
  ASSERT_EQ(back.poses.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(back.poses[i].utime, c.poses[i].utime);
    EXPECT_LT((back.poses[i].T_W_C.matrix() - c.poses[i].T_W_C.matrix()).cwiseAbs().maxCoeff(),
              1e-12);
  }
  const MessageCheck check = checkMessage(bytes.data(), bytes.size(), true);
  EXPECT_TRUE(check.ok) << check.error;
  EXPECT_EQ(check.type, "pose_correction_t");
}

TEST(CorrectionConversions, BadMessagesNameTheCorrectionAndTheProblem) {
  pose_correction_t msg = toMessage(twoKeyframes());
  msg.num_poses = 3;
  test::expectError([&] { fromMessage(msg); }, {"pose correction 3", "num_poses 3"});
  msg = toMessage(twoKeyframes());
  msg.poses[1].position[0] = std::numeric_limits<double>::quiet_NaN();
  test::expectError([&] { fromMessage(msg); }, {"pose correction 3", "non-finite"});
  msg = toMessage(twoKeyframes());
  msg.poses[0].orientation[0] = 2.0;
  test::expectError([&] { fromMessage(msg); }, {"pose correction 3", "unit length"});
  msg = toMessage(twoKeyframes());
  std::swap(msg.poses[0], msg.poses[1]);
  test::expectError([&] { fromMessage(msg); }, {"pose correction 3", "increase"});
  // The deep check of panmap-loginfo and the processes refuses it the same way.
  const std::vector<uint8_t> bytes = encode(msg);
  const MessageCheck check = checkMessage(bytes.data(), bytes.size(), true);
  EXPECT_FALSE(check.ok);
  EXPECT_NE(check.error.find("increase"), std::string::npos) << check.error;
}

}  // namespace
}  // namespace panmap
