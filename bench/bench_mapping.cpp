// Per-frame mapping cost over a real RGB-D sequence: segmentation (III-A) + super-points
// (III-B) + label-TSDF integration, median and p95 per stage, peak memory, bytes per voxel.
//   panmap-bench-mapping [--data DIR] [--voxel-size M] [--threads N] [--frames N] [--json FILE]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "panmap/io/dataset_reader.h"
#include "panmap/lcm/offline_mapping.h"
#include "panmap/mapper/mapper.h"

int main(int argc, char** argv) {
  CLI::App app{"Time the mapping pipeline (no network) on every frame of a dataset folder."};
  std::string data = "../shared/data/7scenes-200", json_path, log_path;
  panmap::MapperConfig config;
  int frames = 0;
  bool markdown = false;
  app.add_option("--data", data, "dataset folder (7-Scenes, ScanNet export or TUM)")
      ->capture_default_str();
  app.add_option("--voxel-size", config.map.voxel_size_m, "metres")->capture_default_str();
  app.add_option("--threads", config.num_threads, "integration threads")->capture_default_str();
  app.add_option("--frames", frames, "frames to map (0 = all)");
  app.add_option("--log", log_path,
                 "map an LCM log instead (with its panoptic masks: adds the graph update)");
  app.add_option("--json", json_path, "write the figures as JSON");
  app.add_flag("--markdown-row", markdown, "print one Markdown table row instead of JSON");
  CLI11_PARSE(app, argc, argv);
  std::map<std::string, double> p95;
  try {
    panmap::Mapper mapper(config);
    std::map<std::string, std::vector<double>> times;
    if (!log_path.empty()) {
      // Timings per stage come from the mapper; message decoding is not counted.
      panmap::SessionOptions options;
      options.max_frames = frames;
      const panmap::OfflineReport report = panmap::mapLog(log_path, options, &mapper);
      for (const auto& [stage, t] : report.timings) {
        times[stage] = {t.median_ms};
        p95[stage] = t.p95_ms;
      }
      data = log_path;
    } else {
      const auto reader = panmap::openDataset(data, panmap::DatasetOptions{});
      const size_t n = frames > 0 ? std::min<size_t>(frames, reader->size()) : reader->size();
      // Decode everything first: the benchmark times mapping, not JPEG/PNG decoding.
      std::vector<panmap::DatasetFrame> input;
      for (size_t i = 0; i < n; ++i) input.push_back(reader->read(i));
      for (const panmap::DatasetFrame& f : input) {
        if (!f.T_W_C) continue;
        const panmap::FrameStats s = mapper.integrate(f.rgbd, *f.T_W_C, nullptr);
        for (const auto& [stage, ms] : s.stageTimes()) times[stage].push_back(ms);
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    const panmap::LabelledMesh mesh = mapper.extractMesh();
    const double mesh_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    struct rusage usage;
    getrusage(RUSAGE_SELF, &usage);
    const size_t voxels = mapper.map().numBlocks() * panmap::kBlockVoxels;
    nlohmann::json out = {
        {"data", data},
        {"frames", times["total"].size()},
        {"voxel_size_m", config.map.voxel_size_m},
        {"threads", config.num_threads},
        {"blocks", mapper.map().numBlocks()},
        {"voxels", voxels},
        {"bytes_per_voxel", static_cast<double>(mapper.map().memoryBytes()) / voxels},
        {"map_bytes", mapper.map().memoryBytes()},
        {"peak_rss_bytes", static_cast<size_t>(usage.ru_maxrss) * 1024},
        {"final_mesh_ms", mesh_ms},
        {"mesh_vertices", mesh.numVertices()}};
    for (auto& [stage, list] : times) {
      panmap::StageTiming t = panmap::summariseTimes(list);
      if (p95.count(stage)) t.p95_ms = p95[stage];  // from a log run: summarised already
      out["stages"][stage] = {{"median_ms", t.median_ms}, {"p95_ms", t.p95_ms}};
    }
    out["frames"] = mapper.framesIntegrated();
    if (markdown) {
      // | voxel | threads | frames | segmentation | super-points | integration | graph |
      // occupancy | total | ...
      auto cell = [&](const char* stage) {
        const auto& t = out["stages"][stage];
        char buf[64];
        std::snprintf(buf, sizeof(buf), "%.1f / %.1f", t["median_ms"].get<double>(),
                      t["p95_ms"].get<double>());
        return std::string(buf);
      };
      std::printf(
          "| %.0f cm | %d | %lld | %s | %s | %s | %s | %s | **%s** | %.0f | %.0f | %.1f |\n",
          config.map.voxel_size_m * 100.0, config.num_threads,
          static_cast<long long>(mapper.framesIntegrated()), cell("segmentation").c_str(),
          cell("superpoints").c_str(), cell("integration").c_str(), cell("graph").c_str(),
          cell("occupancy").c_str(), cell("total").c_str(), mapper.map().memoryBytes() / 1048576.0,
          static_cast<double>(usage.ru_maxrss) / 1024.0,
          static_cast<double>(mapper.map().memoryBytes()) / voxels);
    } else {
      std::printf("%s\n", out.dump(2).c_str());
    }
    if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-mapping: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
