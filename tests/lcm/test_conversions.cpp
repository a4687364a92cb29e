#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "panmap/command_t.hpp"
#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/message_types.h"

namespace panmap {
namespace {

RgbdFrame makeFrame() {
  RgbdFrame f;
  f.utime = 1234567;
  f.frame_id = 42;
  f.camera_name = "test";
  f.camera = PinholeCamera{50.0, 51.0, 15.5, 11.5, 32, 24};
  f.depth_scale_m = 0.001;
  f.depth = DepthImage(32, 24);
  f.color = ColorImage(32, 24);
  for (int v = 0; v < 24; ++v) {
    for (int u = 0; u < 32; ++u) {
      f.depth(u, v) = static_cast<uint16_t>(500 + 40 * u + v);
      f.color(u, v) = Rgb8{static_cast<uint8_t>(8 * u), static_cast<uint8_t>(10 * v), 128};
    }
  }
  return f;
}

template <typename Msg>
std::vector<uint8_t> encode(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  return bytes;
}

template <typename Msg>
Msg decode(const std::vector<uint8_t>& bytes) {
  Msg msg;
  EXPECT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  return msg;
}

TEST(Conversions, RgbdRoundTripRawAndPngIsExact) {
  const RgbdFrame f = makeFrame();
  ImageEncoding raw;
  raw.color = raw.depth = image_t::COMPRESSION_NONE;
  ImageEncoding png;
  png.color = image_t::COMPRESSION_PNG;
  for (const ImageEncoding& enc : {raw, png}) {
    const RgbdFrame back = fromMessage(decode<rgbd_frame_t>(encode(toMessage(f, enc))));
    EXPECT_EQ(back.utime, f.utime);
    EXPECT_EQ(back.frame_id, 42);
    EXPECT_EQ(back.camera_name, "test");
    EXPECT_DOUBLE_EQ(back.camera.fy, 51.0);
    EXPECT_EQ(back.camera.width, 32);
    EXPECT_EQ(back.depth, f.depth);
    EXPECT_EQ(back.color, f.color);
  }
}

TEST(Conversions, AFrameWithoutColourRoundTripsWithEveryEncoding) {
  RgbdFrame f = makeFrame();
  f.color = ColorImage();
  ImageEncoding raw;
  raw.color = raw.depth = image_t::COMPRESSION_NONE;
  ImageEncoding png;
  png.color = image_t::COMPRESSION_PNG;
  for (const ImageEncoding& enc : {raw, png, ImageEncoding{}}) {  // the last: JPEG colour
    const rgbd_frame_t msg = toMessage(f, enc);
    EXPECT_EQ(msg.color.width, 0);
    EXPECT_EQ(msg.color.size, 0);
    const RgbdFrame back = fromMessage(decode<rgbd_frame_t>(encode(msg)));
    EXPECT_TRUE(back.color.empty());
    EXPECT_EQ(back.depth, f.depth);
  }
}

TEST(Conversions, JpegBytesTravelUnchanged) {
  const RgbdFrame f = makeFrame();
  const std::vector<uint8_t> jpeg = encodeJpeg(f.color, 70);
  const rgbd_frame_t msg = toMessage(f, ImageEncoding{}, &jpeg);
  EXPECT_EQ(msg.color.compression, +image_t::COMPRESSION_JPEG);
  EXPECT_EQ(msg.color.data, jpeg);
  EXPECT_EQ(msg.depth.compression, +image_t::COMPRESSION_PNG);
}

TEST(Conversions, BadFramesAreRefusedWithAReason) {
  const RgbdFrame f = makeFrame();
  rgbd_frame_t msg = toMessage(f, ImageEncoding{});
  rgbd_frame_t wrong_size = msg;
  wrong_size.depth.width = 64;  // header disagrees with the PNG
  EXPECT_THROW(fromMessage(wrong_size), Error);
  rgbd_frame_t bad_fx = msg;
  bad_fx.fx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fromMessage(bad_fx), Error);
  rgbd_frame_t truncated = msg;
  truncated.color.data.resize(truncated.color.data.size() / 2);
  truncated.color.size = static_cast<int32_t>(truncated.color.data.size());
  EXPECT_THROW(fromMessage(truncated), Error);
  RgbdFrame small_colour = f;
  small_colour.color = ColorImage(16, 12);
  try {
    fromMessage(toMessage(small_colour, ImageEncoding{}));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not registered"), std::string::npos) << e.what();
  }
}

TEST(Conversions, PoseRoundTripAndNan) {
  StampedPose p;
  p.utime = 99;
  p.frame_id = 3;
  p.source = PoseSource::kSlam;
  p.T_W_C.linear() =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -1, 0.5).normalized()).toRotationMatrix();
  p.T_W_C.translation() << 1.5, -2.25, 0.125;
  const StampedPose back = fromMessage(decode<pose_t>(encode(toMessage(p))));
  EXPECT_EQ(back.utime, 99);
  EXPECT_EQ(back.frame_id, 3);
  EXPECT_EQ(back.source, PoseSource::kSlam);
  EXPECT_LT((back.T_W_C.matrix() - p.T_W_C.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  pose_t nan = toMessage(p);
  nan.position[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fromMessage(nan), Error);
  pose_t scaled = toMessage(p);
  scaled.orientation[0] *= 2.0;
  EXPECT_THROW(fromMessage(scaled), Error);
}

TEST(Conversions, PanopticRoundTrip) {
  PanopticFrame f;
  f.utime = 5;
  f.frame_id = 6;
  f.segment_ids = LabelImage(4, 3, 0);
  f.segment_ids(1, 1) = 70000;
  f.segment_ids(3, 2) = 2;
  f.segments = {{70000, 5, 62, true, 0.75f}, {2, 1, 1, false, 1.0f}};
  for (int8_t c : {image_t::COMPRESSION_NONE, image_t::COMPRESSION_PNG}) {
    ImageEncoding enc;
    enc.labels = c;
    const PanopticFrame back = fromMessage(decode<panoptic_t>(encode(toMessage(f, enc))));
    EXPECT_EQ(back.segment_ids, f.segment_ids);
    EXPECT_EQ(back.segments, f.segments);
    EXPECT_EQ(back.frame_id, 6);
  }
  panoptic_t dup = toMessage(f, ImageEncoding{});
  dup.segments[1].id = 70000;
  EXPECT_THROW(fromMessage(dup), Error);
}

TEST(MessageTypes, IdentifiesAndChecks) {
  const auto bytes = encode(toMessage(makeFrame(), ImageEncoding{}));
  MessageCheck ok = checkMessage(bytes.data(), bytes.size(), true);
  EXPECT_TRUE(ok.ok) << ok.error;
  EXPECT_EQ(ok.type, "rgbd_frame_t");
  EXPECT_EQ(ok.utime, 1234567);

  MessageCheck cut = checkMessage(bytes.data(), bytes.size() - 100, true);
  EXPECT_FALSE(cut.ok);
  EXPECT_EQ(cut.type, "rgbd_frame_t");
  EXPECT_NE(cut.error.find("does not decode"), std::string::npos);

  std::vector<uint8_t> garbage = bytes;
  garbage[0] ^= 0xFF;
  EXPECT_EQ(checkMessage(garbage.data(), garbage.size(), true).type, "");
  EXPECT_FALSE(checkMessage(bytes.data(), 4, false).ok);

  command_t cmd;
  cmd.utime = 7;
  cmd.command = command_t::COMMAND_SAVE;
  cmd.argument = "/tmp/map.panmap";
  const auto cmd_bytes = encode(cmd);
  EXPECT_TRUE(checkMessage(cmd_bytes.data(), cmd_bytes.size(), true).ok);
  EXPECT_EQ(messageTypeNames().size(), 10u);
}

}  // namespace
}  // namespace panmap
