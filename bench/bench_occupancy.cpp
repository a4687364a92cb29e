// Occupancy update cost: one 640x480 frame of procedural room 1 (noisy depth, survey
// trajectory) integrated into a 5 cm OccupancyMap that already holds the frames before it,
// on one core, for pixel strides 2, 4 (the default) and 8. Counters: per-frame median wall
// and thread-CPU time and p95 wall time (ms), hit samples, cells tested and cells updated per
// frame. Then the export after the walk (OcTree construction and serialisation) with the
// message and .bt sizes. Target: well under 5 ms per frame. For comparison, OctoMap's own
// insertPointCloud on the same frames.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "panmap/occupancy/occupancy_map.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/trajectory.h"

namespace {

struct Walk {
  panmap::PinholeCamera camera{525.0, 525.0, 319.5, 239.5, 640, 480};
  std::vector<panmap::DepthImage> depth;
  std::vector<Eigen::Isometry3d> T_W_C;
};

// 120 frames, every 5th of a 20 s survey, rendered once and shared by the benchmarks.
const Walk& walk() {
  static const Walk w = [] {
    Walk out;
    const panmap::ProceduralRoom room = panmap::generateRoom(1);
    panmap::SurveyConfig survey;
    survey.num_frames = 600;
    const std::vector<panmap::StampedPose> poses = planSurvey(room.mesh, survey, 7);
    const panmap::MeshRenderer renderer(room.mesh);
    panmap::RenderedView view;
    for (size_t k = 0; k < poses.size(); k += 5) {
      renderer.render(out.camera, poses[k].T_W_C, &view);
      out.depth.push_back(panmap::simulateDepth(view, panmap::DepthNoiseConfig(), k));
      out.T_W_C.push_back(poses[k].T_W_C);
    }
    return out;
  }();
  return w;
}

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1))];
}

// Arg: pixel stride (4 is the default).
void BM_IntegrateFrame(benchmark::State& state) {
  const Walk& w = walk();
  panmap::OccupancyMap::Config config;
  config.pixel_stride = static_cast<int>(state.range(0));
  auto map = std::make_unique<panmap::OccupancyMap>(config);
  std::vector<double> ms, cpu_ms;
  size_t k = 0, samples = 0, updates = 0, tested = 0;
  for (auto _ : state) {
    if (k == w.depth.size()) {  // a new walk through the same room: start from an empty map
      state.PauseTiming();
      map = std::make_unique<panmap::OccupancyMap>(config);
      k = 0;
      state.ResumeTiming();
    }
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = threadCpuSeconds();
    const panmap::OccupancyUpdateStats stats =
        map->integrate(w.depth[k], 0.001, w.camera, w.T_W_C[k]);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cpu_ms.push_back((threadCpuSeconds() - cpu_start) * 1e3);
    state.SetIterationTime(seconds);
    ms.push_back(seconds * 1e3);
    tested += stats.cells_tested;
    samples += stats.depth_samples;
    updates += stats.free_updates + stats.occupied_updates;
    ++k;
  }
  state.counters["median_ms"] = percentile(ms, 0.5);
  state.counters["p95_ms"] = percentile(ms, 0.95);
  state.counters["median_cpu_ms"] = percentile(cpu_ms, 0.5);
  state.counters["cells_tested"] = static_cast<double>(tested) / ms.size();
  state.counters["hit_samples"] = static_cast<double>(samples) / ms.size();
  state.counters["cell_updates"] = static_cast<double>(updates) / ms.size();
}
BENCHMARK(BM_IntegrateFrame)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->UseManualTime()
    ->Iterations(240)
    ->Unit(benchmark::kMillisecond);

// The same frames through OctoMap's own ray casting (insertPointCloud, discretised, max range
// 3.5 m) at the same pixel stride: what OccupancyMap replaces. Arg: pixel stride.
void BM_OctomapInsertPointCloud(benchmark::State& state) {
  const Walk& w = walk();
  const int stride = static_cast<int>(state.range(0));
  auto tree = std::make_unique<octomap::OcTree>(0.05);
  std::vector<double> ms;
  size_t k = 0;
  for (auto _ : state) {
    if (k == w.depth.size()) {
      state.PauseTiming();
      tree = std::make_unique<octomap::OcTree>(0.05);
      k = 0;
      state.ResumeTiming();
    }
    const auto start = std::chrono::steady_clock::now();
    octomap::Pointcloud cloud;
    const panmap::DepthImage& depth = w.depth[k];
    for (int v = 0; v < depth.height(); v += stride) {
      for (int u = 0; u < depth.width(); u += stride) {
        const double z = 0.001 * depth(u, v);
        if (z < 0.1 || z > 3.5) continue;
        const Eigen::Vector3d p_W =
            w.T_W_C[k] * Eigen::Vector3d((u - w.camera.cx) * z / w.camera.fx,
                                         (v - w.camera.cy) * z / w.camera.fy, z);
        cloud.push_back(static_cast<float>(p_W.x()), static_cast<float>(p_W.y()),
                        static_cast<float>(p_W.z()));
      }
    }
    const Eigen::Vector3d o = w.T_W_C[k].translation();
    tree->insertPointCloud(cloud, octomap::point3d(o.x(), o.y(), o.z()), 3.5, false, true);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(seconds);
    ms.push_back(seconds * 1e3);
    ++k;
  }
  state.counters["median_ms"] = percentile(ms, 0.5);
  state.counters["p95_ms"] = percentile(ms, 0.95);
}
BENCHMARK(BM_OctomapInsertPointCloud)
    ->Arg(4)
    ->Arg(8)
    ->UseManualTime()
    ->Iterations(120)
    ->Unit(benchmark::kMillisecond);

// Export after the whole walk: OcTree construction and the PANMAP_OCTOMAP data.
void BM_ExportBinaryData(benchmark::State& state) {
  const Walk& w = walk();
  panmap::OccupancyMap map;
  for (size_t k = 0; k < w.depth.size(); ++k) {
    map.integrate(w.depth[k], 0.001, w.camera, w.T_W_C[k]);
  }
  size_t bytes = 0;
  for (auto _ : state) {
    const std::string data = map.toBinaryData();
    bytes = data.size();
    benchmark::DoNotOptimize(data.data());
  }
  state.counters["data_bytes"] = static_cast<double>(bytes);
  state.counters["bt_bytes"] = static_cast<double>(map.toBtBytes().size());
  state.counters["grid_bytes"] = static_cast<double>(map.grid().memoryBytes());
}
BENCHMARK(BM_ExportBinaryData)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
