// Cost of the depth calibration per frame (docs/MAPPING.md, "Depth calibration"): correcting a
// 640x480 depth image of 0.5-4 m readings (10 % holes) with a 32 x 24 cell, 9 knot
// calibration, as Mapper::integrate() does to every frame when a calibration is configured.
#include <cmath>
#include <cstdint>
#include <vector>

#include <benchmark/benchmark.h>

#include "panmap/calibration/depth_calibration.h"

namespace {

panmap::RgbdFrame frame() {
  panmap::RgbdFrame f;
  f.camera = panmap::PinholeCamera{585.0, 585.0, 320.0, 240.0, 640, 480};
  f.depth = panmap::DepthImage(640, 480);
  f.color = panmap::ColorImage(640, 480);
  uint32_t state = 12345;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      state = state * 1664525u + 1013904223u;
      if (state % 10 == 0) continue;  // a hole
      f.depth(u, v) = static_cast<uint16_t>(500 + (u * 7 + v * 3 + (state >> 24)) % 3500);
    }
  }
  return f;
}

panmap::DepthCalibration calibration() {
  std::vector<float> offsets(32 * 24 * 9);
  for (size_t i = 0; i < offsets.size(); ++i) offsets[i] = 0.01f * std::sin(0.37 * i);
  return panmap::DepthCalibration(640, 480, 32, 24, 9, 0.5, offsets);
}

// Argument: threads (the mapper passes its pool, 2 threads by default).
void BM_ApplyToFrame(benchmark::State& state) {
  const panmap::RgbdFrame raw = frame();
  const panmap::DepthCalibration k = calibration();
  panmap::ThreadPool pool(static_cast<int>(state.range(0)));
  panmap::RgbdFrame corrected;
  for (auto _ : state) {
    k.apply(raw, &corrected, &pool);
    benchmark::DoNotOptimize(corrected.depth(320, 240));
  }
}
BENCHMARK(BM_ApplyToFrame)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly();

}  // namespace

BENCHMARK_MAIN();
