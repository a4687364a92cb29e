#include "panmap/io/image_codec.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <zlib.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "panmap/core/error.h"
#include "panmap/io/opencv_image.h"

namespace panmap {

std::vector<uint8_t> readFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read " + path);
  // A regular file is read in one call of its size: a byte-wise copy through stream iterators
  // (the vector regrowing) was most of the time of loading a map file under the fuzzer.
  std::error_code ec;
  const auto size = std::filesystem::is_regular_file(path, ec)
                        ? std::filesystem::file_size(path, ec)
                        : static_cast<std::uintmax_t>(-1);
  if (!ec && size != static_cast<std::uintmax_t>(-1)) {
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    if (!bytes.empty() &&
        !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size))) {
      throw Error("cannot read " + path);
    }
    return bytes;
  }
  // Anything else (a pipe, a device): read to the end.
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  if (in.bad()) throw Error("cannot read " + path);
  return bytes;
}

void writeFileBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  out.close();  // the last bytes reach the disk here: a full disk shows now, not never
  if (!out) throw Error("cannot write " + path);
}

std::vector<uint8_t> encodeJpeg(const ColorImage& image, int quality) {
  cv::Mat bgr;
  cv::cvtColor(asMat(image), bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> bytes;
  if (!cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality})) {
    throw Error("JPEG encoding failed");
  }
  return bytes;
}

std::vector<uint8_t> encodePng(const ColorImage& image) {
  cv::Mat bgr;
  cv::cvtColor(asMat(image), bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> bytes;
  if (!cv::imencode(".png", bgr, bytes, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    throw Error("PNG encoding failed");
  }
  return bytes;
}

std::vector<uint8_t> encodeDepthPng(const DepthImage& image, int compression) {
  if (compression < 0 || compression > 9) throw Error("PNG compression level outside 0..9");
  std::vector<uint8_t> bytes;
  if (!cv::imencode(".png", asMat(image), bytes, {cv::IMWRITE_PNG_COMPRESSION, compression})) {
    throw Error("depth PNG encoding failed");
  }
  return bytes;
}

std::vector<uint8_t> encodeLabelPng(const LabelImage& image, int compression) {
  if (compression < 0 || compression > 9) throw Error("PNG compression level outside 0..9");
  cv::Mat bgr(image.height(), image.width(), CV_8UC3);
  for (int v = 0; v < image.height(); ++v) {
    const int32_t* src = image.row(v);
    auto* dst = bgr.ptr<cv::Vec3b>(v);
    for (int u = 0; u < image.width(); ++u) {
      const int32_t id = src[u];
      if (id < 0 || id >= (1 << 24))
        throw Error("label " + std::to_string(id) + " outside [0, 2^24)");
      dst[u] = cv::Vec3b(static_cast<uint8_t>(id >> 16), static_cast<uint8_t>((id >> 8) & 255),
                         static_cast<uint8_t>(id & 255));
    }
  }
  std::vector<uint8_t> bytes;
  if (!cv::imencode(".png", bgr, bytes, {cv::IMWRITE_PNG_COMPRESSION, compression})) {
    throw Error("label PNG encoding failed");
  }
  return bytes;
}

bool isCompleteJpeg(const uint8_t* data, size_t size) {
  // SOI and the next marker's 0xFF: exactly what OpenCV's JPEG decoder matches. Bytes starting
  // FF D8 without it went to whichever other decoder claimed them (GDAL, through a temporary
  // file left in /tmp), found by fuzz/fuzz_image_codec.
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8 || data[2] != 0xFF) return false;
  // EOI ends the stream; some writers pad a few bytes after it.
  const size_t tail = size > 64 ? size - 64 : 2;
  for (size_t i = size - 2; i + 1 > tail; --i) {
    if (data[i] == 0xFF && data[i + 1] == 0xD9) return true;
  }
  return false;
}

bool isPng(const uint8_t* data, size_t size) {
  static const uint8_t kMagic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  return size >= 8 && std::equal(kMagic, kMagic + 8, data);
}

namespace {

uint32_t bigEndian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

// Walks a PNG's chunks (length, type, data, CRC) up to IEND, so that truncated or corrupted
// files get a message naming the offset instead of reaching libpng (which prints its own
// warnings).
void checkPngStructure(const uint8_t* data, size_t size, const std::string& what) {
  size_t pos = 8;
  bool first = true;
  while (true) {
    if (size - pos < 12) {
      throw Error(what + ": truncated PNG (chunk header cut at offset " + std::to_string(pos) +
                  " of " + std::to_string(size) + " bytes)");
    }
    const uint32_t length = bigEndian32(data + pos);
    const uint8_t* type = data + pos + 4;
    const std::string type_name(reinterpret_cast<const char*>(type), 4);
    if (length > size - pos - 12) {
      throw Error(what + ": truncated PNG (chunk " + type_name + " at offset " +
                  std::to_string(pos) + " runs past the end)");
    }
    const uLong crc = crc32(0L, type, static_cast<uInt>(length + 4));
    if (crc != bigEndian32(data + pos + 8 + length)) {
      throw Error(what + ": corrupt PNG (checksum of chunk " + type_name + " at offset " +
                  std::to_string(pos) + ")");
    }
    if (first && (type_name != "IHDR" || length != 13)) {
      throw Error(what + ": corrupt PNG (no IHDR chunk first)");
    }
    first = false;
    pos += 12 + length;
    if (type_name == "IEND") return;
  }
}

// Width and height from a PNG's IHDR or a JPEG's SOF marker; false when the header does not
// say (the decoder then refuses the file itself).
bool headerSize(const uint8_t* data, size_t size, uint64_t* width, uint64_t* height) {
  const auto be16 = [data](size_t at) { return (uint32_t{data[at]} << 8) | data[at + 1]; };
  if (isPng(data, size)) {
    if (size < 24 || std::memcmp(data + 12, "IHDR", 4) != 0) return false;
    *width = bigEndian32(data + 16);
    *height = bigEndian32(data + 20);
    return true;
  }
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8) return false;
  size_t pos = 2;
  while (pos + 4 <= size) {
    // Like libjpeg, skip stray bytes up to the next marker (segment lengths may be wrong).
    if (data[pos] != 0xFF) {
      ++pos;
      continue;
    }
    const uint8_t marker = data[pos + 1];
    if (marker == 0xFF) {  // fill byte
      ++pos;
      continue;
    }
    // FF 00 is a stuffed zero, which libjpeg skips like stray bytes (reading a length there
    // let a frame header hide from this check, found by fuzz/fuzz_image_codec); TEM and RSTn
    // have no length field.
    if (marker == 0x00 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {
      pos += 2;
      continue;
    }
    const bool sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (pos + 9 > size) return false;
      *height = be16(pos + 5);
      *width = be16(pos + 7);
      return true;
    }
    if (marker == 0xDA) return false;  // scan data before any frame header
    pos += 2 + be16(pos + 2);
  }
  return false;
}

cv::Mat decodeUnchanged(const uint8_t* data, size_t size, const std::string& what) {
  if (size == 0) throw Error(what + ": empty image data");
  // Only PNG and JPEG signatures reach cv::imdecode, so it never picks another of its decoders.
  if (isPng(data, size)) {
    checkPngStructure(data, size, what);
  } else if (!isCompleteJpeg(data, size)) {
    throw Error(what + ": not a PNG or a complete JPEG image");
  }
  // The decoders allocate the whole image from the header's size before reading any pixel:
  // a 100-byte file claiming 30000 x 30000 pixels took 1.8 GB and 10 s in fuzz/
  // fuzz_image_codec. No RGB-D camera comes near the limit (8K UHD is 33.2 M pixels).
  uint64_t width = 0, height = 0;
  if (headerSize(data, size, &width, &height) && width * height > kMaxImagePixels) {
    throw Error(what + ": image of " + std::to_string(width) + "x" + std::to_string(height) +
                " pixels is larger than the " + std::to_string(kMaxImagePixels) +
                " pixels panmap reads");
  }
  const cv::Mat buffer(1, static_cast<int>(size), CV_8UC1, const_cast<uint8_t*>(data));
  cv::Mat mat = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  if (mat.empty()) throw Error(what + ": not a decodable image (corrupt or truncated)");
  return mat;
}

}  // namespace

ColorImage decodeColor(const uint8_t* data, size_t size, const std::string& what) {
  const bool png = isPng(data, size);
  if (!png && !isCompleteJpeg(data, size)) {
    throw Error(what + ": truncated or not a JPEG/PNG image");
  }
  cv::Mat mat = decodeUnchanged(data, size, what);
  if (mat.depth() != CV_8U) throw Error(what + ": colour image must have 8 bits per channel");
  cv::Mat rgb;
  switch (mat.channels()) {
    case 1:
      cv::cvtColor(mat, rgb, cv::COLOR_GRAY2RGB);
      break;
    case 3:
      cv::cvtColor(mat, rgb, cv::COLOR_BGR2RGB);
      break;
    case 4:
      cv::cvtColor(mat, rgb, cv::COLOR_BGRA2RGB);
      break;
    default:
      throw Error(what + ": unsupported channel count " + std::to_string(mat.channels()));
  }
  return colorFromMat(rgb);
}

DepthImage decodeDepthPng(const uint8_t* data, size_t size, const std::string& what) {
  if (!isPng(data, size)) throw Error(what + ": depth must be a 16-bit PNG");
  const cv::Mat mat = decodeUnchanged(data, size, what);
  if (mat.type() != CV_16UC1) {
    throw Error(what + ": depth PNG must be 16-bit single channel");
  }
  return depthFromMat(mat);
}

LabelImage decodeLabelPng(const uint8_t* data, size_t size, const std::string& what) {
  if (!isPng(data, size)) throw Error(what + ": labels must be a PNG");
  const cv::Mat mat = decodeUnchanged(data, size, what);
  LabelImage labels(mat.cols, mat.rows);
  if (mat.type() == CV_8UC3) {
    for (int v = 0; v < mat.rows; ++v) {
      const auto* src = mat.ptr<cv::Vec3b>(v);  // B G R
      int32_t* dst = labels.row(v);
      for (int u = 0; u < mat.cols; ++u) dst[u] = src[u][2] + 256 * src[u][1] + 65536 * src[u][0];
    }
  } else if (mat.type() == CV_16UC1 || mat.type() == CV_8UC1) {
    mat.convertTo(asMat(labels), CV_32S);
  } else {
    throw Error(what + ": label PNG must be 8-bit RGB (COCO panoptic) or greyscale");
  }
  return labels;
}

ColorImage readColorFile(const std::string& path) {
  const auto bytes = readFileBytes(path);
  return decodeColor(bytes.data(), bytes.size(), path);
}

DepthImage readDepthFile(const std::string& path) {
  const auto bytes = readFileBytes(path);
  return decodeDepthPng(bytes.data(), bytes.size(), path);
}

}  // namespace panmap
