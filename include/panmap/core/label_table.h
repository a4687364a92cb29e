#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace panmap {

/// Maps a segmenter's category ids to panmap classes (NYU40 ids).
///
/// File format (tab- or space-separated, '#' starts a comment, one category per line):
///   source_id  panmap_class  is_thing  name...
/// e.g. "1  31  1  person". panmap_class 0 marks a category panmap ignores.
class LabelTable {
 public:
  /// One row of the table.
  struct Entry {
    int32_t panmap_class = 0;  ///< NYU40 id, 0 = ignored
    bool is_thing = false;     ///< countable object vs stuff
    std::string name;          ///< the segmenter's name for it
  };

  /// Loads a table file; throws Error naming the file and line on a malformed row.
  static LabelTable load(const std::string& path);

  /// The identity table over NYU40 (for segmenters trained on ScanNet labels).
  static LabelTable nyu40Identity();

  /// The same rows renumbered 0..size()-1 in increasing source id: the contiguous class
  /// indices a network's raw output uses when its dataset's categories are listed in id order
  /// (Mask2Former, OneFormer and Hugging Face transformers number COCO panoptic's 133
  /// categories so; ADE20K's 0-149 are contiguous already).
  LabelTable contiguous() const;

  /// Adds or replaces one row.
  void set(int32_t source_id, const Entry& entry) { entries_[source_id] = entry; }

  /// The row of a source category, or nothing when the table does not know it.
  std::optional<Entry> lookup(int32_t source_id) const;

  /// Number of rows.
  size_t size() const { return entries_.size(); }

 private:
  std::map<int32_t, Entry> entries_;
};

}  // namespace panmap
