#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "panmap/core/frame.h"
#include "panmap/core/thread_pool.h"
#include "panmap/segmentation/panoptic_geometric.h"

namespace panmap {
namespace internal {

/// Eq. 1, the panoptic confidence P_o of a surface inside panoptic segment o: the segmenter's
/// score for a thing, a fixed stuff_confidence for stuff.
inline float panopticConfidence(const PanopticSegment& segment, float stuff_confidence) {
  return segment.is_thing ? segment.score : stuff_confidence;
}

/// Intersects geometric segments with panoptic masks into surfaces (III-A). Holds scratch
/// buffers reused across frames.
class SurfaceFuser {
 public:
  /// Fills out->surfaces and out->surface_list from out->geometric (ids 1..num_geometric).
  /// Pixels in no listed panoptic segment, or in one of unknown category (0), are background.
  /// Surface ids run from 1 in order of (geometric segment, panoptic segment id), then the
  /// mask-only surfaces in order of their first pixel.
  /// @param panoptic null or geometry-only: every surface is background
  /// Throws Error when a listed segment id is not positive or listed twice.
  /// @param pool threads for the final relabelling pass (not owned; null: the caller's thread)
  /// @param depth the frame's depth, for mask-only surfaces (SurfaceFusionConfig); null: none
  void fuse(const PanopticFrame* panoptic, const SurfaceFusionConfig& config,
            FrameSegmentation* out, ThreadPool* pool = nullptr, const DepthImage* depth = nullptr);

 private:
  struct Pair {
    int32_t geometric;      ///< geometric segment id
    int32_t segment_index;  ///< index in PanopticFrame::segments, -1 = background
    int32_t panoptic_id;    ///< its panoptic segment id, 0 = background
    int32_t num_pixels;
  };

  void indexSegments(const PanopticFrame& panoptic);
  int32_t segmentIndex(int32_t panoptic_id) const;
  int32_t findOrAddPair(int32_t geometric, int32_t segment_index, int32_t panoptic_id);
  /// Adds the mask-only surfaces of thing masks that hold no surface (after pass 2).
  void addMaskOnlySurfaces(const PanopticFrame& panoptic, const DepthImage& depth,
                           const SurfaceFusionConfig& config, FrameSegmentation* out);

  std::vector<std::pair<int32_t, int32_t>> id_to_index_;  ///< (id, index), sorted by id
  std::vector<uint64_t> table_keys_;  ///< open-addressing (geometric, index) -> pair table
  std::vector<int32_t> table_values_;
  std::vector<Pair> pairs_;
  std::vector<int32_t> order_;
  std::vector<int32_t> pair_to_surface_;
  std::vector<uint8_t> segment_has_surface_;  ///< per PanopticFrame::segments index
  std::vector<int32_t> open_;                 ///< per pixel: mask id still to group, else 0
  std::vector<int32_t> queue_;                ///< pixels of the part being grown
};

}  // namespace internal
}  // namespace panmap
