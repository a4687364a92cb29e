#pragma once

#include <map>
#include <string>
#include <vector>

#include "panmap/core/frame.h"
#include "panmap/core/label_table.h"
#include "panmap/io/mask_reader.h"

namespace panmap {

/// Panoptic masks in the COCO panoptic format: one PNG per image with segment id
/// R + 256 G + 65536 B, and segments_info entries {id, category_id, isthing?, score?}.
///
/// Two JSON arrangements are accepted: one COCO file for the whole folder (its "annotations"
/// each with file_name, image_id and segments_info, "images" mapping image_id to a file
/// name), or one JSON per PNG (<stem>.json holding segments_info or an object with it).
class CocoPanopticReader : public MaskReader {
 public:
  /// @param mask_dir folder with the PNGs (and per-frame JSONs)
  /// @param json_path COCO panoptic JSON, or "" for per-frame JSONs
  /// @param table the segmenter's categories -> panmap classes
  CocoPanopticReader(const std::string& mask_dir, const std::string& json_path, LabelTable table);

  /// True when a mask exists for the colour image with this file stem.
  bool has(const std::string& color_stem) const override;
  /// The colour-image stems of every mask found, in sorted order.
  std::vector<std::string> stems() const override {
    std::vector<std::string> out;
    for (const auto& entry : entries_) out.push_back(entry.first);
    return out;
  }

  /// Reads the mask of a colour image (segment ids) and its segments with panmap classes.
  /// Throws Error naming the file on bad input.
  PanopticFrame read(const std::string& color_stem) override;

 private:
  struct Entry {
    std::string png_path;
    std::string json_path;  // per-frame JSON, or "" when segments come from the COCO file
    std::vector<PanopticSegment> segments;  // from the COCO file
  };
  std::string mask_dir_;
  LabelTable table_;
  std::map<std::string, Entry> entries_;  // by colour stem
};

}  // namespace panmap
