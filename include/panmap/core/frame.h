#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/core/camera.h"
#include "panmap/core/image.h"

namespace panmap {

/// One RGB-D frame with colour registered to the depth camera.
struct RgbdFrame {
  int64_t utime = 0;             ///< capture time of the depth image, microseconds
  int64_t frame_id = 0;          ///< index of the frame in its source sequence
  std::string camera_name;       ///< free text: camera or dataset name
  PinholeCamera camera;          ///< depth camera model, shared by the registered colour image
  double depth_scale_m = 0.001;  ///< metres per depth unit
  DepthImage depth;              ///< camera.width x camera.height
  ColorImage color;              ///< same size as depth, or empty when the source has no colour
};

/// The largest panoptic segment id the mapper takes (the graph update keys a mask's pixels by
/// twice its id; network ids, COCO's category * 1000 + instance included, are far below).
constexpr int32_t kMaxPanopticSegmentId = (int32_t{1} << 30) - 1;

/// One segment of a 2D panoptic segmentation.
struct PanopticSegment {
  int32_t id = 0;        ///< pixel value in PanopticFrame::segment_ids (1..kMaxPanopticSegmentId)
  int32_t category = 0;  ///< panmap class (NYU40 id); 0 = unknown
  int32_t source_category = 0;  ///< the segmenter's own category id
  bool is_thing = false;        ///< countable object (has an instance) vs stuff
  float score = 1.0f;           ///< segmenter confidence in [0, 1]
  bool operator==(const PanopticSegment& o) const {
    return id == o.id && category == o.category && source_category == o.source_category &&
           is_thing == o.is_thing && score == o.score;
  }
};

/// A 2D panoptic segmentation of one frame, at the depth image's resolution.
struct PanopticFrame {
  int64_t utime = 0;       ///< utime of the RgbdFrame it segments
  int64_t frame_id = 0;    ///< frame_id of that RgbdFrame
  LabelImage segment_ids;  ///< per pixel a PanopticSegment::id, 0 = no segment
  std::vector<PanopticSegment> segments;
};

}  // namespace panmap
