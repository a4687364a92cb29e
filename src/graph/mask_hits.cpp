#include "panmap/graph/internal/mask_hits.h"

#include <algorithm>
#include <array>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "panmap/core/radix_sort.h"

namespace panmap::internal {

namespace {

constexpr int kFieldBits = 21;
constexpr uint64_t kFieldMask = (uint64_t{1} << kFieldBits) - 1;
// Below this many hits the radix passes' fixed costs are not worth it.
constexpr size_t kMinRadixHits = 512;

uint64_t field(uint64_t key, int axis) { return (key >> (kFieldBits * (2 - axis))) & kFieldMask; }

void sortAndUnique(std::vector<MaskHit>* hits) {
  std::sort(hits->begin(), hits->end());
  hits->erase(std::unique(hits->begin(), hits->end()), hits->end());
}

}  // namespace

void sortUniqueHits(std::vector<MaskHit>* hits, std::vector<MaskHit>* scratch) {
  const size_t n = hits->size();
  if (n < kMinRadixHits) return sortAndUnique(hits);
  // One frame's hits span a few masks and a room's worth of voxels: the offsets of each from
  // its minimum fit in far fewer than the key's 96 bits. Packed in (mask, x, y, z) order they
  // sort as the hits do, in a few counting passes (std::sort took 2.1 ms of a 5.2 ms graph
  // update per frame at 1 cm; these passes about a third of that, and half of Boost's
  // spreadsort or pdqsort on the same keys).
  int32_t mask_lo = (*hits)[0].mask, mask_hi = mask_lo;
  std::array<uint64_t, 3> lo, hi;
  for (int a = 0; a < 3; ++a) lo[a] = hi[a] = field((*hits)[0].voxel, a);
  for (const MaskHit& h : *hits) {
    mask_lo = std::min(mask_lo, h.mask);
    mask_hi = std::max(mask_hi, h.mask);
    for (int a = 0; a < 3; ++a) {
      const uint64_t f = field(h.voxel, a);
      lo[a] = std::min(lo[a], f);
      hi[a] = std::max(hi[a], f);
    }
  }
  const int mask_bits = bitWidth(
      static_cast<uint64_t>(static_cast<int64_t>(mask_hi) - static_cast<int64_t>(mask_lo)));
  std::array<int, 3> bits;
  for (int a = 0; a < 3; ++a) bits[a] = bitWidth(hi[a] - lo[a]);
  const int total = mask_bits + bits[0] + bits[1] + bits[2];
  if (total > 64) return sortAndUnique(hits);
  const int shift_z = 0, shift_y = bits[2], shift_x = bits[1] + bits[2];
  const int shift_mask = bits[0] + bits[1] + bits[2];
  for (MaskHit& h : *hits) {
    uint64_t key = ((field(h.voxel, 0) - lo[0]) << shift_x) |
                   ((field(h.voxel, 1) - lo[1]) << shift_y) |
                   ((field(h.voxel, 2) - lo[2]) << shift_z);
    if (mask_bits > 0) {
      key |= static_cast<uint64_t>(static_cast<int64_t>(h.mask) - mask_lo) << shift_mask;
    }
    h.voxel = key;
  }

  radixSortByKey(hits, scratch, total, [](const MaskHit& h) { return h.voxel; });

  const uint64_t mask_x = (uint64_t{1} << bits[0]) - 1, mask_y = (uint64_t{1} << bits[1]) - 1,
                 mask_z = (uint64_t{1} << bits[2]) - 1;
  for (MaskHit& h : *hits) {
    const uint64_t key = h.voxel;
    h.mask = mask_bits > 0 ? static_cast<int32_t>(mask_lo + static_cast<int64_t>(key >> shift_mask))
                           : mask_lo;
    h.voxel = (((key >> shift_x) & mask_x) + lo[0]) << (2 * kFieldBits) |
              (((key >> shift_y) & mask_y) + lo[1]) << kFieldBits | ((key & mask_z) + lo[2]);
  }
  hits->erase(std::unique(hits->begin(), hits->end()), hits->end());
}

void maskInterior(const Image<int32_t>& segment_ids, int radius_px, Image<uint8_t>* interior) {
  const int w = segment_ids.width(), h = segment_ids.height();
  if (interior->width() != w || interior->height() != h) *interior = Image<uint8_t>(w, h);
  // 255 where a pixel and its right and lower neighbours agree (and it has a segment): a pixel
  // at an outline marks both sides of it. Eroding that by the radius leaves the interior.
  cv::Mat same(h, w, CV_8U, cv::Scalar(255));
  for (int v = 0; v < h; ++v) {
    const int32_t* ids = segment_ids.row(v);
    const int32_t* below = v + 1 < h ? segment_ids.row(v + 1) : nullptr;
    uint8_t* out = same.ptr<uint8_t>(v);
    uint8_t* out_below = v + 1 < h ? same.ptr<uint8_t>(v + 1) : nullptr;
    for (int u = 0; u < w; ++u) {
      if (ids[u] == 0) out[u] = 0;
      if (u + 1 < w && ids[u + 1] != ids[u]) out[u] = out[u + 1] = 0;
      if (below && below[u] != ids[u]) out[u] = out_below[u] = 0;
    }
  }
  cv::Mat eroded(h, w, CV_8U, interior->data());
  const int k = 2 * radius_px - 1;  // the outline pixels themselves are already 0
  if (k > 1) {
    cv::erode(same, eroded, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  } else {
    same.copyTo(eroded);
  }
  eroded /= 255;
}

}  // namespace panmap::internal
