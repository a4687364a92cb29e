#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "panmap/core/image.h"

namespace panmap {

/// How a .sens file stores colour (ScanNet's COMPRESSION_TYPE_COLOR).
enum class SensColorCompression : int32_t { kRaw = 0, kPng = 1, kJpeg = 2 };
/// How a .sens file stores depth (COMPRESSION_TYPE_DEPTH; occi, 2, is not read).
enum class SensDepthCompression : int32_t { kRaw = 0, kZlib = 1 };

/// The header of a ScanNet .sens file (version 4, the only one ScanNet released): the sensor,
/// both cameras' 4x4 intrinsics and rig extrinsics (row-major in the file), image sizes, and
/// the depth unit (depth_shift units per metre, 1000 for millimetres).
struct ScanNetSensHeader {
  std::string sensor_name;
  Eigen::Matrix4f intrinsic_color = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f extrinsic_color = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f intrinsic_depth = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f extrinsic_depth = Eigen::Matrix4f::Identity();
  int32_t color_compression = static_cast<int32_t>(SensColorCompression::kJpeg);
  int32_t depth_compression = static_cast<int32_t>(SensDepthCompression::kZlib);
  uint32_t color_width = 0;
  uint32_t color_height = 0;
  uint32_t depth_width = 0;
  uint32_t depth_height = 0;
  float depth_shift = 1000.0f;
};

/// One frame of a .sens file as stored: camera-to-world pose (-inf where ScanNet's
/// reconstruction lost track), the two time stamps, and the images' bytes as compressed.
struct ScanNetSensFrame {
  Eigen::Matrix4f camera_to_world = Eigen::Matrix4f::Identity();
  uint64_t timestamp_color = 0;
  uint64_t timestamp_depth = 0;
  std::vector<uint8_t> color;
  std::vector<uint8_t> depth;
};

/// A ScanNet .sens file (the recording ScanNet's download script fetches for each scan),
/// indexed when opened and read a frame at a time, so a file of several GB costs only its
/// frame index in memory.
class ScanNetSensFile {
 public:
  /// Reads the header and walks the frame records to index them. Throws Error naming the
  /// file and what is wrong: unreadable, not version 4, a size in the header that the file
  /// cannot hold, a frame cut off by the end of the file.
  static ScanNetSensFile open(const std::string& path);

  /// The file's path.
  const std::string& path() const { return path_; }
  /// The header.
  const ScanNetSensHeader& header() const { return header_; }
  /// Number of frames.
  size_t size() const { return records_.size(); }
  /// Frame i's pose, time stamps and image bytes. Throws Error naming the file and frame.
  ScanNetSensFrame readFrame(size_t index) const;
  /// Frame i's camera-to-world pose alone (-inf where ScanNet lost track). Throws Error like
  /// readFrame.
  Eigen::Matrix4f readPose(size_t index) const;
  /// Frame i's depth, decompressed: depth_width x depth_height raw units. Throws Error naming
  /// the file and frame when the bytes do not decompress to exactly that.
  DepthImage decodeDepth(const ScanNetSensFrame& frame, size_t index) const;
  /// Frame i's colour as RGB, color_width x color_height. Throws Error like decodeDepth.
  ColorImage decodeColor(const ScanNetSensFrame& frame, size_t index) const;

 private:
  struct Record {
    uint64_t offset = 0;  ///< of the frame's pose
    uint64_t color_bytes = 0;
    uint64_t depth_bytes = 0;
  };
  /// The file, positioned at frame i's record. Throws Error naming a frame it lacks.
  std::ifstream openAt(size_t index) const;

  std::string path_;
  ScanNetSensHeader header_;
  std::vector<Record> records_;
};

/// Writes a .sens file (version 4, no IMU frames) with the frames' bytes as given; what
/// tests and fuzz seeds build their recordings with. Throws Error naming the path on failure.
void writeScanNetSens(const std::string& path, const ScanNetSensHeader& header,
                      const std::vector<ScanNetSensFrame>& frames);

/// Depth as a .sens file stores it with zlib: the raw 16-bit little-endian pixels, deflated.
std::vector<uint8_t> compressSensDepth(const DepthImage& depth);

}  // namespace panmap
