#pragma once

#include <map>
#include <set>
#include <string>

#include "panmap/core/label_table.h"
#include "panmap/io/mask_reader.h"

namespace panmap {

/// Splits an image of class ids into panoptic segments, as SemanticMaskReader describes: each
/// stuff class one segment, each connected region (8-neighbourhood) of a thing class one,
/// numbered from 1 in order of class id, then of the region's first pixel in raster order.
/// Pixels of ids `table` lacks are 0; their number of distinct ids is added to `unknown_ids`,
/// except for the void values of semantic PNGs (isSemanticVoid), which are only added to
/// `void_ids` when given.
PanopticFrame panopticFromClasses(const LabelImage& classes, const LabelTable& table,
                                  size_t* unknown_ids,
                                  std::map<int32_t, size_t>* unknown_by_id = nullptr,
                                  std::set<int32_t>* void_ids = nullptr);

/// True for the ids semantic segmentation PNGs use for "no class" when `table` does not list
/// them as a class: 0 (unlabelled in ADE20K's and NYU's numbering), 255 (the ignore value of
/// 8-bit masks of networks that count classes from 0) and 65535 (its 16-bit form).
bool isSemanticVoid(int32_t id, const LabelTable& table);

/// The masks a semantic network would have given for a panoptic frame: each pixel keeps its
/// segment's class (NYU40 id, looked up in `table` as a source id) and loses its instance,
/// then panopticFromClasses splits the classes again. Class 0 pixels stay unsegmented.
PanopticFrame withoutInstances(const PanopticFrame& panoptic, const LabelTable& table);

/// Masks of a semantic segmentation network (no instances): one greyscale PNG (8 or 16 bit) per
/// colour image, named after it, each pixel the class id in the network's numbering.
///
/// Each stuff class of a frame becomes one segment. Each connected region (8-neighbourhood) of
/// a thing class becomes one segment: a guess at its instances that keeps apart the objects of
/// a class that do not touch in the image and joins those that do. Pixels of ids the label
/// table lacks stay unsegmented (0); each such id counts once per frame as an unknown
/// segment, but for the void values (isSemanticVoid), which MaskReaderStats::void_ids lists.
class SemanticMaskReader : public MaskReader {
 public:
  /// @param mask_dir folder with the PNGs
  /// @param table the network's class ids -> panmap classes (is_thing decides instances)
  SemanticMaskReader(const std::string& mask_dir, LabelTable table);

  /// True when a mask exists for the colour image with this file stem.
  bool has(const std::string& color_stem) const override;
  /// The colour-image stems of every mask found, in sorted order.
  std::vector<std::string> stems() const override {
    std::vector<std::string> out;
    for (const auto& entry : files_) out.push_back(entry.first);
    return out;
  }

  /// Reads a mask and splits it into segments. Throws Error naming the file when it is not a
  /// greyscale PNG.
  PanopticFrame read(const std::string& color_stem) override;

 private:
  LabelTable table_;
  std::map<std::string, std::string> files_;  // colour stem -> PNG path
};

}  // namespace panmap
