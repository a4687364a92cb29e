#pragma once

#include <cstdint>
#include <unordered_set>
#include <vector>

#include "panmap/core/frame.h"

namespace panmap {

/// The ids of a panoptic frame's segments of a known class (category > 0), for a test per
/// pixel: a flag per id below kDense (a network's segments of one frame have small ids in
/// practice), a hash set for the rest.
class KnownSegments {
 public:
  static constexpr int32_t kDense = 1 << 16;

  /// Collects the segments of `frame` with category > 0 and a positive id.
  explicit KnownSegments(const PanopticFrame& frame) : dense_(kDense, 0) {
    for (const PanopticSegment& s : frame.segments) {
      if (s.category <= 0 || s.id <= 0) continue;
      if (s.id < kDense) {
        dense_[static_cast<size_t>(s.id)] = 1;
      } else {
        sparse_.insert(s.id);
      }
      ++size_;
    }
  }

  /// Whether `id` (any pixel value, 0 and negatives included) is a segment of a known class.
  bool contains(int32_t id) const {
    return id > 0 && (id < kDense ? dense_[static_cast<size_t>(id)] != 0 : sparse_.count(id) != 0);
  }

  /// Whether the frame has no segment of a known class.
  bool empty() const { return size_ == 0; }

 private:
  std::vector<uint8_t> dense_;
  std::unordered_set<int32_t> sparse_;
  size_t size_ = 0;
};

}  // namespace panmap
