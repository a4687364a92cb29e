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

namespace {

// The fill over image rows [window_begin, window_end) as if the image had no other rows; labels
// are only read. Leaves in band->queue every source and every pixel it filled, with its label.
void fillWindow(const uint16_t* d, const int32_t* mask, const int32_t* label,
                const KnownSegments& known, int w, int window_begin, int window_end,
                const MaskEdgeFillConfig& config, MaskEdgeFillScratch::Band* band) {
  // Pixels a fill may reach (in a known mask, with depth, without a label), on a grid one pixel
  // wider on every side whose border is never open: a neighbour is tested without bounds checks
  // and without dividing an index back into (u, v). Pixel (u, v) sits at
  // p = (v - window_begin + 1) pw + u + 1.
  const int pw = w + 2;
  band->open.assign(static_cast<size_t>(pw) * static_cast<size_t>(window_end - window_begin + 2),
                    0);
  band->queue.clear();
  uint8_t* open = band->open.data();
  bool any_open = false;
  for (int v = window_begin; v < window_end; ++v) {
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(w);
    uint8_t* open_row = open + static_cast<size_t>(v - window_begin + 1) * pw + 1;
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
  if (!any_open) return;
  // Sources, in pixel order: labelled pixels of a known mask next to an open pixel of the same
  // mask (one with none can give nothing: the fill moves through open pixels only).
  for (int v = window_begin; v < window_end; ++v) {
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(w);
    const int32_t padded_row = (v - window_begin + 1) * pw + 1;
    const uint8_t* open_row = open + padded_row;
    for (int u = 0; u < w; ++u) {
      // Most pixels have no open neighbour at all: four byte loads rule them out.
      if (!(open_row[u - 1] | open_row[u + 1] | open_row[u - pw] | open_row[u + pw])) continue;
      const size_t k = row + static_cast<size_t>(u);
      if (label[k] <= 0) continue;
      const int32_t m = mask[k];
      if (((open_row[u - 1] && mask[k - 1] == m) || (open_row[u + 1] && mask[k + 1] == m) ||
           (open_row[u - pw] && mask[k - w] == m) || (open_row[u + pw] && mask[k + w] == m)) &&
          known.contains(m)) {
        band->queue.push_back({static_cast<int32_t>(k), padded_row + u, 0, label[k]});
      }
    }
  }
  const float step = static_cast<float>(config.max_depth_step);
  std::vector<MaskEdgeFillScratch::Item>& queue = band->queue;
  for (size_t head = 0; head < queue.size(); ++head) {
    const MaskEdgeFillScratch::Item item = queue[head];
    const int32_t next_steps = item.steps + 1;
    if (config.max_distance_px > 0 && next_steps > config.max_distance_px) continue;
    const int32_t i = item.pixel, p = item.padded;
    const float di = static_cast<float>(d[i]);
    const int32_t mi = mask[i];
    auto reach = [&](int32_t j, int32_t q) {
      if (!open[q] || mask[j] != mi) return;
      const float dj = static_cast<float>(d[j]);
      if (std::fabs(dj - di) > step * std::min(di, dj)) return;
      open[q] = 0;
      queue.push_back({j, q, next_steps, item.label});
    };
    reach(i - 1, p - 1);
    reach(i + 1, p + 1);
    reach(i - w, p - pw);
    reach(i + w, p + pw);
  }
}

}  // namespace

int64_t fillMaskEdges(const DepthImage& depth, const PanopticFrame& masks,
                      const MaskEdgeFillConfig& config, LabelImage* labels,
                      MaskEdgeFillScratch* scratch, ThreadPool* pool) {
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
  MaskEdgeFillScratch local;
  MaskEdgeFillScratch& work = scratch ? *scratch : local;
  // Bands of rows, each filled over its rows and `margin` rows on either side. A pixel filled
  // at step k <= D = max_distance_px takes its label down a chain of k pixels from a source;
  // the chain, the chains it competes with for the pixel (first in queue order wins) and their
  // sources all lie within k rows of it (a pixel j steps down a chain is at most k - j rows
  // away, and its source at most j rows further), and whether a pixel is a source depends on
  // its neighbours: D + 1 rows decide every label of the band. Without a limit on the
  // distance, one band.
  const int bands = pool && config.max_distance_px > 0 ? std::min(pool->size(), h) : 1;
  const int margin = config.max_distance_px + 1;
  work.bands.resize(static_cast<size_t>(bands));
  auto bandRows = [h, bands](int b) {
    return static_cast<int>(static_cast<int64_t>(h) * b / bands);
  };
  auto fillBand = [&](int b) {
    fillWindow(d, mask, label, known, w, std::max(0, bandRows(b) - margin),
               std::min(h, bandRows(b + 1) + margin), config, &work.bands[static_cast<size_t>(b)]);
  };
  // The labels are written once every band is filled: the windows overlap.
  auto writeBand = [&](int b) {
    const int64_t lo = static_cast<int64_t>(bandRows(b)) * w;
    const int64_t hi = static_cast<int64_t>(bandRows(b + 1)) * w;
    int64_t filled = 0;
    for (const MaskEdgeFillScratch::Item& item : work.bands[static_cast<size_t>(b)].queue) {
      if (item.steps == 0 || item.pixel < lo || item.pixel >= hi) continue;
      label[item.pixel] = item.label;
      ++filled;
    }
    return filled;
  };
  if (bands == 1) {
    fillBand(0);
    return writeBand(0);
  }
  std::vector<int64_t> filled(static_cast<size_t>(bands), 0);
  pool->parallelFor(static_cast<size_t>(bands), [&](size_t b0, size_t b1, int) {
    for (size_t b = b0; b < b1; ++b) fillBand(static_cast<int>(b));
  });
  pool->parallelFor(static_cast<size_t>(bands), [&](size_t b0, size_t b1, int) {
    for (size_t b = b0; b < b1; ++b) filled[b] = writeBand(static_cast<int>(b));
  });
  int64_t total = 0;
  for (const int64_t f : filled) total += f;
  return total;
}

}  // namespace panmap
