// Per-frame mapping cost over a real RGB-D sequence or a synthetic log: segmentation (III-A),
// super-points (III-B), label-TSDF integration with votes, graph update (III-C) and occupancy,
// median and p95 per stage; the periodic outputs (incremental mesh update, occupancy tree
// export) timed every --outputs-every frames; peak memory and bytes per voxel.
//   panmap-bench-mapping [--data DIR | --log FILE] [--voxel-size M] [--threads N] [--frames N]
//                        [--outputs-every N] [--json FILE] [--markdown-row] [--mesh-change]
// --mesh-change: how much the blocks an update re-meshes moved since their previous mesh
// (issue 23: which of them a cheaper change test could skip).

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <utility>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "panmap/core/memory_policy.h"
#include "panmap/core/process_memory.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/lcm/offline_mapping.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mesh/marching_cubes.h"

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct BlockLess {
  bool operator()(const panmap::BlockIndex& a, const panmap::BlockIndex& b) const {
    return panmap::blockIndexLess(a, b);
  }
};

// Per-stage samples, plus the periodic outputs a live mapper produces (mesh, octree).
class Recorder {
 public:
  Recorder(panmap::Mapper* mapper, int outputs_every, bool mesh_change)
      : mapper_(mapper), outputs_every_(outputs_every), mesh_change_(mesh_change) {}

  void add(const panmap::FrameStats& s) {
    for (const auto& [stage, ms] : s.stageTimes()) times_[stage].push_back(ms);
    voxels_updated_.push_back(static_cast<double>(s.integration.voxels_updated));
    blocks_in_view_.push_back(static_cast<double>(s.integration.blocks_in_view));
    if (outputs_every_ > 0 && ++frames_ % outputs_every_ == 0) {
      // A live view's update: the blocks changed in the period, labelled. Then the whole
      // labelled mesh (an export), which after the update only assembles stored blocks.
      auto start = Clock::now();
      const panmap::MeshUpdate update = mapper_->updateMesh();
      times_["mesh_update"].push_back(msSince(start));
      blocks_remeshed_.push_back(static_cast<double>(update.blocks.size()));
      if (mesh_change_) compareWithPrevious(update);
      start = Clock::now();
      mapper_->extractMesh();
      times_["whole_mesh"].push_back(msSince(start));
      if (mapper_->occupancy()) {
        start = Clock::now();
        const std::string tree = mapper_->occupancy()->toBinaryData();
        times_["octree_export"].push_back(msSince(start));
      }
    }
  }

  nlohmann::json summary() const {
    nlohmann::json out;
    for (const auto& [stage, list] : times_) {
      const panmap::StageTiming t = panmap::summariseTimes(list);
      out["stages"][stage] = {{"median_ms", t.median_ms}, {"p95_ms", t.p95_ms}};
    }
    out["heap_huge_pages"] = panmap::heapUsesHugePages();
    out["voxels_updated_median"] = panmap::summariseTimes(voxels_updated_).median_ms;
    out["blocks_in_view_median"] = panmap::summariseTimes(blocks_in_view_).median_ms;
    out["blocks_remeshed_median"] = panmap::summariseTimes(blocks_remeshed_).median_ms;
    if (mesh_change_) {
      // Shares of all re-meshed blocks over every update after the first.
      double total = 0.0;
      for (const auto& [kind, n] : change_counts_) total += n;
      for (const auto& [kind, n] : change_counts_) {
        out["mesh_change"][kind] = total > 0.0 ? n / total : 0.0;
      }
      out["mesh_change"]["blocks"] = total;
    }
    return out;
  }

 private:
  // Sorts each re-meshed block that had a mesh before by how far its new mesh moved: the
  // same faces with every vertex within 0.5, 1 or 2 mm (same labels or not), farther, or other
  // faces.
  void compareWithPrevious(const panmap::MeshUpdate& update) {
    for (size_t i = 0; i < update.blocks.size(); ++i) {
      const panmap::LabelledMesh now = update.mesh(i);
      auto it = previous_.find(update.blocks[i]);
      if (it != previous_.end()) {
        const panmap::LabelledMesh& before = it->second;
        std::string kind = "faces_changed";
        if (before.faces == now.faces && before.vertices.size() == now.vertices.size()) {
          kind = "moved_over_2mm";
          float moved_m = 0.0f;
          for (size_t v = 0; v < now.vertices.size(); ++v) {
            moved_m = std::max(moved_m, (now.vertices[v] - before.vertices[v]).norm());
          }
          const bool same_labels = before.semantic == now.semantic &&
                                   before.instance == now.instance &&
                                   before.superpoint == now.superpoint;
          if (moved_m < 0.0005f) {
            kind = same_labels ? "within_0.5mm" : "within_0.5mm_labels_changed";
          } else if (moved_m < 0.001f) {
            kind = same_labels ? "within_1mm" : "within_1mm_labels_changed";
          } else if (moved_m < 0.002f) {
            kind = same_labels ? "within_2mm" : "within_2mm_labels_changed";
          }
        }
        change_counts_[kind] += 1.0;
        it->second = now;
      } else {
        previous_.emplace(update.blocks[i], now);
      }
    }
  }

  panmap::Mapper* mapper_;
  int outputs_every_;
  int frames_ = 0;
  std::map<std::string, std::vector<double>> times_;
  std::vector<double> voxels_updated_, blocks_in_view_, blocks_remeshed_;
  bool mesh_change_ = false;
  std::map<panmap::BlockIndex, panmap::LabelledMesh, BlockLess> previous_;
  std::map<std::string, double> change_counts_;
};

}  // namespace

int main(int argc, char** argv) {
  panmap::applyMemoryPolicy(argv);  // panmap-mapper's allocation policy
  CLI::App app{"Time the mapping pipeline (no network) on every frame of a dataset or log."};
  std::string data = "../shared/data/7scenes-200", json_path, log_path, config_path;
  panmap::MapperConfig config;
  int frames = 0, outputs_every = 30;
  bool markdown = false, slam = false, mesh_change = false;
  app.add_option("--data", data, "dataset folder (7-Scenes, ScanNet export or TUM)")
      ->capture_default_str();
  app.add_option("--config", config_path,
                 "mapper YAML config, applied first (--voxel-size and --threads override it)");
  app.add_option("--voxel-size", config.map.voxel_size_m, "metres")->capture_default_str();
  app.add_option("--threads", config.num_threads, "mapping threads")->capture_default_str();
  app.add_option("--frames", frames, "frames to map (0 = all)");
  app.add_option("--log", log_path,
                 "map an LCM log instead (with its panoptic masks: adds the graph update)");
  app.add_option("--outputs-every", outputs_every,
                 "frames between incremental mesh updates and occupancy exports, timed on their "
                 "own (0 = none)")
      ->capture_default_str();
  app.add_flag("--slam-poses", slam,
               "flag the dataset's poses as SLAM poses and skip auto's depth check, so that "
               "tracking refines each against the map and its stage is timed");
  app.add_flag("--mesh-change", mesh_change,
               "report how far the blocks each mesh update re-meshes moved since their previous "
               "mesh (slower: keeps every block's mesh)");
  app.add_option("--json", json_path, "write the figures as JSON");
  app.add_flag("--markdown-row", markdown, "print one Markdown table row instead of JSON");
  CLI11_PARSE(app, argc, argv);
  try {
    if (!config_path.empty()) {
      const float voxel_m = config.map.voxel_size_m;
      const int threads = config.num_threads;
      config = panmap::loadConfig(config_path).mapper;
      if (app.count("--voxel-size")) config.map.voxel_size_m = voxel_m;
      if (app.count("--threads")) config.num_threads = threads;
    }
    // Timing refinement means refining every frame: auto's depth check would stop it on an
    // uncalibrated sensor after its 30 frames.
    if (slam) config.depth_check.frames = 0;
    panmap::Mapper mapper(config);
    Recorder recorder(&mapper, outputs_every, mesh_change);
    if (!log_path.empty()) {
      // Messages are decoded between frames; only the mapper's own stages are timed.
      panmap::SessionOptions options;
      options.max_frames = frames;
      panmap::mapLog(
          log_path, options, &mapper, {},
          [&](const panmap::SyncedFrame&, const panmap::FrameStats& s) { recorder.add(s); });
      data = log_path;
    } else {
      const auto reader = panmap::openDataset(data, panmap::DatasetOptions{});
      const size_t n = frames > 0 ? std::min<size_t>(frames, reader->size()) : reader->size();
      // Decode everything first: the benchmark times mapping, not JPEG/PNG decoding.
      std::vector<panmap::DatasetFrame> input;
      for (size_t i = 0; i < n; ++i) input.push_back(reader->read(i));
      for (const panmap::DatasetFrame& f : input) {
        if (f.T_W_C) {
          recorder.add(
              mapper.integrate(f.rgbd, *f.T_W_C, nullptr,
                               slam ? panmap::PoseSource::kSlam : panmap::PoseSource::kUnknown));
        }
      }
    }
    const auto start = Clock::now();
    const panmap::LabelledMesh mesh = mapper.extractMesh();
    const double mesh_ms = msSince(start);
    const size_t peak_rss = panmap::peakResidentBytes();
    const size_t voxels = mapper.map().numBlocks() * panmap::kBlockVoxels;
    nlohmann::json out = recorder.summary();
    out.update({{"data", data},
                {"frames", mapper.framesIntegrated()},
                {"voxel_size_m", config.map.voxel_size_m},
                {"threads", config.num_threads},
                {"outputs_every", outputs_every},
                {"blocks", mapper.map().numBlocks()},
                {"voxels", voxels},
                {"bytes_per_voxel", static_cast<double>(mapper.map().memoryBytes()) / voxels},
                {"map_bytes", mapper.map().memoryBytes()},
                {"peak_rss_bytes", peak_rss},
                {"final_mesh_ms", mesh_ms},
                {"mesh_vertices", mesh.numVertices()}});
    if (markdown) {
      // | voxel | threads | frames | segmentation | super-points | integration | graph |
      // occupancy | total | mesh update | whole mesh | octree export | map MB | peak RSS MB |
      // bytes / voxel |
      auto cell = [&](const char* stage) {
        if (!out["stages"].contains(stage)) return std::string("-");
        const auto& t = out["stages"][stage];
        char buf[64];
        std::snprintf(buf, sizeof(buf), "%.1f / %.1f", t["median_ms"].get<double>(),
                      t["p95_ms"].get<double>());
        return std::string(buf);
      };
      std::printf(
          "| %.0f cm | %d | %lld | %s | %s | %s | %s | %s | **%s** | %s | %s | %s | %.0f | %.0f | "
          "%.1f |\n",
          config.map.voxel_size_m * 100.0, config.num_threads,
          static_cast<long long>(mapper.framesIntegrated()), cell("segmentation").c_str(),
          cell("superpoints").c_str(), cell("integration").c_str(), cell("graph").c_str(),
          cell("occupancy").c_str(), cell("total").c_str(), cell("mesh_update").c_str(),
          cell("whole_mesh").c_str(), cell("octree_export").c_str(),
          mapper.map().memoryBytes() / 1048576.0, peak_rss / 1048576.0,
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
