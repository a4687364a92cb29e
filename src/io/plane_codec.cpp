#include "panmap/io/plane_codec.h"

#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <type_traits>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"

namespace panmap {

namespace {

constexpr uint8_t kMagic[4] = {'P', 'M', 'Z', 'P'};
constexpr size_t kHeaderBytes = 16;
// Pixel types of the header's byte 4 (bytes 5-7 are 0, kept for later use).
constexpr uint8_t kDepthU16 = 1;
constexpr uint8_t kLabelI32 = 2;
// Labels that all fit in fewer bytes are coded in them: zstd then finds longer matches
// (geometric segment ids of a 7-Scenes frame: 20-25 % smaller in 8 bits than in 32).
constexpr uint8_t kLabelU8 = 3;
constexpr uint8_t kLabelU16 = 4;

void putLe32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}

uint32_t getLe32(const uint8_t* p) {
  return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}

bool littleEndianHost() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// Pixels in little-endian byte order, so a store written on one host decodes on any (on a
// little-endian host the pixels are coded in place, without these).
template <typename T>
void toLittleEndian(const T* pixels, size_t count, uint8_t* out) {
  for (size_t i = 0; i < count; ++i) {
    const auto bits = static_cast<std::make_unsigned_t<T>>(pixels[i]);
    for (size_t b = 0; b < sizeof(T); ++b)
      out[i * sizeof(T) + b] = static_cast<uint8_t>(bits >> (8 * b));
  }
}

template <typename T>
void fromLittleEndian(const uint8_t* in, size_t count, T* pixels) {
  for (size_t i = 0; i < count; ++i) {
    std::make_unsigned_t<T> bits = 0;
    for (size_t b = 0; b < sizeof(T); ++b) {
      bits |= static_cast<std::make_unsigned_t<T>>(in[i * sizeof(T) + b]) << (8 * b);
    }
    pixels[i] = static_cast<T>(bits);
  }
}

template <typename Image>
std::vector<uint8_t> encode(const Image& image, uint8_t type, int level) {
  using Pixel = typename Image::Pixel;
  if (level < 1 || level > ZSTD_maxCLevel()) {
    throw Error("plane codec: zstd level " + std::to_string(level) + " outside 1.." +
                std::to_string(ZSTD_maxCLevel()));
  }
  const size_t raw_bytes = image.size() * sizeof(Pixel);
  std::vector<uint8_t> swapped;
  const void* raw = image.data();
  if (!littleEndianHost()) {
    swapped.resize(raw_bytes);
    toLittleEndian(image.data(), image.size(), swapped.data());
    raw = swapped.data();
  }
  std::vector<uint8_t> out(kHeaderBytes + ZSTD_compressBound(raw_bytes));
  std::memcpy(out.data(), kMagic, 4);
  out[4] = type;
  putLe32(out.data() + 8, static_cast<uint32_t>(image.width()));
  putLe32(out.data() + 12, static_cast<uint32_t>(image.height()));
  // With zstd's content checksum a plane checks itself: a damaged file fails to decode
  // instead of giving other pixels, wherever it is read from.
  const std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> context(ZSTD_createCCtx(),
                                                                   ZSTD_freeCCtx);
  if (!context) throw Error("plane codec: out of memory");
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, level);
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_checksumFlag, 1);
  const size_t n = ZSTD_compress2(context.get(), out.data() + kHeaderBytes,
                                  out.size() - kHeaderBytes, raw, raw_bytes);
  if (ZSTD_isError(n)) throw Error(std::string("plane codec: zstd: ") + ZSTD_getErrorName(n));
  out.resize(kHeaderBytes + n);
  return out;
}

template <typename Image>
Image decode(const uint8_t* data, size_t size, uint8_t type, const char* kind,
             const std::string& what) {
  using Pixel = typename Image::Pixel;
  if (!isPlane(data, size)) throw Error(what + ": not a panmap plane file (magic PMZP)");
  if (size < kHeaderBytes) throw Error(what + ": cut inside the header");
  if (data[4] != type || data[5] != 0 || data[6] != 0 || data[7] != 0) {
    throw Error(what + ": not a " + kind + " plane (pixel type " + std::to_string(data[4]) + ")");
  }
  const uint64_t width = getLe32(data + 8), height = getLe32(data + 12);
  if (width == 0 || height == 0 || width * height > kMaxImagePixels) {
    throw Error(what + ": image size " + std::to_string(width) + "x" + std::to_string(height) +
                " outside 1.." + std::to_string(kMaxImagePixels) + " pixels");
  }
  const size_t raw_bytes = static_cast<size_t>(width * height) * sizeof(Pixel);
  const uint8_t* frame = data + kHeaderBytes;
  const size_t frame_bytes = size - kHeaderBytes;
  // The zstd frame must hold exactly one frame of exactly the pixels the header promises: a
  // cut file, trailing bytes and a header from another file all fail here.
  const size_t compressed = ZSTD_findFrameCompressedSize(frame, frame_bytes);
  if (ZSTD_isError(compressed) || compressed != frame_bytes) {
    throw Error(what + ": the zstd frame is cut or followed by other bytes");
  }
  const unsigned long long content = ZSTD_getFrameContentSize(frame, frame_bytes);
  if (content != raw_bytes) {
    throw Error(what + ": the zstd frame does not hold " + std::to_string(width) + "x" +
                std::to_string(height) + " " + kind + " pixels");
  }
  Image image(static_cast<int>(width), static_cast<int>(height));
  std::vector<uint8_t> swapped(littleEndianHost() ? 0 : raw_bytes);
  void* raw = littleEndianHost() ? static_cast<void*>(image.data()) : swapped.data();
  const size_t n = ZSTD_decompress(raw, raw_bytes, frame, frame_bytes);
  if (ZSTD_isError(n) || n != raw_bytes) {
    throw Error(what + ": corrupt zstd frame" +
                (ZSTD_isError(n) ? std::string(" (") + ZSTD_getErrorName(n) + ")" : ""));
  }
  if (!littleEndianHost()) fromLittleEndian(swapped.data(), image.size(), image.data());
  return image;
}

}  // namespace

std::vector<uint8_t> encodePlane(const DepthImage& image, int level) {
  return encode(image, kDepthU16, level);
}

std::vector<uint8_t> encodePlane(const LabelImage& image, int level) {
  int32_t lo = 0, hi = 0;
  for (size_t i = 0; i < image.size(); ++i) {
    lo = std::min(lo, image.data()[i]);
    hi = std::max(hi, image.data()[i]);
  }
  if (lo < 0 || hi > UINT16_MAX) return encode(image, kLabelI32, level);
  const auto narrowed = [&image](auto pixel) {
    Image<decltype(pixel)> out(image.width(), image.height());
    for (size_t i = 0; i < image.size(); ++i) {
      out.data()[i] = static_cast<decltype(pixel)>(image.data()[i]);
    }
    return out;
  };
  if (hi <= UINT8_MAX) return encode(narrowed(uint8_t{}), kLabelU8, level);
  return encode(narrowed(uint16_t{}), kLabelU16, level);
}

bool isPlane(const uint8_t* data, size_t size) {
  return size >= 4 && std::memcmp(data, kMagic, 4) == 0;
}

DepthImage decodeDepthPlane(const uint8_t* data, size_t size, const std::string& what) {
  return decode<DepthImage>(data, size, kDepthU16, "depth", what);
}

LabelImage decodeLabelPlane(const uint8_t* data, size_t size, const std::string& what) {
  const uint8_t type = isPlane(data, size) && size > 4 ? data[4] : kLabelI32;
  if (type != kLabelU8 && type != kLabelU16) {
    return decode<LabelImage>(data, size, kLabelI32, "label", what);
  }
  const auto widened = [](const auto& narrow) {
    LabelImage out(narrow.width(), narrow.height());
    for (size_t i = 0; i < narrow.size(); ++i) out.data()[i] = narrow.data()[i];
    return out;
  };
  if (type == kLabelU8) return widened(decode<Image<uint8_t>>(data, size, type, "label", what));
  return widened(decode<Image<uint16_t>>(data, size, type, "label", what));
}

}  // namespace panmap
