#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/core/thread_pool.h"

namespace panmap {

/// Which unlabelled pixels of a panoptic mask take a super-point label from the mask's
/// labelled pixels (fillMaskEdges).
struct MaskEdgeFillConfig {
  /// Off: pixels that no surface holds (geometric edges, dropped small surfaces) cast no vote.
  bool enabled = true;
  /// A step between 4-neighbours is followed when their depths differ by at most this share
  /// of the nearer one (as depth_segmentation.depth_discontinuity_ratio marks a jump).
  double max_depth_step = 0.01;
  /// Steps at most from a labelled pixel (0: no limit). 6, half the depth segmentation's
  /// normal window: the band it leaves out of every surface along an edge. Farther, a fill
  /// would cross whole dropped segments, and the gap between two objects one mask covers
  /// (a `hard` network's merged masks: two touching chairs joined through it).
  int max_distance_px = 6;
  /// Throws Error naming the bad field.
  void check() const;
};

/// Working memory of fillMaskEdges, kept between frames so that a frame allocates nothing.
struct MaskEdgeFillScratch {
  /// A pixel being filled: its index, its index on the padded grid of its band, steps from its
  /// source and the label it carries.
  struct Item {
    int32_t pixel;
    int32_t padded;
    int32_t steps;
    int32_t label;
  };
  /// One band's: the pixels a fill may reach, and the breadth-first queue (its sources, then
  /// every pixel it filled).
  struct Band {
    std::vector<uint8_t> open;
    std::vector<Item> queue;
  };
  std::vector<Band> bands;
};

/// Gives each pixel without a label (0) that lies inside a panoptic mask of a known class, and
/// has depth, the label of the nearest labelled pixel of the same mask it reaches through at
/// most max_distance_px 4-neighbour steps without a depth jump (breadth first from the
/// labelled pixels of the masks, in pixel order: deterministic). Why: the geometric segmentation
/// leaves the pixels near depth edges, concave joints and thin parts out of every surface (a band
/// of about half its normal window), so a chair's legs, or the strip of its seat seen under a desk,
/// would never vote and stay unlabelled in the map however often they are seen; the mask says whose
/// they are, the depth says where that stops. Returns the number of pixels labelled.
/// @param depth the frame's depth image (0 = none), in units of depth_scale_m
/// @param masks the frame's panoptic segmentation, same size
/// @param labels super-point label per pixel, same size; filled in place
/// @param scratch working memory reused between calls (null: allocated for this call)
/// @param pool threads to fill horizontal bands of the image with (null: one); the result is
///        the same whatever the number of threads (each band runs the fill over its rows and
///        max_distance_px + 1 rows around them, all a band pixel's label can depend on)
int64_t fillMaskEdges(const DepthImage& depth, const PanopticFrame& masks,
                      const MaskEdgeFillConfig& config, LabelImage* labels,
                      MaskEdgeFillScratch* scratch = nullptr, ThreadPool* pool = nullptr);

}  // namespace panmap
