#include "panmap/segmentation/mask_edge_fill.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>

#include "panmap/core/error.h"

namespace panmap {

void MaskEdgeFillConfig::check() const {
  if (!(max_depth_step >= 0.0) || !std::isfinite(max_depth_step)) {
    throw Error("mask_edge_fill.max_depth_step must be finite and >= 0, got " +
                std::to_string(max_depth_step));
  }
}

int64_t fillMaskEdges(const DepthImage& depth, const PanopticFrame& masks,
                      const MaskEdgeFillConfig& config, LabelImage* labels) {
  config.check();
  if (!config.enabled || masks.segment_ids.empty()) return 0;
  const int w = labels->width(), h = labels->height();
  if (depth.width() != w || depth.height() != h || masks.segment_ids.width() != w ||
      masks.segment_ids.height() != h) {
    throw Error("mask edge fill: depth, mask and label images differ in size");
  }
  // Masks of a known class: a category-0 segment names no class to vote for.
  std::unordered_set<int32_t> known;
  for (const PanopticSegment& s : masks.segments) {
    if (s.category > 0) known.insert(s.id);
  }
  if (known.empty()) return 0;
  const int32_t* mask = masks.segment_ids.data();
  const uint16_t* d = depth.data();
  int32_t* label = labels->data();
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  // Pixels a fill may reach: in a known mask, with depth, without a label. Sources: labelled
  // pixels of a known mask. Both found once, so the loop below reads no set.
  std::vector<uint8_t> open(n, 0);
  std::vector<int32_t> queue;
  for (size_t i = 0; i < n; ++i) {
    if (mask[i] <= 0 || known.count(mask[i]) == 0) continue;
    if (label[i] > 0) {
      queue.push_back(static_cast<int32_t>(i));
    } else if (d[i] > 0) {
      open[i] = 1;
    }
  }
  const float step = static_cast<float>(config.max_depth_step);
  int64_t filled = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int32_t i = queue[head];
    const int u = i % w, v = i / w;
    const float di = static_cast<float>(d[i]);
    auto reach = [&](int32_t j) {
      if (!open[j] || mask[j] != mask[i]) return;
      const float dj = static_cast<float>(d[j]);
      // The source may lack depth (a labelled pixel always has it, a filled one too).
      if (std::fabs(dj - di) > step * std::min(di, dj)) return;
      open[j] = 0;
      label[j] = label[i];
      ++filled;
      queue.push_back(j);
    };
    if (u > 0) reach(i - 1);
    if (u + 1 < w) reach(i + 1);
    if (v > 0) reach(i - w);
    if (v + 1 < h) reach(i + w);
  }
  return filled;
}

}  // namespace panmap
