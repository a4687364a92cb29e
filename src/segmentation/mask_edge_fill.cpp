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
                      const MaskEdgeFillConfig& config, LabelImage* labels,
                      MaskEdgeFillScratch* scratch) {
  config.check();
  if (!config.enabled || masks.segment_ids.empty()) return 0;
  const int w = labels->width(), h = labels->height();
  if (depth.width() != w || depth.height() != h || masks.segment_ids.width() != w ||
      masks.segment_ids.height() != h) {
    throw Error("mask edge fill: depth, mask and label images differ in size");
  }
  // Masks of a known class: a category-0 segment names no class to vote for.
  const KnownSegments known(masks);
  const int32_t* mask = masks.segment_ids.data();
  const uint16_t* d = depth.data();
  int32_t* label = labels->data();
  // Pixels a fill may reach (in a known mask, with depth, without a label), on a grid one pixel
  // wider on every side whose border is never open: a neighbour is tested without bounds checks
  // and without dividing an index back into (u, v). Pixel i = v * w + u sits at
  // p = i + (2 v + 1) + pw.
  MaskEdgeFillScratch local;
  MaskEdgeFillScratch& work = scratch ? *scratch : local;
  const int pw = w + 2;
  work.open.assign(static_cast<size_t>(pw) * static_cast<size_t>(h + 2), 0);
  uint8_t* open = work.open.data();
  bool any_open = false;
  for (int v = 0; v < h; ++v) {
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(w);
    uint8_t* open_row = open + static_cast<size_t>(v + 1) * pw + 1;
    // Masks are piecewise constant along a row: the last id's verdict is reused.
    int32_t last_id = 0;
    bool last_known = false;
    for (int u = 0; u < w; ++u) {
      const size_t i = row + static_cast<size_t>(u);
      if (label[i] != 0 || d[i] == 0) continue;
      const int32_t id = mask[i];
      if (id != last_id) last_id = id, last_known = known.contains(id);
      if (last_known) open_row[u] = 1, any_open = true;
    }
  }
  if (!any_open) return 0;
  // Sources, in pixel order: labelled pixels of a known mask next to an open pixel of the same
  // mask (one with none can give nothing: the fill moves through open pixels only).
  work.queue.clear();
  for (int v = 0; v < h; ++v) {
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(w);
    const uint8_t* open_row = open + static_cast<size_t>(v + 1) * pw + 1;
    for (int u = 0; u < w; ++u) {
      // Most pixels have no open neighbour at all: four byte loads rule them out.
      if (!(open_row[u - 1] | open_row[u + 1] | open_row[u - pw] | open_row[u + pw])) continue;
      const size_t k = row + static_cast<size_t>(u);
      if (label[k] <= 0) continue;
      const int32_t m = mask[k];
      if (((open_row[u - 1] && mask[k - 1] == m) || (open_row[u + 1] && mask[k + 1] == m) ||
           (open_row[u - pw] && mask[k - w] == m) || (open_row[u + pw] && mask[k + w] == m)) &&
          known.contains(m)) {
        work.queue.push_back(
            {static_cast<int32_t>(k), static_cast<int32_t>(k + 2 * v + 1 + pw), 0});
      }
    }
  }
  const float step = static_cast<float>(config.max_depth_step);
  int64_t filled = 0;
  for (size_t head = 0; head < work.queue.size(); ++head) {
    const MaskEdgeFillScratch::Item item = work.queue[head];
    const int32_t next_steps = item.steps + 1;
    if (config.max_distance_px > 0 && next_steps > config.max_distance_px) continue;
    const int32_t i = item.pixel, p = item.padded;
    const float di = static_cast<float>(d[i]);
    const int32_t mi = mask[i], li = label[i];
    auto reach = [&](int32_t j, int32_t q) {
      if (!open[q] || mask[j] != mi) return;
      const float dj = static_cast<float>(d[j]);
      if (std::fabs(dj - di) > step * std::min(di, dj)) return;
      open[q] = 0;
      label[j] = li;
      ++filled;
      work.queue.push_back({j, q, next_steps});
    };
    reach(i - 1, p - 1);
    reach(i + 1, p + 1);
    reach(i - w, p - pw);
    reach(i + w, p + pw);
  }
  return filled;
}

}  // namespace panmap
