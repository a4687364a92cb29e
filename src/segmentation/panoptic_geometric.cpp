// The per-frame 2D panoptic-geometric segmentation (paper III-A): depth -> normals -> edges ->
// connected components -> geometric segments, fused with the panoptic masks into surfaces.
#include "panmap/segmentation/panoptic_geometric.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "panmap/core/error.h"
#include "panmap/core/fingerprint.h"
#include "panmap/core/thread_pool.h"
#include "panmap/segmentation/internal/depth_edges.h"
#include "panmap/segmentation/internal/depth_geometry.h"
#include "panmap/segmentation/internal/surface_fusion.h"

namespace panmap {

namespace {

constexpr int kMaxThreads = 64;

// The normal estimator's box sums stay exact up to this window (see depth_normals.cpp).
constexpr int kMaxWindowPx = 127;

// Image rows a thread takes at a time for normals and edges: large enough that restarting the
// window sums at each chunk costs little.
constexpr size_t kRowsPerChunk = 48;

void requireOddWindow(int value_px, const char* field) {
  if (value_px < 3 || value_px > kMaxWindowPx || value_px % 2 == 0) {
    throw Error(std::string("DepthSegmentationConfig.") + field +
                " must be odd and in [3, 127], got " + std::to_string(value_px));
  }
}

std::string sizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace

uint64_t DepthSegmentationConfig::key() const {
  Fingerprint f;
  const auto mix = [&f](const auto& value) { f.add(&value, sizeof(value)); };
  mix(normals_window_px);
  mix(min_convexity_window_px);
  mix(min_convexity_threshold);
  mix(depth_discontinuity_ratio);
  mix(min_segment_px);
  mix(max_depth_m);
  return f.value();
}

void DepthSegmentationConfig::check() const {
  requireOddWindow(normals_window_px, "normals_window_px");
  requireOddWindow(min_convexity_window_px, "min_convexity_window_px");
  if (!(min_convexity_threshold >= -1.0f && min_convexity_threshold <= 1.0f)) {
    throw Error("DepthSegmentationConfig.min_convexity_threshold must be in [-1, 1], got " +
                std::to_string(min_convexity_threshold));
  }
  if (!(depth_discontinuity_ratio > 0.0f && depth_discontinuity_ratio < 1.0f)) {
    throw Error("DepthSegmentationConfig.depth_discontinuity_ratio must be in (0, 1), got " +
                std::to_string(depth_discontinuity_ratio));
  }
  if (min_segment_px < 1) {
    throw Error("DepthSegmentationConfig.min_segment_px must be >= 1, got " +
                std::to_string(min_segment_px));
  }
  if (!(max_depth_m > 0.0f && std::isfinite(max_depth_m))) {
    throw Error("DepthSegmentationConfig.max_depth_m must be positive and finite, got " +
                std::to_string(max_depth_m));
  }
  if (num_threads < 1 || num_threads > kMaxThreads) {
    throw Error("DepthSegmentationConfig.num_threads must be in [1, 64], got " +
                std::to_string(num_threads));
  }
}

void SurfaceFusionConfig::check() const {
  if (min_surface_px < 1) {
    throw Error("SurfaceFusionConfig.min_surface_px must be >= 1, got " +
                std::to_string(min_surface_px));
  }
  if (!(stuff_confidence >= 0.0f && stuff_confidence <= 1.0f)) {
    throw Error("SurfaceFusionConfig.stuff_confidence must be in [0, 1], got " +
                std::to_string(stuff_confidence));
  }
  if (!(mask_only_depth_step >= 0.0f) || !std::isfinite(mask_only_depth_step)) {
    throw Error("SurfaceFusionConfig.mask_only_depth_step must be finite and >= 0, got " +
                std::to_string(mask_only_depth_step));
  }
}

struct PanopticGeometricSegmenter::Impl {
  Impl(const DepthSegmentationConfig& depth, const SurfaceFusionConfig& fusion)
      : depth_config(depth),
        fusion_config(fusion),
        config_key(depth.key()),
        pool(depth.num_threads),
        normal_estimators(depth.num_threads),
        edge_scratch(depth.num_threads) {}

  void checkInputs(const RgbdFrame& frame, const PanopticFrame* panoptic) const;
  void geometricSegments(LabelImage* geometric);
  /// The depth stages: normals, edges, components into `geometric` (resized to the depth's).
  void segmentDepth(const RgbdFrame& frame, LabelImage* geometric);

  const DepthSegmentationConfig depth_config;
  const SurfaceFusionConfig fusion_config;
  const uint64_t config_key;
  bool kept_last = false;  ///< the last segment() took kept geometric segments
  ThreadPool pool;
  std::vector<internal::NormalEstimator> normal_estimators;  ///< one per thread
  std::vector<internal::EdgeScratch> edge_scratch;           ///< one per thread
  internal::DepthGeometry geometry;
  internal::EdgeMaps edges;
  internal::SurfaceFuser fuser;
  std::vector<std::vector<int32_t>> component_area_px;     ///< per thread
  std::vector<std::vector<size_t>> component_first_px;     ///< per thread: first pixel index
  std::vector<std::pair<size_t, size_t>> component_order;  ///< (first pixel, component)
  std::vector<int32_t> component_to_segment;
};

void PanopticGeometricSegmenter::Impl::checkInputs(const RgbdFrame& frame,
                                                   const PanopticFrame* panoptic) const {
  std::string why;
  if (!frame.camera.isValid(&why)) throw Error("RgbdFrame.camera: " + why);
  if (frame.depth.width() != frame.camera.width || frame.depth.height() != frame.camera.height) {
    throw Error("RgbdFrame.depth is " + sizeText(frame.depth.width(), frame.depth.height()) +
                ", camera is " + sizeText(frame.camera.width, frame.camera.height));
  }
  if (!(frame.depth_scale_m > 0.0 && std::isfinite(frame.depth_scale_m))) {
    throw Error("RgbdFrame.depth_scale_m must be positive and finite, got " +
                std::to_string(frame.depth_scale_m));
  }
  if (panoptic != nullptr && !fusion_config.geometry_only &&
      (panoptic->segment_ids.width() != frame.depth.width() ||
       panoptic->segment_ids.height() != frame.depth.height())) {
    throw Error("PanopticFrame.segment_ids is " +
                sizeText(panoptic->segment_ids.width(), panoptic->segment_ids.height()) +
                ", depth is " + sizeText(frame.depth.width(), frame.depth.height()));
  }
}

// Connected components (4-connected) of the non-edge pixels; components smaller than
// min_segment_px are dropped and the rest numbered from 1 in raster order of their first
// pixel, so ids do not depend on OpenCV's labelling algorithm or its threads. The counting and
// relabelling passes run on the pool: each thread counts areas and first pixels of its rows,
// and the parts combine exactly (sums and minima).
void PanopticGeometricSegmenter::Impl::geometricSegments(LabelImage* geometric) {
  const int width = geometry.width;
  const int height = geometry.height;
  cv::Mat mask(height, width, CV_8UC1, edges.segmentable.data());
  cv::Mat labels(height, width, CV_32SC1, geometric->data());
  const size_t num_labels = static_cast<size_t>(cv::connectedComponents(mask, labels, 4, CV_32S));
  int32_t* label = geometric->data();
  const size_t n = geometric->size();
  const size_t threads = static_cast<size_t>(pool.size());
  component_area_px.resize(threads);
  component_first_px.resize(threads);
  pool.parallelFor(threads, [&](size_t t0, size_t t1, int) {
    for (size_t t = t0; t < t1; ++t) {
      std::vector<int32_t>& area = component_area_px[t];
      std::vector<size_t>& first = component_first_px[t];
      area.assign(num_labels, 0);
      first.assign(num_labels, n);
      for (size_t i = n * t / threads; i < n * (t + 1) / threads; ++i) {
        const size_t l = static_cast<size_t>(label[i]);
        if (area[l]++ == 0) first[l] = i;
      }
    }
  });
  // Components in raster order of their first pixel; label 0 (edges) stays 0.
  component_order.clear();
  for (size_t l = 1; l < num_labels; ++l) {
    int32_t area = 0;
    size_t first = n;
    for (size_t t = 0; t < threads; ++t) {
      area += component_area_px[t][l];
      first = std::min(first, component_first_px[t][l]);
    }
    if (area >= depth_config.min_segment_px) component_order.emplace_back(first, l);
  }
  std::sort(component_order.begin(), component_order.end());
  component_to_segment.assign(num_labels, 0);
  for (size_t k = 0; k < component_order.size(); ++k) {
    component_to_segment[component_order[k].second] = static_cast<int32_t>(k) + 1;
  }
  const int32_t* to_segment = component_to_segment.data();
  pool.parallelFor(n, [label, to_segment](size_t begin, size_t end, int) {
    for (size_t i = begin; i < end; ++i) label[i] = to_segment[label[i]];
  });
}

PanopticGeometricSegmenter::PanopticGeometricSegmenter(const DepthSegmentationConfig& depth_config,
                                                       const SurfaceFusionConfig& fusion_config) {
  depth_config.check();
  fusion_config.check();
  impl_ = std::make_unique<Impl>(depth_config, fusion_config);
}

PanopticGeometricSegmenter::~PanopticGeometricSegmenter() = default;

FrameSegmentation PanopticGeometricSegmenter::segment(const RgbdFrame& frame,
                                                      const PanopticFrame* panoptic) {
  FrameSegmentation out;
  segment(frame, panoptic, &out);
  return out;
}

void PanopticGeometricSegmenter::Impl::segmentDepth(const RgbdFrame& frame, LabelImage* geometric) {
  const int width = frame.depth.width();
  const int height = frame.depth.height();
  geometry.resize(width, height);
  edges.resize(width, height);

  // Each stage reads its neighbours' rows of the previous one, so the stages are separate
  // parallel loops over bands of rows. The lambdas capture two pointers, which std::function
  // holds without allocating.
  Impl* const self = this;
  const RgbdFrame* const input = &frame;
  pool.parallelFor(height, [self, input](size_t v0, size_t v1, int) {
    internal::backProjectRows(*input, self->depth_config.max_depth_m, static_cast<int>(v0),
                              static_cast<int>(v1), &self->geometry);
  });
  pool.parallelFor(height, [self](size_t v0, size_t v1, int) {
    internal::markDiscontinuityRows(self->depth_config.depth_discontinuity_ratio,
                                    static_cast<int>(v0), static_cast<int>(v1), &self->geometry);
  });
  // Normals and edges cost more where the depth is valid, so rows are handed out in chunks to
  // whichever thread is free; each chunk restarts its window sums, exactly (see
  // depth_normals.cpp), so results do not depend on the split.
  pool.parallelForDynamic(height, kRowsPerChunk, [self](size_t v0, size_t v1, int thread) {
    self->normal_estimators[thread].computeRows(self->depth_config.normals_window_px,
                                                static_cast<int>(v0), static_cast<int>(v1),
                                                &self->geometry);
  });
  pool.parallelForDynamic(height, kRowsPerChunk, [self](size_t v0, size_t v1, int thread) {
    internal::computeEdgeRows(self->geometry, self->depth_config, static_cast<int>(v0),
                              static_cast<int>(v1), &self->edge_scratch[thread], &self->edges);
  });
  // Overwritten whole, so a buffer of the right size is reused as it is.
  if (geometric->width() != width || geometric->height() != height) {
    *geometric = LabelImage(width, height);
  }
  geometricSegments(geometric);
}

void PanopticGeometricSegmenter::segment(const RgbdFrame& frame, const PanopticFrame* panoptic,
                                         FrameSegmentation* out, const GeometricSegments* kept) {
  Impl& impl = *impl_;
  impl.checkInputs(frame, panoptic);
  const int width = frame.depth.width();
  const int height = frame.depth.height();
  impl.kept_last = kept && kept->config_key == impl.config_key && kept->ids.width() == width &&
                   kept->ids.height() == height;
  if (impl.kept_last) {
    out->geometric = kept->ids;
  } else {
    impl.segmentDepth(frame, &out->geometric);
  }
  if (out->surfaces.width() != width || out->surfaces.height() != height) {
    out->surfaces = LabelImage(width, height);
  }
  impl.fuser.fuse(panoptic, impl.fusion_config, out, &impl.pool, &frame.depth);
  out->panoptic = panoptic != nullptr;
}

bool PanopticGeometricSegmenter::keptLast() const { return impl_->kept_last; }

Eigen::Vector3f PanopticGeometricSegmenter::normal(int u, int v) const {
  const internal::DepthGeometry& g = impl_->geometry;
  if (u < 0 || v < 0 || u >= g.width || v >= g.height) {
    throw Error("normal(" + std::to_string(u) + ", " + std::to_string(v) +
                "): pixel outside the last frame (" + sizeText(g.width, g.height) + ")");
  }
  const size_t i = g.index(u, v);
  return Eigen::Vector3f(g.nx[i], g.ny[i], g.nz[i]);
}

const Image<float>& PanopticGeometricSegmenter::minConvexity() const {
  return impl_->edges.min_convexity;
}

const Image<uint8_t>& PanopticGeometricSegmenter::edgeFlags() const { return impl_->edges.flags; }

}  // namespace panmap
