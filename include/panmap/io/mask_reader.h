#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "panmap/core/frame.h"

namespace panmap {

/// Counts of what a mask reader has read so far.
struct MaskReaderStats {
  size_t frames_with_masks = 0;
  size_t segments = 0;
  size_t unknown_category_segments = 0;            ///< category absent from the label table
  std::map<int32_t, size_t> unknown_category_ids;  ///< those categories, with their segments
  /// Ids read as "no class" rather than as unknown categories (semantic PNGs' 0 and 255 when
  /// the label table lacks them: isSemanticVoid).
  std::set<int32_t> void_ids;
  size_t labelled_pixels = 0;  ///< pixels with a segment id other than 0 (void), as read
  /// Of those, pixels whose id no segment lists (left unsegmented: COCO treats them as void).
  size_t unlisted_pixels = 0;
  /// Of the unlisted, pixels whose id with R and B swapped is listed: a PNG written as BGR.
  size_t unlisted_bgr_pixels = 0;
};

/// A segmentation network's masks of a dataset's colour images, one per image, found by the
/// image's file stem, with panmap classes from a label table.
class MaskReader {
 public:
  virtual ~MaskReader() = default;

  /// True when a mask exists for the colour image with this file stem.
  virtual bool has(const std::string& color_stem) const = 0;

  /// Reads the mask of a colour image (segment ids at the mask file's resolution) and its
  /// segments with panmap classes. Throws Error naming the file on bad input.
  virtual PanopticFrame read(const std::string& color_stem) = 0;

  /// The colour-image stems of every mask found, in sorted order.
  virtual std::vector<std::string> stems() const = 0;

  /// What has been read so far.
  const MaskReaderStats& stats() const { return stats_; }

 protected:
  MaskReaderStats stats_;
};

}  // namespace panmap
