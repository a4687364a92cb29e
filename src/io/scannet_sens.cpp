// ScanNet's .sens recording (SensReader's sensorData.h, version 4): little-endian throughout.
//   uint32 version; uint64 name length; name; 4 x float[16] (colour intrinsics, colour
//   extrinsics, depth intrinsics, depth extrinsics, row-major); int32 colour and depth
//   compression; uint32 colour width, height, depth width, height; float depth shift;
//   uint64 frame count; then per frame: float[16] camera-to-world, uint64 colour and depth
//   time stamps, uint64 colour and depth byte counts, the colour bytes, the depth bytes.
// IMU records may follow the frames; nothing here reads them.
#include "panmap/io/scannet_sens.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <tuple>

#include <zlib.h>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"

namespace panmap {
namespace {

static_assert(sizeof(Rgb8) == 3, "raw .sens colour is copied as packed RGB");

constexpr uint32_t kSensVersion = 4;
/// Bytes of a frame record before its images: pose, two time stamps, two byte counts.
constexpr uint64_t kFrameRecordBytes = 16 * 4 + 4 * 8;
/// A sensor name longer than this is a corrupt header, not a name.
constexpr uint64_t kMaxNameBytes = 4096;

class LittleEndianReader {
 public:
  LittleEndianReader(std::ifstream* in, const std::string& what) : in_(in), what_(what) {}

  void bytes(void* out, size_t n, const char* field) {
    in_->read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    if (!*in_) throw Error(what_ + ": file ends inside the " + field);
  }
  uint64_t u64(const char* field) { return little(8, field); }
  uint32_t u32(const char* field) { return static_cast<uint32_t>(little(4, field)); }
  int32_t i32(const char* field) { return static_cast<int32_t>(u32(field)); }
  float f32(const char* field) {
    const uint32_t bits = u32(field);
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
  }
  Eigen::Matrix4f matrix(const char* field) {
    Eigen::Matrix4f m;
    for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = f32(field);
    return m;
  }

 private:
  // The next n bytes as a little-endian unsigned number.
  uint64_t little(int n, const char* field) {
    unsigned char b[8];
    bytes(b, static_cast<size_t>(n), field);
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | b[i];
    return v;
  }

  std::ifstream* in_;
  const std::string& what_;
};

void putBytes(std::vector<uint8_t>* out, uint64_t v, int n) {
  for (int i = 0; i < n; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void putFloat(std::vector<uint8_t>* out, float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  putBytes(out, bits, 4);
}
void putMatrix(std::vector<uint8_t>* out, const Eigen::Matrix4f& m) {
  for (int i = 0; i < 16; ++i) putFloat(out, m(i / 4, i % 4));
}

std::string frameName(const std::string& path, size_t index) {
  return path + " frame " + std::to_string(index);
}

}  // namespace

ScanNetSensFile ScanNetSensFile::open(const std::string& path) {
  std::error_code ec;
  const uint64_t file_bytes = std::filesystem::file_size(path, ec);
  if (ec) throw Error("cannot read " + path + ": " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read " + path);
  LittleEndianReader r(&in, path);
  ScanNetSensFile file;
  file.path_ = path;
  const uint32_t version = r.u32("version");
  if (version != kSensVersion) {
    throw Error(path + ": .sens version " + std::to_string(version) + ", only version 4 (" +
                "ScanNet's) is read");
  }
  const uint64_t name_bytes = r.u64("sensor name length");
  if (name_bytes > kMaxNameBytes || name_bytes > file_bytes) {
    throw Error(path + ": sensor name of " + std::to_string(name_bytes) +
                " bytes (not a .sens header)");
  }
  ScanNetSensHeader& h = file.header_;
  h.sensor_name.resize(name_bytes);
  r.bytes(h.sensor_name.data(), name_bytes, "sensor name");
  h.intrinsic_color = r.matrix("colour intrinsics");
  h.extrinsic_color = r.matrix("colour extrinsics");
  h.intrinsic_depth = r.matrix("depth intrinsics");
  h.extrinsic_depth = r.matrix("depth extrinsics");
  h.color_compression = r.i32("colour compression");
  h.depth_compression = r.i32("depth compression");
  h.color_width = r.u32("colour width");
  h.color_height = r.u32("colour height");
  h.depth_width = r.u32("depth width");
  h.depth_height = r.u32("depth height");
  h.depth_shift = r.f32("depth shift");
  const uint64_t frames = r.u64("frame count");
  for (const auto& [w, hgt, kind] : {std::make_tuple(h.color_width, h.color_height, "colour"),
                                     std::make_tuple(h.depth_width, h.depth_height, "depth")}) {
    if (w == 0 || hgt == 0 || uint64_t{w} * hgt > kMaxImagePixels) {
      throw Error(path + ": " + kind + " images of " + std::to_string(w) + "x" +
                  std::to_string(hgt) + " pixels");
    }
  }
  if (!(h.depth_shift > 0.0f) || !std::isfinite(h.depth_shift)) {
    throw Error(path + ": depth shift " + std::to_string(h.depth_shift) +
                " (units per metre must be positive)");
  }
  uint64_t offset = static_cast<uint64_t>(in.tellg());
  if (frames > (file_bytes - offset) / kFrameRecordBytes) {
    throw Error(path + ": header says " + std::to_string(frames) + " frames, the file (" +
                std::to_string(file_bytes) + " bytes) cannot hold them");
  }
  file.records_.reserve(frames);
  for (uint64_t i = 0; i < frames; ++i) {
    const std::string what = frameName(path, i) + " of " + std::to_string(frames);
    if (file_bytes - offset < kFrameRecordBytes) {
      throw Error(what + ": the file ends inside it (" + std::to_string(file_bytes) +
                  " bytes; a partial download?)");
    }
    in.seekg(static_cast<std::streamoff>(offset + kFrameRecordBytes - 16));
    LittleEndianReader fr(&in, what);
    Record rec;
    rec.offset = offset;
    rec.color_bytes = fr.u64("colour byte count");
    rec.depth_bytes = fr.u64("depth byte count");
    // No image of the largest size decoders accept takes more than 4 bytes a pixel stored.
    if (rec.color_bytes > 4 * kMaxImagePixels || rec.depth_bytes > 4 * kMaxImagePixels) {
      throw Error(what + ": images of " + std::to_string(rec.color_bytes) + " and " +
                  std::to_string(rec.depth_bytes) + " bytes (not a frame record)");
    }
    const uint64_t left = file_bytes - offset - kFrameRecordBytes;
    if (rec.color_bytes > left || rec.depth_bytes > left - rec.color_bytes) {
      throw Error(what + ": the file ends inside it (" + std::to_string(file_bytes) +
                  " bytes; a partial download?)");
    }
    file.records_.push_back(rec);
    offset += kFrameRecordBytes + rec.color_bytes + rec.depth_bytes;
  }
  return file;
}

std::ifstream ScanNetSensFile::openAt(size_t index) const {
  if (index >= records_.size()) {
    throw Error(frameName(path_, index) + ": the file has " + std::to_string(records_.size()) +
                " frames");
  }
  std::ifstream in(path_, std::ios::binary);
  if (!in) throw Error("cannot read " + path_);
  in.seekg(static_cast<std::streamoff>(records_[index].offset));
  return in;
}

Eigen::Matrix4f ScanNetSensFile::readPose(size_t index) const {
  std::ifstream in = openAt(index);
  const std::string what = frameName(path_, index);
  return LittleEndianReader(&in, what).matrix("pose");
}

ScanNetSensFrame ScanNetSensFile::readFrame(size_t index) const {
  std::ifstream in = openAt(index);
  const Record& rec = records_[index];
  const std::string what = frameName(path_, index);
  LittleEndianReader r(&in, what);
  ScanNetSensFrame frame;
  frame.camera_to_world = r.matrix("pose");
  frame.timestamp_color = r.u64("colour time stamp");
  frame.timestamp_depth = r.u64("depth time stamp");
  if (r.u64("colour byte count") != rec.color_bytes ||
      r.u64("depth byte count") != rec.depth_bytes) {
    throw Error(what + ": changed since the file was opened");
  }
  frame.color.resize(rec.color_bytes);
  r.bytes(frame.color.data(), frame.color.size(), "colour image");
  frame.depth.resize(rec.depth_bytes);
  r.bytes(frame.depth.data(), frame.depth.size(), "depth image");
  return frame;
}

DepthImage ScanNetSensFile::decodeDepth(const ScanNetSensFrame& frame, size_t index) const {
  const std::string what = frameName(path_, index);
  const size_t pixels = size_t{header_.depth_width} * header_.depth_height;
  std::vector<uint8_t> raw;
  const std::vector<uint8_t>* bytes = &frame.depth;
  if (header_.depth_compression == static_cast<int32_t>(SensDepthCompression::kZlib)) {
    raw.resize(pixels * 2);
    uLongf raw_bytes = static_cast<uLongf>(raw.size());
    const int status = uncompress(raw.data(), &raw_bytes, frame.depth.data(),
                                  static_cast<uLong>(frame.depth.size()));
    if (status == Z_BUF_ERROR) {
      throw Error(what + ": depth inflates to more than " + std::to_string(pixels) + " pixels");
    }
    if (status != Z_OK) throw Error(what + ": depth is not zlib data (" + zError(status) + ")");
    raw.resize(raw_bytes);
    bytes = &raw;
  } else if (header_.depth_compression != static_cast<int32_t>(SensDepthCompression::kRaw)) {
    throw Error(path_ + ": depth compression " + std::to_string(header_.depth_compression) +
                " is not read (0 raw and 1 zlib are; ScanNet's files are zlib)");
  }
  if (bytes->size() != pixels * 2) {
    throw Error(what + ": depth holds " + std::to_string(bytes->size() / 2) + " pixels, not " +
                std::to_string(header_.depth_width) + "x" + std::to_string(header_.depth_height));
  }
  DepthImage depth(static_cast<int>(header_.depth_width), static_cast<int>(header_.depth_height));
  uint16_t* out = depth.data();
  for (size_t i = 0; i < pixels; ++i) {
    out[i] = static_cast<uint16_t>((*bytes)[2 * i] | ((*bytes)[2 * i + 1] << 8));
  }
  return depth;
}

ColorImage ScanNetSensFile::decodeColor(const ScanNetSensFrame& frame, size_t index) const {
  const std::string what = frameName(path_, index) + " colour";
  const int w = static_cast<int>(header_.color_width);
  const int h = static_cast<int>(header_.color_height);
  ColorImage color;
  switch (static_cast<SensColorCompression>(header_.color_compression)) {
    case SensColorCompression::kJpeg:
    case SensColorCompression::kPng:
      color = panmap::decodeColor(frame.color.data(), frame.color.size(), what);
      break;
    case SensColorCompression::kRaw:
      if (frame.color.size() != size_t{header_.color_width} * header_.color_height * 3) {
        throw Error(what + ": " + std::to_string(frame.color.size()) + " bytes, not " +
                    std::to_string(w) + "x" + std::to_string(h) + " RGB");
      }
      color = ColorImage(w, h);
      std::memcpy(color.data(), frame.color.data(), frame.color.size());
      break;
    default:
      throw Error(path_ + ": colour compression " + std::to_string(header_.color_compression) +
                  " is not read (0 raw, 1 PNG and 2 JPEG are)");
  }
  if (color.width() != w || color.height() != h) {
    throw Error(what + " is " + std::to_string(color.width()) + "x" +
                std::to_string(color.height()) + ", the header says " + std::to_string(w) + "x" +
                std::to_string(h));
  }
  return color;
}

void writeScanNetSens(const std::string& path, const ScanNetSensHeader& h,
                      const std::vector<ScanNetSensFrame>& frames) {
  std::vector<uint8_t> out;
  putBytes(&out, kSensVersion, 4);
  putBytes(&out, h.sensor_name.size(), 8);
  out.insert(out.end(), h.sensor_name.begin(), h.sensor_name.end());
  for (const Eigen::Matrix4f* m :
       {&h.intrinsic_color, &h.extrinsic_color, &h.intrinsic_depth, &h.extrinsic_depth}) {
    putMatrix(&out, *m);
  }
  putBytes(&out, static_cast<uint32_t>(h.color_compression), 4);
  putBytes(&out, static_cast<uint32_t>(h.depth_compression), 4);
  for (uint32_t v : {h.color_width, h.color_height, h.depth_width, h.depth_height}) {
    putBytes(&out, v, 4);
  }
  putFloat(&out, h.depth_shift);
  putBytes(&out, frames.size(), 8);
  for (const ScanNetSensFrame& f : frames) {
    putMatrix(&out, f.camera_to_world);
    for (uint64_t v : {f.timestamp_color, f.timestamp_depth, uint64_t{f.color.size()},
                       uint64_t{f.depth.size()}}) {
      putBytes(&out, v, 8);
    }
    out.insert(out.end(), f.color.begin(), f.color.end());
    out.insert(out.end(), f.depth.begin(), f.depth.end());
  }
  writeFileBytes(path, out);
}

std::vector<uint8_t> compressSensDepth(const DepthImage& depth) {
  std::vector<uint8_t> raw;
  raw.reserve(depth.size() * 2);
  for (size_t i = 0; i < depth.size(); ++i) putBytes(&raw, depth.data()[i], 2);
  uLongf bytes = compressBound(static_cast<uLong>(raw.size()));
  std::vector<uint8_t> out(bytes);
  if (compress(out.data(), &bytes, raw.data(), static_cast<uLong>(raw.size())) != Z_OK) {
    throw Error("cannot compress a depth image");
  }
  out.resize(bytes);
  return out;
}

}  // namespace panmap
