#include <zlib.h>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"

namespace panmap {
namespace {

TEST(ImageCodec, DepthPngRoundTripIsExact) {
  DepthImage depth(7, 5);
  for (int v = 0; v < 5; ++v) {
    for (int u = 0; u < 7; ++u) depth(u, v) = static_cast<uint16_t>(u * 9000 + v * 13);
  }
  depth(6, 4) = 65535;
  const auto png = encodeDepthPng(depth);
  EXPECT_EQ(decodeDepthPng(png.data(), png.size(), "t"), depth);
}

TEST(ImageCodec, LabelPngUsesCocoEncoding) {
  LabelImage labels(3, 2, 0);
  labels(0, 0) = 1;
  labels(1, 0) = 300;  // R 44, G 1
  labels(2, 1) = 2 * 65536 + 3 * 256 + 4;
  const auto png = encodeLabelPng(labels);
  EXPECT_EQ(decodeLabelPng(png.data(), png.size(), "t"), labels);
  LabelImage too_big(1, 1, 1 << 24);
  EXPECT_THROW(encodeLabelPng(too_big), Error);
}

TEST(ImageCodec, ColorRoundTrip) {
  ColorImage color(16, 8);
  for (int v = 0; v < 8; ++v) {
    for (int u = 0; u < 16; ++u)
      color(u, v) = Rgb8{static_cast<uint8_t>(u * 16), static_cast<uint8_t>(v * 32), 77};
  }
  const auto png = encodePng(color);
  EXPECT_EQ(decodeColor(png.data(), png.size(), "t"), color);  // lossless
  const auto jpeg = encodeJpeg(color, 95);
  const ColorImage back = decodeColor(jpeg.data(), jpeg.size(), "t");
  ASSERT_EQ(back.width(), 16);
  int max_error = 0;
  for (size_t i = 0; i < back.size(); ++i) {
    max_error = std::max(max_error, std::abs(back.data()[i].r - color.data()[i].r));
  }
  EXPECT_LT(max_error, 20);  // lossy but close; channel order preserved (R stays R)
}

TEST(ImageCodec, TruncatedJpegIsRefused) {
  ColorImage color(64, 48, Rgb8{10, 200, 30});
  auto jpeg = encodeJpeg(color);
  ASSERT_TRUE(isCompleteJpeg(jpeg.data(), jpeg.size()));
  jpeg.resize(jpeg.size() / 2);
  EXPECT_FALSE(isCompleteJpeg(jpeg.data(), jpeg.size()));
  try {
    decodeColor(jpeg.data(), jpeg.size(), "frame.jpg");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame.jpg: truncated"), std::string::npos) << e.what();
  }
}

TEST(ImageCodec, EightBitPngIsNotDepth) {
  ColorImage color(4, 4);
  const auto png = encodePng(color);
  EXPECT_THROW(decodeDepthPng(png.data(), png.size(), "d.png"), Error);
  const std::vector<uint8_t> garbage = {1, 2, 3};
  EXPECT_THROW(decodeDepthPng(garbage.data(), garbage.size(), "d.png"), Error);
  EXPECT_THROW(decodeColor(garbage.data(), 0, "c.jpg"), Error);
}

}  // namespace
}  // namespace panmap

namespace panmap {
namespace {

std::string decodeError(const std::vector<uint8_t>& bytes) {
  try {
    decodeDepthPng(bytes.data(), bytes.size(), "d.png");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ImageCodec, BrokenPngChunksAreNamedWithTheirOffset) {
  DepthImage depth(16, 8, 1234);
  const std::vector<uint8_t> good = encodeDepthPng(depth);
  ASSERT_EQ(decodeError(good), "");

  std::vector<uint8_t> cut(good.begin(), good.end() - 20);  // IDAT or IEND cut short
  EXPECT_NE(decodeError(cut).find("d.png: truncated PNG"), std::string::npos) << decodeError(cut);

  std::vector<uint8_t> flipped = good;
  flipped[8 + 8 + 2] ^= 0x01;  // a byte of IHDR's data: its CRC no longer matches
  EXPECT_EQ(decodeError(flipped), "d.png: corrupt PNG (checksum of chunk IHDR at offset 8)");

  // IHDR claiming 30000 x 30000 pixels, with a correct CRC: refused before any allocation.
  std::vector<uint8_t> huge = good;
  const uint32_t side = 30000;
  for (int i = 0; i < 4; ++i) {
    huge[16 + i] = huge[20 + i] = static_cast<uint8_t>(side >> (24 - 8 * i));
  }
  const uLong crc = crc32(0L, huge.data() + 12, 17);
  for (int i = 0; i < 4; ++i) huge[29 + i] = static_cast<uint8_t>(crc >> (24 - 8 * i));
  EXPECT_EQ(decodeError(huge),
            "d.png: image of 30000x30000 pixels is larger than the 33554432 pixels panmap reads");
}

}  // namespace
}  // namespace panmap
