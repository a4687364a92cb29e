#include "panmap/lcm/conversions.h"

#include <cmath>
#include <cstring>
#include <set>
#include <sstream>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"

namespace panmap {
namespace {

// Synchronisation subtracts time stamps from one another: beyond 2^61 us (73,000 years) from
// the epoch the differences overflow int64 (a pose at INT64_MIN did, in fuzz/fuzz_lcm_session).
void checkUtime(int64_t utime, const std::string& what) {
  constexpr int64_t kMaxUtime = int64_t{1} << 61;
  if (utime < -kMaxUtime || utime > kMaxUtime) {
    // No number in the reason: rejections are counted by it, one key however many arrive.
    throw Error(what + ": utime out of range (beyond 2^61 us)");
  }
}

template <typename T>
image_t rawImage(const Image<T>& image, int8_t format) {
  image_t msg;
  msg.width = image.width();
  msg.height = image.height();
  msg.row_stride = static_cast<int32_t>(image.width() * sizeof(T));
  msg.pixel_format = format;
  msg.compression = image_t::COMPRESSION_NONE;
  msg.data.resize(image.size() * sizeof(T));
  if (!msg.data.empty()) std::memcpy(msg.data.data(), image.data(), msg.data.size());
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

image_t compressedImage(int width, int height, int8_t format, int8_t compression,
                        std::vector<uint8_t> bytes) {
  image_t msg;
  msg.width = width;
  msg.height = height;
  msg.row_stride = 0;
  msg.pixel_format = format;
  msg.compression = compression;
  msg.data = std::move(bytes);
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

// Raw pixels of a message, row by row (strides may pad rows).
template <typename T>
Image<T> rawFromMessage(const image_t& msg, const char* what) {
  const size_t row_bytes = static_cast<size_t>(msg.width) * sizeof(T);
  if (msg.row_stride < static_cast<int64_t>(row_bytes) ||
      static_cast<size_t>(msg.size) != static_cast<size_t>(msg.row_stride) * msg.height ||
      msg.data.size() != static_cast<size_t>(msg.size)) {
    std::ostringstream s;
    s << what << ": raw image of " << msg.width << "x" << msg.height << " with stride "
      << msg.row_stride << " does not match its " << msg.data.size() << " bytes";
    throw Error(s.str());
  }
  Image<T> image(msg.width, msg.height);
  for (int v = 0; v < msg.height; ++v) {
    std::memcpy(image.row(v), msg.data.data() + static_cast<size_t>(v) * msg.row_stride, row_bytes);
  }
  return image;
}

void checkHeader(const image_t& msg, int8_t format, const char* what) {
  if (msg.pixel_format != format) {
    throw Error(std::string(what) + ": pixel format " + std::to_string(msg.pixel_format) +
                ", expected " + std::to_string(format));
  }
  if (msg.width <= 0 || msg.height <= 0 || msg.width > 16384 || msg.height > 16384) {
    throw Error(std::string(what) + ": image size " + std::to_string(msg.width) + "x" +
                std::to_string(msg.height) + " is empty or implausible");
  }
  if (msg.size < 0 || static_cast<size_t>(msg.size) != msg.data.size()) {
    throw Error(std::string(what) + ": size field disagrees with the data");
  }
}

template <typename T>
void checkDecodedSize(const Image<T>& image, const image_t& msg, const char* what) {
  if (image.width() != msg.width || image.height() != msg.height) {
    std::ostringstream s;
    s << what << ": compressed image is " << image.width() << "x" << image.height()
      << " but the message says " << msg.width << "x" << msg.height;
    throw Error(s.str());
  }
}

}  // namespace

image_t colorToMessage(const ColorImage& image, const ImageEncoding& encoding,
                       const std::vector<uint8_t>* jpeg_bytes) {
  // A depth-only source (or a frame store kept without colour) sends no colour: an empty raw
  // image, which fromMessage reads back as a frame without colour. The codecs refuse 0x0.
  if (image.empty()) return rawImage(image, image_t::PIXEL_FORMAT_RGB8);
  switch (encoding.color) {
    case image_t::COMPRESSION_JPEG:
      return compressedImage(
          image.width(), image.height(), image_t::PIXEL_FORMAT_RGB8, image_t::COMPRESSION_JPEG,
          jpeg_bytes && !jpeg_bytes->empty() ? *jpeg_bytes
                                             : encodeJpeg(image, encoding.jpeg_quality));
    case image_t::COMPRESSION_PNG:
      return compressedImage(image.width(), image.height(), image_t::PIXEL_FORMAT_RGB8,
                             image_t::COMPRESSION_PNG, encodePng(image));
    default:
      return rawImage(image, image_t::PIXEL_FORMAT_RGB8);
  }
}

image_t depthToMessage(const DepthImage& image, const ImageEncoding& encoding,
                       const std::vector<uint8_t>* png_bytes) {
  if (encoding.depth == image_t::COMPRESSION_PNG) {
    return compressedImage(image.width(), image.height(), image_t::PIXEL_FORMAT_DEPTH_U16,
                           image_t::COMPRESSION_PNG,
                           png_bytes && !png_bytes->empty() ? *png_bytes : encodeDepthPng(image));
  }
  return rawImage(image, image_t::PIXEL_FORMAT_DEPTH_U16);
}

image_t labelsToMessage(const LabelImage& image, const ImageEncoding& encoding) {
  if (encoding.labels == image_t::COMPRESSION_PNG) {
    return compressedImage(image.width(), image.height(), image_t::PIXEL_FORMAT_LABEL_I32,
                           image_t::COMPRESSION_PNG, encodeLabelPng(image));
  }
  return rawImage(image, image_t::PIXEL_FORMAT_LABEL_I32);
}

ColorImage colorFromMessage(const image_t& msg, const char* what) {
  checkHeader(msg, image_t::PIXEL_FORMAT_RGB8, what);
  if (msg.compression == image_t::COMPRESSION_NONE) return rawFromMessage<Rgb8>(msg, what);
  if (msg.compression != image_t::COMPRESSION_JPEG && msg.compression != image_t::COMPRESSION_PNG) {
    throw Error(std::string(what) + ": unknown compression " + std::to_string(msg.compression));
  }
  ColorImage image = decodeColor(msg.data.data(), msg.data.size(), what);
  checkDecodedSize(image, msg, what);
  return image;
}

DepthImage depthFromMessage(const image_t& msg, const char* what) {
  checkHeader(msg, image_t::PIXEL_FORMAT_DEPTH_U16, what);
  if (msg.compression == image_t::COMPRESSION_NONE) return rawFromMessage<uint16_t>(msg, what);
  if (msg.compression != image_t::COMPRESSION_PNG) {
    throw Error(std::string(what) + ": depth compression must be none or PNG");
  }
  DepthImage image = decodeDepthPng(msg.data.data(), msg.data.size(), what);
  checkDecodedSize(image, msg, what);
  return image;
}

LabelImage labelsFromMessage(const image_t& msg, const char* what) {
  checkHeader(msg, image_t::PIXEL_FORMAT_LABEL_I32, what);
  if (msg.compression == image_t::COMPRESSION_NONE) return rawFromMessage<int32_t>(msg, what);
  if (msg.compression != image_t::COMPRESSION_PNG) {
    throw Error(std::string(what) + ": label compression must be none or PNG");
  }
  LabelImage image = decodeLabelPng(msg.data.data(), msg.data.size(), what);
  checkDecodedSize(image, msg, what);
  return image;
}

rgbd_frame_t toMessage(const RgbdFrame& frame, const ImageEncoding& encoding,
                       const std::vector<uint8_t>* color_jpeg,
                       const std::vector<uint8_t>* depth_png) {
  rgbd_frame_t msg;
  msg.utime = frame.utime;
  msg.frame_id = frame.frame_id;
  msg.camera = frame.camera_name;
  msg.fx = frame.camera.fx;
  msg.fy = frame.camera.fy;
  msg.cx = frame.camera.cx;
  msg.cy = frame.camera.cy;
  msg.depth_scale_m = frame.depth_scale_m;
  msg.color = colorToMessage(frame.color, encoding, color_jpeg);
  msg.depth = depthToMessage(frame.depth, encoding, depth_png);
  return msg;
}

RgbdFrame fromMessage(const rgbd_frame_t& msg) {
  checkUtime(msg.utime, "frame");
  RgbdFrame frame;
  frame.utime = msg.utime;
  frame.frame_id = msg.frame_id;
  frame.camera_name = msg.camera;
  frame.depth_scale_m = msg.depth_scale_m;
  if (!(std::isfinite(msg.depth_scale_m) && msg.depth_scale_m > 0.0)) {
    throw Error("rgbd frame " + std::to_string(msg.frame_id) + ": depth_scale_m must be > 0");
  }
  frame.depth = depthFromMessage(msg.depth, "rgbd depth");
  frame.camera =
      PinholeCamera{msg.fx, msg.fy, msg.cx, msg.cy, frame.depth.width(), frame.depth.height()};
  std::string why;
  if (!frame.camera.isValid(&why)) {
    throw Error("rgbd frame " + std::to_string(msg.frame_id) + ": intrinsics: " + why);
  }
  if (msg.cx < 0.0 || msg.cx > frame.depth.width() || msg.cy < 0.0 ||
      msg.cy > frame.depth.height()) {
    // The usual sign of intrinsics calibrated for another resolution than the image's.
    std::ostringstream s;
    s << "rgbd frame " << msg.frame_id << ": principal point (" << msg.cx << ", " << msg.cy
      << ") lies outside the " << frame.depth.width() << "x" << frame.depth.height()
      << " depth image";
    throw Error(s.str());
  }
  if (msg.color.size > 0 || msg.color.width > 0) {
    frame.color = colorFromMessage(msg.color, "rgbd colour");
    if (frame.color.width() != frame.depth.width() ||
        frame.color.height() != frame.depth.height()) {
      std::ostringstream s;
      s << "rgbd frame " << msg.frame_id << ": colour " << frame.color.width() << "x"
        << frame.color.height() << " is not registered to depth " << frame.depth.width() << "x"
        << frame.depth.height();
      throw Error(s.str());
    }
  }
  return frame;
}

pose_t toMessage(const StampedPose& pose) {
  pose_t msg;
  msg.utime = pose.utime;
  msg.frame_id = pose.frame_id;
  const Eigen::Vector3d t = pose.T_W_C.translation();
  const Eigen::Quaterniond q(pose.T_W_C.linear());
  for (int i = 0; i < 3; ++i) msg.position[i] = t[i];
  msg.orientation[0] = q.w();
  msg.orientation[1] = q.x();
  msg.orientation[2] = q.y();
  msg.orientation[3] = q.z();
  msg.source = static_cast<int8_t>(pose.source);
  return msg;
}

StampedPose fromMessage(const pose_t& msg) {
  checkUtime(msg.utime, "pose");
  bool finite = true;
  for (double x : msg.position) finite = finite && std::isfinite(x);
  for (double x : msg.orientation) finite = finite && std::isfinite(x);
  if (!finite) throw Error("pose " + std::to_string(msg.utime) + ": non-finite value");
  const Eigen::Quaterniond q(msg.orientation[0], msg.orientation[1], msg.orientation[2],
                             msg.orientation[3]);
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    throw Error("pose " + std::to_string(msg.utime) + ": quaternion is not unit length");
  }
  StampedPose pose;
  pose.utime = msg.utime;
  pose.frame_id = msg.frame_id;
  pose.T_W_C.linear() = q.normalized().toRotationMatrix();
  pose.T_W_C.translation() = Eigen::Vector3d(msg.position[0], msg.position[1], msg.position[2]);
  pose.source = (msg.source >= 0 && msg.source <= 3) ? static_cast<PoseSource>(msg.source)
                                                     : PoseSource::kUnknown;
  return pose;
}

panoptic_t toMessage(const PanopticFrame& frame, const ImageEncoding& encoding) {
  panoptic_t msg;
  msg.utime = frame.utime;
  msg.frame_id = frame.frame_id;
  msg.segment_ids = labelsToMessage(frame.segment_ids, encoding);
  msg.num_segments = static_cast<int32_t>(frame.segments.size());
  for (const PanopticSegment& s : frame.segments) {
    panoptic_segment_t m;
    m.id = s.id;
    m.category = s.category;
    m.source_category = s.source_category;
    m.is_thing = s.is_thing;
    m.score = s.score;
    msg.segments.push_back(m);
  }
  return msg;
}

PanopticFrame fromMessage(const panoptic_t& msg) {
  checkUtime(msg.utime, "panoptic");
  PanopticFrame frame;
  frame.utime = msg.utime;
  frame.frame_id = msg.frame_id;
  frame.segment_ids = labelsFromMessage(msg.segment_ids, "panoptic segment_ids");
  std::set<int32_t> ids;
  for (const panoptic_segment_t& m : msg.segments) {
    if (m.id <= 0 || !ids.insert(m.id).second) {
      throw Error("panoptic " + std::to_string(msg.utime) + ": segment id " + std::to_string(m.id) +
                  " is not positive and unique");
    }
    if (!(m.score >= 0.0f && m.score <= 1.0f)) {
      throw Error("panoptic " + std::to_string(msg.utime) + ": score of segment " +
                  std::to_string(m.id) + " not in [0, 1]");
    }
    frame.segments.push_back(
        PanopticSegment{m.id, m.category, m.source_category, m.is_thing != 0, m.score});
  }
  return frame;
}

}  // namespace panmap
