#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/frame.h"
#include "panmap/core/pose.h"
#include "panmap/image_t.hpp"
#include "panmap/panoptic_t.hpp"
#include "panmap/pose_t.hpp"
#include "panmap/rgbd_frame_t.hpp"

namespace panmap {

/// How images are put into messages.
struct ImageEncoding {
  int8_t color = image_t::COMPRESSION_JPEG;  ///< NONE, JPEG or PNG
  int jpeg_quality = 90;                     ///< 1..100, when colour is re-encoded as JPEG
  int8_t depth = image_t::COMPRESSION_PNG;   ///< NONE or PNG (lossless either way)
  int8_t labels = image_t::COMPRESSION_PNG;  ///< NONE or PNG (lossless either way)
};

/// Image message of a colour image; `jpeg_bytes`, when given and JPEG is asked for, travels
/// unchanged instead of a re-encoding (no second lossy pass).
image_t colorToMessage(const ColorImage& image, const ImageEncoding& encoding,
                       const std::vector<uint8_t>* jpeg_bytes = nullptr);
/// Image message of a depth image; `png_bytes`, when given and PNG is asked for, travel as is.
image_t depthToMessage(const DepthImage& image, const ImageEncoding& encoding,
                       const std::vector<uint8_t>* png_bytes = nullptr);
/// Image message of a label image (raw int32 or COCO-encoded PNG).
image_t labelsToMessage(const LabelImage& image, const ImageEncoding& encoding);

/// Decodes a colour image message; throws Error naming `what` on a bad format or size.
ColorImage colorFromMessage(const image_t& msg, const char* what);
/// Decodes a depth image message; throws Error naming `what` on a bad format or size.
DepthImage depthFromMessage(const image_t& msg, const char* what);
/// Decodes a label image message; throws Error naming `what` on a bad format or size.
LabelImage labelsFromMessage(const image_t& msg, const char* what);

/// Message of an RGB-D frame. The optional bytes are the source's own JPEG / PNG files.
rgbd_frame_t toMessage(const RgbdFrame& frame, const ImageEncoding& encoding,
                       const std::vector<uint8_t>* color_jpeg = nullptr,
                       const std::vector<uint8_t>* depth_png = nullptr);
/// Frame of a message. Throws Error when intrinsics are invalid, images fail to decode, or
/// image sizes disagree with each other.
RgbdFrame fromMessage(const rgbd_frame_t& msg);

/// Message of a pose (position + unit quaternion w x y z).
pose_t toMessage(const StampedPose& pose);
/// Pose of a message. Throws Error on non-finite values or a quaternion far from unit norm.
StampedPose fromMessage(const pose_t& msg);

/// Message of a panoptic segmentation.
panoptic_t toMessage(const PanopticFrame& frame, const ImageEncoding& encoding);
/// Segmentation of a message. Throws Error when the image fails to decode or segment ids
/// are not unique and positive.
PanopticFrame fromMessage(const panoptic_t& msg);

}  // namespace panmap
