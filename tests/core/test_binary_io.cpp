#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/binary_io.h"
#include "panmap/core/error.h"

namespace panmap {
namespace {

// Hands out a byte vector in order and counts what it was asked for.
class VectorSource : public ByteSource {
 public:
  explicit VectorSource(std::vector<uint8_t> bytes) : bytes_(std::move(bytes)) {}
  void read(uint8_t* out, size_t size) override {
    if (size > bytes_.size() - pos_) throw Error("source: short read");
    std::memcpy(out, bytes_.data() + pos_, size);
    pos_ += size;
    ++calls_;
  }
  size_t pos() const { return pos_; }
  size_t calls() const { return calls_; }

 private:
  std::vector<uint8_t> bytes_;
  size_t pos_ = 0;
  size_t calls_ = 0;
};

std::vector<uint8_t> sample() {
  BinaryWriter w;
  w.put<uint8_t>(7);
  w.put<int32_t>(-123456);
  w.put<double>(2.5);
  w.putString("a string longer than the window");
  w.put<uint64_t>(3);  // a count of 3 items of 8 bytes
  for (uint64_t i = 0; i < 3; ++i) w.put<uint64_t>(1000 + i);
  std::vector<uint8_t> big(100);
  std::iota(big.begin(), big.end(), uint8_t{0});
  w.putBytes(big.data(), big.size());
  w.put<uint16_t>(0xBEEF);
  return w.bytes();
}

// Reads sample()'s values back; the same code for both kinds of reader.
void readSample(BinaryReader* r) {
  EXPECT_EQ(r->get<uint8_t>(), 7);
  EXPECT_EQ(r->get<int32_t>(), -123456);
  EXPECT_EQ(r->get<double>(), 2.5);
  EXPECT_EQ(r->getString(), "a string longer than the window");
  const uint64_t n = r->getCount(8);
  ASSERT_EQ(n, 3u);
  for (uint64_t i = 0; i < n; ++i) EXPECT_EQ(r->get<uint64_t>(), 1000 + i);
  std::vector<uint8_t> big(100);
  r->getBytes(big.data(), big.size());
  for (size_t i = 0; i < big.size(); ++i) EXPECT_EQ(big[i], i);
  EXPECT_EQ(r->get<uint16_t>(), 0xBEEF);
  EXPECT_EQ(r->remaining(), 0u);
}

std::string errorOf(BinaryReader* r, size_t size) {
  std::vector<uint8_t> out(size);
  try {
    r->getBytes(out.data(), size);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(BinaryReader, StreamedReadsGiveWhatMemoryReadsGiveAcrossWindowEdges) {
  const std::vector<uint8_t> bytes = sample();
  BinaryReader in_memory(bytes.data(), bytes.size(), "m");
  readSample(&in_memory);
  for (size_t window : {1, 3, 7, 16, 64, 4096}) {
    SCOPED_TRACE("window " + std::to_string(window));
    VectorSource source(bytes);
    BinaryReader streamed(&source, bytes.size(), "m", 0, window);
    readSample(&streamed);
    EXPECT_EQ(source.pos(), bytes.size());  // read exactly once, to the end
  }
}

TEST(BinaryReader, LargeReadsBypassTheWindow) {
  const std::vector<uint8_t> bytes = sample();
  VectorSource source(bytes);
  BinaryReader r(&source, bytes.size(), "m", 0, 8);
  std::vector<uint8_t> all(bytes.size());
  r.getBytes(all.data(), all.size());
  EXPECT_EQ(all, bytes);
  EXPECT_EQ(source.calls(), 1u);  // one read straight into the caller's buffer
}

TEST(BinaryReader, StreamedErrorsNameTheSameOffsetsAsMemoryErrors) {
  const std::vector<uint8_t> bytes = sample();
  BinaryReader in_memory(bytes.data(), bytes.size(), "f.bin", 20);
  VectorSource source(bytes);
  BinaryReader streamed(&source, bytes.size(), "f.bin", 20, 5);
  in_memory.getBytes(std::vector<uint8_t>(10).data(), 10);
  streamed.getBytes(std::vector<uint8_t>(10).data(), 10);
  const std::string expected =
      "f.bin: truncated (needs " + std::to_string(bytes.size()) + " more bytes at offset 30)";
  EXPECT_EQ(errorOf(&in_memory, bytes.size()), expected);
  EXPECT_EQ(errorOf(&streamed, bytes.size()), expected);
  // A failed read consumes nothing.
  EXPECT_EQ(streamed.remaining(), bytes.size() - 10);

  // A count the rest cannot hold is refused before anything is allocated.
  BinaryWriter w;
  w.put<uint64_t>(1000);
  w.put<uint64_t>(0);
  VectorSource count_source(w.bytes());
  BinaryReader counts(&count_source, w.bytes().size(), "c", 0, 4);
  try {
    counts.getCount(8);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "c: corrupt count 1000 at offset 0");
  }
}

TEST(BinaryReader, SkipRestReadsTheSourceToItsEnd) {
  const std::vector<uint8_t> bytes = sample();
  VectorSource source(bytes);
  BinaryReader r(&source, bytes.size(), "m", 0, 16);
  EXPECT_EQ(r.get<uint8_t>(), 7);
  r.skipRest();
  EXPECT_EQ(r.remaining(), 0u);
  EXPECT_EQ(source.pos(), bytes.size());
  EXPECT_FALSE(errorOf(&r, 1).empty());
}

}  // namespace
}  // namespace panmap
