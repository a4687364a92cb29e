// Timing of PanopticGeometricSegmenter::segment() on a real 640x480 frame (7-Scenes frame 0,
// fx = fy = 585): issue target <= 12 ms median on one core. Args: threads; masks (a 4 x 4 grid
// of panoptic segments, so the fusion pass does real work); reuse (segment into the same
// FrameSegmentation every frame instead of returning a new one). Run pinned to one core for the
// single-core figures: taskset -c 0 build/panmap-bench-segmentation
#include <cstdlib>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "panmap/io/image_codec.h"
#include "panmap/segmentation/panoptic_geometric.h"

namespace {

std::string depthPath() {
  if (const char* path = std::getenv("PANMAP_BENCH_DEPTH")) return path;
#ifdef PANMAP_DATA_DIR
  return std::string(PANMAP_DATA_DIR) + "/7scenes-200/frame-000000.depth.png";
#else
  return "../shared/data/7scenes-200/frame-000000.depth.png";
#endif
}

// A 4 x 4 grid of segments alternating stuff and things.
panmap::PanopticFrame gridMasks(int width, int height) {
  panmap::PanopticFrame panoptic;
  panoptic.segment_ids = panmap::LabelImage(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      panoptic.segment_ids(u, v) = 1 + 4 * (4 * v / height) + 4 * u / width;
    }
  }
  for (int32_t id = 1; id <= 16; ++id) {
    const bool thing = id % 2 == 0;
    panoptic.segments.push_back({id, thing ? 5 : 1, id, thing, 0.9f});
  }
  return panoptic;
}

void BM_SegmentSevenScenesFrame(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const bool with_masks = state.range(1) != 0;
  const bool reuse = state.range(2) != 0;
  const std::string path = depthPath();
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("no depth image at " + path + " (set PANMAP_BENCH_DEPTH)").c_str());
    return;
  }
  // OpenCV's connected components may use its own threads: give it the same budget.
  cv::setNumThreads(threads);
  panmap::RgbdFrame frame;
  frame.depth = panmap::readDepthFile(path);
  frame.camera =
      panmap::PinholeCamera{585.0, 585.0, 320.0, 240.0, frame.depth.width(), frame.depth.height()};
  frame.depth_scale_m = 0.001;
  const panmap::PanopticFrame masks = gridMasks(frame.depth.width(), frame.depth.height());
  const panmap::PanopticFrame* panoptic = with_masks ? &masks : nullptr;
  panmap::DepthSegmentationConfig config;
  config.num_threads = threads;
  panmap::PanopticGeometricSegmenter segmenter(config, {});
  panmap::FrameSegmentation reused;
  size_t surfaces = 0;
  for (auto _ : state) {
    if (reuse) {
      segmenter.segment(frame, panoptic, &reused);
      surfaces = reused.surface_list.size();
      benchmark::DoNotOptimize(reused.surfaces.data());
    } else {
      const panmap::FrameSegmentation result = segmenter.segment(frame, panoptic);
      surfaces = result.surface_list.size();
      benchmark::DoNotOptimize(result.surfaces.data());
    }
  }
  state.counters["surfaces"] = static_cast<double>(surfaces);
}

BENCHMARK(BM_SegmentSevenScenesFrame)
    ->ArgNames({"threads", "masks", "reuse"})
    ->Args({1, 0, 0})
    ->Args({1, 1, 0})
    ->Args({1, 1, 1})
    ->Args({2, 0, 0})
    ->Args({2, 1, 0})
    ->Args({2, 1, 1})
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(9)
    ->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
