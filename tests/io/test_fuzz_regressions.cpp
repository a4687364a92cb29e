// Inputs on which fuzz/fuzz_image_codec once failed (tests/fixtures/fuzz_regressions/), and the
// same fault built by hand for PNG: each must end in a clean Error.
#include <zlib.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/io/image_codec.h"
#include "test_helpers.h"

namespace panmap {
namespace {

std::vector<uint8_t> fuzzInput(const std::string& fixture) {
  const std::string s = test::fileBytes(test::fixtureDir("fuzz_regressions/" + fixture));
  EXPECT_FALSE(s.empty()) << fixture;
  return std::vector<uint8_t>(s.begin(), s.end());
}

TEST(ImageFuzzRegressions, JpegClaimingHugeSizeIsRefusedBeforeDecoding) {
  // 244 bytes whose frame header says 12040 x 14895: the decoder allocated and filled 180 M
  // pixels (1.8 GB, over 10 s under the sanitisers) before finding the data short.
  const std::vector<uint8_t> jpeg = fuzzInput("image_codec/jpeg_claims_179m_pixels");
  ASSERT_TRUE(isCompleteJpeg(jpeg.data(), jpeg.size()));
  test::expectError([&] { decodeColor(jpeg.data(), jpeg.size(), "f.jpg"); },
                    {"f.jpg", "12040x14895", "larger than"});
}

TEST(ImageFuzzRegressions, StuffedZeroBeforeTheFrameHeaderDoesNotHideItsSize) {
  // 178 bytes opening FF D8 FF 00: libjpeg skips FF 00 as a stuffed zero and found the same
  // 12040 x 14895 frame header, which the size check had read past as a segment length.
  const std::vector<uint8_t> jpeg = fuzzInput("image_codec/jpeg_stuffed_zero_hides_179m_pixels");
  ASSERT_TRUE(isCompleteJpeg(jpeg.data(), jpeg.size()));
  test::expectError([&] { decodeColor(jpeg.data(), jpeg.size(), "f.jpg"); },
                    {"f.jpg", "12040x14895", "larger than"});
}

TEST(ImageFuzzRegressions, PngClaimingHugeSizeIsRefusedBeforeDecoding) {
  // A real 8x6 depth PNG with its IHDR rewritten to 60000 x 60000: as found, the chunk's
  // checksum refuses it; with the checksum made right, the size does.
  std::vector<uint8_t> png = encodeDepthPng(DepthImage(8, 6, 1000));
  for (size_t at : {16, 20}) {
    png[at] = 0x00, png[at + 1] = 0x00, png[at + 2] = 0xEA, png[at + 3] = 0x60;
  }
  test::expectError([&] { decodeDepthPng(png.data(), png.size(), "d.png"); },
                    {"d.png", "corrupt PNG", "IHDR"});
  const uLong crc = crc32(0L, png.data() + 12, 17);
  for (int i = 0; i < 4; ++i) png[29 + i] = static_cast<uint8_t>(crc >> (24 - 8 * i));
  test::expectError([&] { decodeDepthPng(png.data(), png.size(), "d.png"); },
                    {"d.png", "60000x60000", "larger than"});
  test::expectError([&] { decodeLabelPng(png.data(), png.size(), "l.png"); }, {"l.png"});
  test::expectError([&] { decodeColor(png.data(), png.size(), "c.png"); }, {"c.png"});
}

TEST(ImageFuzzRegressions, BytesThatOnlyLookLikeAJpegNeverReachAnotherDecoder) {
  // SOI, then no marker: OpenCV's JPEG decoder does not claim these bytes, and cv::imdecode
  // offered them to its other decoders; under the fuzzer GDAL took some through a temporary
  // file left in /tmp. They are refused before imdecode now.
  const std::vector<uint8_t> bytes = {0xFF, 0xD8, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xFF, 0xD9};
  EXPECT_FALSE(isCompleteJpeg(bytes.data(), bytes.size()));
  test::expectError([&] { decodeColor(bytes.data(), bytes.size(), "c.jpg"); },
                    {"c.jpg", "not a JPEG/PNG"});
}

TEST(ImageFuzzRegressions, ImagesUpToTheLimitStillDecode) {
  const DepthImage depth(640, 480, 1234);
  const std::vector<uint8_t> png = encodeDepthPng(depth);
  const DepthImage back = decodeDepthPng(png.data(), png.size(), "d.png");
  EXPECT_EQ(back.width(), 640);
  EXPECT_EQ(back(5, 7), 1234);
  const std::vector<uint8_t> jpeg = encodeJpeg(ColorImage(64, 48, Rgb8{10, 20, 30}));
  EXPECT_EQ(decodeColor(jpeg.data(), jpeg.size(), "c.jpg").height(), 48);
}

}  // namespace
}  // namespace panmap
