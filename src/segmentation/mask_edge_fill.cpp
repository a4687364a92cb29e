#include "panmap/segmentation/mask_edge_fill.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "panmap/core/error.h"
#include "panmap/core/known_segments.h"

namespace panmap {

void MaskEdgeFillConfig::check() const {
  if (max_distance_px < 0) {
    throw Error("mask_edge_fill.max_distance_px must be >= 0, got " +
                std::to_string(max_distance_px));
  }
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
  const KnownSegments known_segments(masks);
  auto known = [&known_segments](int32_t id) { return known_segments.contains(id); };
  const int32_t* mask = masks.segment_ids.data();
  const uint16_t* d = depth.data();
  int32_t* label = labels->data();
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  // Pixels a fill may reach: in a known mask, with depth, without a label.
  std::vector<uint8_t> open(n, 0);
  bool any_open = false;
  for (size_t i = 0; i < n; ++i) {
    if (label[i] == 0 && d[i] > 0 && known(mask[i])) open[i] = 1, any_open = true;
  }
  if (!any_open) return 0;
  // Sources, in pixel order: labelled pixels of a known mask next to an open pixel of the same
  // mask (one with none can give nothing: the fill moves through open pixels only).
  std::vector<int32_t> queue;
  for (int v = 0; v < h; ++v) {
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(w);
    for (int u = 0; u < w; ++u) {
      const size_t k = row + static_cast<size_t>(u);
      if (label[k] <= 0) continue;
      const int32_t m = mask[k];
      auto opens = [&](size_t j) { return open[j] && mask[j] == m; };
      if (((u > 0 && opens(k - 1)) || (u + 1 < w && opens(k + 1)) ||
           (v > 0 && opens(k - static_cast<size_t>(w))) ||
           (v + 1 < h && opens(k + static_cast<size_t>(w)))) &&
          known(m)) {
        queue.push_back(static_cast<int32_t>(k));
      }
    }
  }
  const float step = static_cast<float>(config.max_depth_step);
  // Steps from the source of each queued pixel (sources 0), for max_distance_px.
  std::vector<int32_t> steps(queue.size(), 0);
  int64_t filled = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int32_t i = queue[head];
    const int u = i % w, v = i / w;
    const float di = static_cast<float>(d[i]);
    const int32_t next_steps = steps[head] + 1;
    if (config.max_distance_px > 0 && next_steps > config.max_distance_px) continue;
    auto reach = [&](int32_t j) {
      if (!open[j] || mask[j] != mask[i]) return;
      const float dj = static_cast<float>(d[j]);
      if (std::fabs(dj - di) > step * std::min(di, dj)) return;
      open[j] = 0;
      label[j] = label[i];
      ++filled;
      queue.push_back(j);
      steps.push_back(next_steps);
    };
    if (u > 0) reach(i - 1);
    if (u + 1 < w) reach(i + 1);
    if (v > 0) reach(i - w);
    if (v + 1 < h) reach(i + w);
  }
  return filled;
}

}  // namespace panmap
