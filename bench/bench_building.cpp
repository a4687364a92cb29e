// A building-sized map: renders a procedural building (>= 20 rooms, >= 1000 m2 by default)
// along its survey in-process, maps every frame with its masks at ground-truth poses, samples
// resident memory against the map and the surface it has observed, then times the final
// optimisation and every output's export (with the export's own peak resident memory).
//   panmap-bench-building [--building SEED] [--voxel-size M] [--threads N] [--every N]
//                         [--frames N] [--out DIR] [--json FILE]

#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "panmap/building/building.h"
#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/process_memory.h"
#include "panmap/graph/optimiser.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mapper/outputs.h"
#include "panmap/sim/sequence.h"

namespace {

constexpr double kMiB = 1024.0 * 1024.0;

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Value of a "Key:   N kB" line of /proc/self/status, bytes (0 when missing).
size_t statusBytes(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size() + 1, key + ":") == 0) {
      return static_cast<size_t>(std::stoull(line.substr(key.size() + 1))) * 1024;
    }
  }
  return 0;
}

// Restarts the kernel's peak-resident counter (VmHWM) at the current resident size.
void resetPeak() { std::ofstream("/proc/self/clear_refs") << "5"; }

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}

// Observed surface: voxels the surface passes through (observed, |sdf| below half a voxel),
// each standing for a voxel face of area. Exact for axis-aligned walls, floors and furniture.
double observedSurfaceM2(const panmap::Mapper& mapper) {
  const double v = mapper.map().voxelSize();
  size_t count = 0;
  for (const auto& block : mapper.map().blocks()) {
    for (const panmap::Voxel& voxel : block->voxels) {
      count += voxel.weight > 0.0f && std::abs(voxel.sdf_m) < 0.5 * v ? 1 : 0;
    }
  }
  return static_cast<double>(count) * v * v;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Map a procedural building along its survey and report per-frame time, resident memory "
      "against the map and the observed surface, the final optimisation and every output's "
      "cost."};
  int64_t seed = 1;
  int every = 250, threads = 2, frames = 0;
  int idle_scan_every = static_cast<int>(panmap::Mapper::kIdleScanEveryFrames);
  double voxel = 0.02;
  std::string json_path, out_dir;
  app.add_option("--building", seed, "building seed")->capture_default_str();
  app.add_option("--voxel-size", voxel, "metres")->capture_default_str();
  app.add_option("--threads", threads, "mapping threads")->capture_default_str();
  app.add_option("--every", every, "frames between samples")->capture_default_str();
  app.add_option("--frames", frames, "map only this many frames (0 = the whole survey)")
      ->capture_default_str();
  app.add_option("--out", out_dir,
                 "write the outputs here (default: a temporary folder, removed afterwards)");
  app.add_option("--json", json_path, "write the samples and costs as JSON");
  app.add_option("--idle-scan-every", idle_scan_every,
                 "refresh the graph's surface scan after every N frames, outside the frame's "
                 "time, as the live mapper does while it waits for the next frame (0: never, "
                 "as offline mapping of a log)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  // As panmap-mapper: the heap on huge pages where the kernel gives them on request, and buffers
  // of 4 MiB and more fresh pages every time, which the final optimisation's timing includes.
  panmap::applyMemoryPolicy(argv);
  try {
    if (every < 1 || frames < 0 || seed < 0 || idle_scan_every < 0) {
      throw panmap::Error("--every must be >= 1, --frames, --building and --idle-scan-every >= 0");
    }
    const auto setup_start = std::chrono::steady_clock::now();
    const panmap::Building building = panmap::generateBuilding(static_cast<uint64_t>(seed));
    std::vector<panmap::StampedPose> walk =
        panmap::planBuildingSurvey(building, panmap::buildingSurveyConfig(), 1);
    if (frames > 0 && static_cast<size_t>(frames) < walk.size()) walk.resize(frames);
    panmap::SynthConfig synth_config;
    synth_config.seed = 1;
    synth_config.poses = panmap::PoseDriftConfig::fromPreset("gt");
    panmap::SequenceSynthesizer synth(building.mesh, walk, synth_config);
    panmap::MapperConfig config;
    config.map.voxel_size_m = static_cast<float>(voxel);
    config.num_threads = threads;
    auto mapper = std::make_unique<panmap::Mapper>(config);
    std::fprintf(stderr,
                 "panmap-bench-building: building %lld: %zu rooms, %.0f m2, %zu triangles; %zu "
                 "frames at %.0f cm, %d threads (setup %.1f s)\n",
                 static_cast<long long>(seed), building.rooms.size(), building.floor_area_m2,
                 building.mesh.numFaces(), synth.size(), voxel * 100.0, threads,
                 msSince(setup_start) / 1000.0);
    // What the benchmark itself holds (the building, its renderer, the survey) before the
    // first frame: the mapper's share of resident memory is what grows beyond it.
    const size_t baseline = panmap::residentBytes();
    std::fprintf(stderr, "  resident before mapping (building, renderer): %.0f MiB\n",
                 baseline / kMiB);
    std::printf(
        "| frame | mapping MiB | map MiB | mapping / map | blocks | observed surface m2 | "
        "super-points | graph edges | frame ms median | frame ms p95 |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n");
    nlohmann::json samples = nlohmann::json::array();
    std::vector<double> window_ms, all_ms, render_ms, idle_ms;
    const auto start = std::chrono::steady_clock::now();
    for (size_t k = 0; k < synth.size(); ++k) {
      const auto render_start = std::chrono::steady_clock::now();
      const panmap::SynthFrame f = synth.frame(k);
      render_ms.push_back(msSince(render_start));
      const panmap::FrameStats stats =
          mapper->integrate(f.rgbd, f.gt_pose.T_W_C, &f.panoptic, panmap::PoseSource::kGroundTruth);
      window_ms.push_back(stats.total_ms);
      all_ms.push_back(stats.total_ms);
      if (idle_scan_every > 0 && (k + 1) % static_cast<size_t>(idle_scan_every) == 0) {
        const auto idle_start = std::chrono::steady_clock::now();
        mapper->refreshSurfaceScan();
        idle_ms.push_back(msSince(idle_start));
      }
      if ((k + 1) % static_cast<size_t>(every) != 0 && k + 1 != synth.size()) continue;
      const size_t rss = panmap::residentBytes();
      const size_t map_bytes =
          mapper->map().memoryBytes() +
          (mapper->occupancy() ? mapper->occupancy()->grid().memoryBytes() : 0) +
          mapper->graphAccumulator().memoryBytes() + mapper->superpoints().memoryBytes();
      const double surface = observedSurfaceM2(*mapper);
      const double median = quantile(window_ms, 0.5), p95 = quantile(window_ms, 0.95);
      window_ms.clear();
      const double mapping = static_cast<double>(rss) - static_cast<double>(baseline);
      std::printf("| %zu | %.1f | %.1f | %.2f | %zu | %.1f | %zu | %zu | %.1f | %.1f |\n", k + 1,
                  mapping / kMiB, map_bytes / kMiB, mapping / std::max<double>(1.0, map_bytes),
                  mapper->map().numBlocks(), surface, mapper->superpoints().states().size(),
                  mapper->graphAccumulator().numEdges(), median, p95);
      std::fflush(stdout);
      std::fprintf(stderr, "\r  %zu/%zu frames, %.0f s", k + 1, synth.size(),
                   msSince(start) / 1000.0);
      samples.push_back({{"frame", k + 1},
                         {"resident_bytes", rss},
                         {"mapping_bytes", rss - std::min(rss, baseline)},
                         {"map_bytes", map_bytes},
                         {"blocks", mapper->map().numBlocks()},
                         {"observed_surface_m2", surface},
                         {"superpoints", mapper->superpoints().states().size()},
                         {"graph_edges", mapper->graphAccumulator().numEdges()},
                         {"frame_ms_median", median},
                         {"frame_ms_p95", p95}});
    }
    std::fprintf(stderr, "\n");

    // The final optimisation as panmap-mapper runs it: graph of the live super-points, solve.
    const long faults_start = panmap::minorPageFaults();
    const auto graph_start = std::chrono::steady_clock::now();
    const panmap::SuperpointGraph graph = mapper->graph();
    const double graph_ms = msSince(graph_start);
    const long faults_graph = panmap::minorPageFaults();
    const auto solve_start = std::chrono::steady_clock::now();
    const panmap::OptimiserConfig optimiser;
    const panmap::GraphLabels labels = panmap::optimise(graph, optimiser);
    const double solve_ms = msSince(solve_start);
    const long faults_solve = panmap::minorPageFaults();

    const bool temporary = out_dir.empty();
    if (temporary) {
      out_dir = (std::filesystem::temp_directory_path() /
                 ("panmap-bench-building-" + std::to_string(::getpid())))
                    .string();
    }
    panmap::OutputOptions export_options;  // as panmap-mapper's end of a session
    export_options.final_export = true;
    const size_t before_export = panmap::residentBytes();
    resetPeak();
    const auto export_start = std::chrono::steady_clock::now();
    const panmap::OutputSummary outputs =
        panmap::writeOutputs(out_dir, mapper.get(), &labels, optimiser, export_options);
    const double export_ms = msSince(export_start);
    const size_t export_peak = statusBytes("VmHWM");
    const size_t map_bytes = mapper->map().memoryBytes();
    nlohmann::json files = nlohmann::json::object();
    for (const std::string& name : outputs.files) {
      files[name] = std::filesystem::file_size(out_dir + "/" + name);
    }
    if (temporary) std::filesystem::remove_all(out_dir);

    std::printf("\n| final step | value |\n|---|---|\n");
    std::printf("| frames mapped | %zu |\n", synth.size());
    std::printf("| frame ms median / p95 (whole run) | %.1f / %.1f |\n", quantile(all_ms, 0.5),
                quantile(all_ms, 0.95));
    std::printf("| rendering ms median (the benchmark's own, not mapping) | %.1f |\n",
                quantile(render_ms, 0.5));
    std::printf("| peak resident MiB (whole run; %.0f of it the benchmark's building) | %.1f |\n",
                baseline / kMiB, panmap::peakResidentBytes() / kMiB);
    std::printf("| TSDF MiB | %.1f |\n", map_bytes / kMiB);
    std::printf("| final graph: vertices / edges | %zu / %zu |\n", graph.vertices.size(),
                graph.edges.size());
    if (idle_scan_every > 0) {
      double idle_total = 0.0;
      for (double v : idle_ms) idle_total += v;
      std::printf(
          "| idle surface-scan refresh every %d frames, ms median / p95 / total (not in frame "
          "time) | %.1f / %.1f / %.0f |\n",
          idle_scan_every, quantile(idle_ms, 0.5), quantile(idle_ms, 0.95), idle_total);
    } else {
      std::printf("| idle surface-scan refresh | none (--idle-scan-every 0) |\n");
    }
    std::printf("| final optimisation ms: graph / solve | %.0f / %.0f |\n", graph_ms, solve_ms);
    std::printf(
        "| final optimisation: pages touched for the first time, graph / solve | %ld / %ld |\n",
        faults_graph - faults_start, faults_solve - faults_graph);
    std::printf("| heap on transparent huge pages (core/memory_policy.h) | %s |\n",
                panmap::heapUsesHugePages() ? "yes" : "no");
    std::printf("| export s (all outputs) | %.1f |\n", export_ms / 1000.0);
    for (const auto& [step, seconds] : outputs.step_seconds) {
      std::printf("| export: %s s | %.2f |\n", step.c_str(), seconds);
    }
    std::printf("| export peak resident MiB (before: %.0f) | %.1f |\n", before_export / kMiB,
                export_peak / kMiB);
    std::printf("| mesh vertices / faces | %zu / %zu |\n", outputs.mesh_vertices,
                outputs.mesh_faces);
    for (const auto& [name, bytes] : files.items()) {
      std::printf("| %s MB | %.1f |\n", name.c_str(), bytes.get<size_t>() / 1e6);
    }
    if (!json_path.empty()) {
      nlohmann::json steps = nlohmann::json::object();
      for (const auto& [step, seconds] : outputs.step_seconds) steps[step] = seconds;
      std::ofstream(json_path)
          << nlohmann::json{{"building", seed},
                            {"rooms", building.rooms.size()},
                            {"floor_area_m2", building.floor_area_m2},
                            {"frames", synth.size()},
                            {"voxel_size_m", voxel},
                            {"threads", threads},
                            {"samples", samples},
                            {"frame_ms_median", quantile(all_ms, 0.5)},
                            {"frame_ms_p95", quantile(all_ms, 0.95)},
                            {"peak_resident_bytes", panmap::peakResidentBytes()},
                            {"baseline_resident_bytes", baseline},
                            {"tsdf_bytes", map_bytes},
                            {"graph_vertices", graph.vertices.size()},
                            {"graph_edges", graph.edges.size()},
                            {"idle_scan_every", idle_scan_every},
                            {"idle_scan_ms", idle_ms},
                            {"graph_ms", graph_ms},
                            {"solve_ms", solve_ms},
                            {"graph_first_touch_pages", faults_graph - faults_start},
                            {"solve_first_touch_pages", faults_solve - faults_graph},
                            {"heap_huge_pages", panmap::heapUsesHugePages()},
                            {"export_ms", export_ms},
                            {"export_steps_s", steps},
                            {"export_peak_resident_bytes", export_peak},
                            {"resident_before_export_bytes", before_export},
                            {"files_bytes", files}}
                 .dump(2)
          << "\n";
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-building: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
