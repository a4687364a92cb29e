// The frame store's lossless zstd planes: exact round trips, the byte layout, and a clear error
// for every way the bytes can be wrong.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/plane_codec.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::expectError;

DepthImage someDepth() {
  DepthImage d(7, 5);
  for (int v = 0; v < 5; ++v) {
    for (int u = 0; u < 7; ++u) d(u, v) = static_cast<uint16_t>(u * 9000 + v * 13);
  }
  d(6, 4) = 65535;
  d(0, 0) = 0;
  return d;
}

LabelImage someLabels() {
  LabelImage l(5, 3, 42);
  l(0, 0) = 0;
  l(1, 0) = std::numeric_limits<int32_t>::max();
  l(2, 0) = std::numeric_limits<int32_t>::min();
  l(3, 0) = -1;
  l(4, 2) = (1 << 24) + 5;
  return l;
}

TEST(PlaneCodec, RoundTripsAreExactAtEveryLevel) {
  for (int level : {1, kDefaultPlaneLevel, 19}) {
    const auto d = encodePlane(someDepth(), level);
    EXPECT_EQ(decodeDepthPlane(d.data(), d.size(), "t"), someDepth());
    const auto l = encodePlane(someLabels(), level);
    EXPECT_EQ(decodeLabelPlane(l.data(), l.size(), "t"), someLabels());
  }
}

TEST(PlaneCodec, HeaderIsMagicTypeAndLittleEndianSize) {
  const auto bytes = encodePlane(someLabels());
  ASSERT_GE(bytes.size(), 16u);
  EXPECT_EQ(std::vector<uint8_t>(bytes.begin(), bytes.begin() + 16),
            (std::vector<uint8_t>{'P', 'M', 'Z', 'P', 2, 0, 0, 0, 5, 0, 0, 0, 3, 0, 0, 0}));
  EXPECT_TRUE(isPlane(bytes.data(), bytes.size()));
  // zstd's own frame magic follows the header.
  EXPECT_EQ(std::vector<uint8_t>(bytes.begin() + 16, bytes.begin() + 20),
            (std::vector<uint8_t>{0x28, 0xB5, 0x2F, 0xFD}));
  const auto depth = encodePlane(someDepth());
  EXPECT_EQ(depth[4], 1);
}

TEST(PlaneCodec, LargeUniformImagesShrink) {
  const auto bytes = encodePlane(LabelImage(640, 480, 7));
  EXPECT_LT(bytes.size(), 1000u);  // 1.2 MB of one value
  EXPECT_EQ(decodeLabelPlane(bytes.data(), bytes.size(), "t"), LabelImage(640, 480, 7));
}

// Labels that all fit in 8 or 16 bits are coded in them (pixel types 3 and 4): smaller files,
// the same labels back.
TEST(PlaneCodec, LabelsAreCodedInTheFewestBytesThatHoldThem) {
  LabelImage segments(640, 480);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) segments(u, v) = (u / 37 + 7 * (v / 29)) % 256;
  }
  LabelImage wide = segments;
  wide(3, 3) = 65535;
  LabelImage widest = segments;
  widest(3, 3) = 65536;
  LabelImage negative = segments;
  negative(3, 3) = -2;
  std::vector<size_t> sizes;
  for (const auto& [image, type] : {std::make_pair(segments, 3), std::make_pair(wide, 4),
                                    std::make_pair(widest, 2), std::make_pair(negative, 2)}) {
    const auto bytes = encodePlane(image);
    ASSERT_GT(bytes.size(), 16u);
    EXPECT_EQ(bytes[4], type);
    EXPECT_EQ(decodeLabelPlane(bytes.data(), bytes.size(), "t"), image);
    sizes.push_back(bytes.size());
    // Narrow planes are still not depth planes, and every cut is named.
    expectError([&] { decodeDepthPlane(bytes.data(), bytes.size(), "f"); }, {"f", "not a depth"});
    for (size_t n : {size_t{0}, size_t{4}, size_t{15}, bytes.size() / 2, bytes.size() - 1}) {
      expectError([&] { decodeLabelPlane(bytes.data(), n, "f.labels.zst"); }, {"f.labels.zst"});
    }
  }
  EXPECT_LT(sizes[0], sizes[2]);
  EXPECT_LT(sizes[1], sizes[2]);
}

TEST(PlaneCodec, BadBytesGetAnErrorNamingTheFile) {
  const auto good = encodePlane(someDepth());
  // Every cut, from an empty file to one byte short.
  for (size_t n = 0; n < good.size(); ++n) {
    expectError([&] { decodeDepthPlane(good.data(), n, "f.depth.zst"); }, {"f.depth.zst"});
  }
  std::vector<uint8_t> trailing = good;
  trailing.push_back(0);
  expectError([&] { decodeDepthPlane(trailing.data(), trailing.size(), "f"); },
              {"f", "cut or followed"});
  // A label plane is not a depth plane, nor the reverse.
  const auto labels = encodePlane(someLabels());
  expectError([&] { decodeDepthPlane(labels.data(), labels.size(), "f"); }, {"f", "not a depth"});
  expectError([&] { decodeLabelPlane(good.data(), good.size(), "f"); }, {"f", "not a label"});
  // A header whose size disagrees with the pixels.
  std::vector<uint8_t> wider = good;
  wider[8] = 8;
  expectError([&] { decodeDepthPlane(wider.data(), wider.size(), "f"); },
              {"f", "does not hold 8x5 depth pixels"});
  std::vector<uint8_t> huge = good;
  huge[11] = 0x7f;
  expectError([&] { decodeDepthPlane(huge.data(), huge.size(), "f"); }, {"f", "image size"});
  std::vector<uint8_t> empty = good;
  empty[8] = 0;
  expectError([&] { decodeDepthPlane(empty.data(), empty.size(), "f"); }, {"f", "image size"});
  // A PNG is not a plane.
  const auto png = encodeDepthPng(someDepth());
  expectError([&] { decodeDepthPlane(png.data(), png.size(), "f"); }, {"f", "PMZP"});
  // A damaged byte anywhere in the zstd frame fails the decoding (the frame carries a checksum
  // of the pixels): never other pixels, never a crash.
  for (size_t i = 16; i < good.size(); ++i) {
    std::vector<uint8_t> flipped = good;
    flipped[i] ^= 0x5a;
    expectError([&] { decodeDepthPlane(flipped.data(), flipped.size(), "f"); }, {"f"});
  }
  expectError([&] { encodePlane(someDepth(), 0); }, {"level"});
  expectError([&] { encodePlane(someDepth(), 23); }, {"level"});
}

}  // namespace
}  // namespace panmap
