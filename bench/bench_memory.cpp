// Memory over a long run: renders a procedural room along a survey in-process (no log on
// disk), maps every frame and samples the process's resident memory against what the map
// itself holds. On a long walk through one room the map stops growing once the room is seen;
// everything else (scratch buffers, queues, per-frame state) must stay flat with it.
//   panmap-bench-memory [--room N] [--frames N] [--voxel-size M] [--threads N] [--every N]
//                       [--json FILE]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <set>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/process_memory.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/mapper.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/sequence.h"
#include "panmap/sim/trajectory.h"

namespace {

constexpr double kMiB = 1024.0 * 1024.0;

// Median of the times collected since the last sample; empties them.
double takeMedian(std::vector<double>* times) {
  if (times->empty()) return 0.0;
  std::sort(times->begin(), times->end());
  const double median = (*times)[times->size() / 2];
  times->clear();
  return median;
}

// Super-points that still hold a vote in some voxel (the rest only live in the bookkeeping).
size_t superpointsWithVotes(const panmap::Mapper& mapper) {
  std::set<int32_t> labels;
  const panmap::LabelRegistry& registry = mapper.superpoints().labels();
  for (const auto& block : mapper.map().blocks()) {
    for (const panmap::VoxelVotes& votes : block->vote_sets) {
      for (const panmap::LabelVote& vote : votes) {
        if (vote.count > 0) labels.insert(registry.resolve(vote.label));
      }
    }
  }
  return labels.size();
}

}  // namespace

int main(int argc, char** argv) {
  panmap::applyMemoryPolicy(argv);  // panmap-mapper's allocation policy
  CLI::App app{
      "Map a long synthetic walk through one room and report resident memory against the "
      "map's own size every few hundred frames."};
  int room = 1, frames = 3000, every = 250, threads = 2;
  double voxel = 0.02;
  std::string json_path, config_path;
  app.add_option(
      "--config", config_path,
      "YAML config (panmap-mapper --print-config); --voxel-size and --threads override it");
  app.add_option("--room", room, "procedural room seed")->capture_default_str();
  app.add_option("--frames", frames, "frames to map (30 Hz survey)")->capture_default_str();
  app.add_option("--voxel-size", voxel, "metres")->capture_default_str();
  app.add_option("--threads", threads, "mapping threads")->capture_default_str();
  app.add_option("--every", every, "frames between samples")->capture_default_str();
  app.add_option("--json", json_path, "write the samples as JSON");
  CLI11_PARSE(app, argc, argv);
  try {
    if (frames < 1 || every < 1) throw panmap::Error("--frames and --every must be >= 1");
    const panmap::ProceduralRoom layout = panmap::generateRoom(static_cast<uint64_t>(room));
    panmap::SurveyConfig survey;
    survey.num_frames = frames;
    panmap::SynthConfig synth_config;
    synth_config.seed = 1;
    synth_config.poses = panmap::PoseDriftConfig::fromPreset("gt");
    panmap::SequenceSynthesizer synth(layout.mesh, panmap::planSurvey(layout.mesh, survey, 1),
                                      synth_config);
    panmap::MapperConfig config;
    if (!config_path.empty()) config = panmap::loadConfig(config_path).mapper;
    config.map.voxel_size_m = static_cast<float>(voxel);
    config.num_threads = threads;
    panmap::Mapper mapper(config);
    std::fprintf(stderr, "panmap-bench-memory: room %d, %zu frames at %.0f cm, %d threads\n", room,
                 synth.size(), voxel * 100.0, threads);
    std::printf(
        "| frame | resident MiB | TSDF MiB | occupancy MiB | graph MiB | other MiB | blocks | "
        "super-points (with votes) | co-observed pairs | graph edges | graph ms | total ms |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    nlohmann::json samples = nlohmann::json::array();
    const auto start = std::chrono::steady_clock::now();
    std::vector<double> graph_ms, total_ms;  // since the last sample
    for (size_t k = 0; k < synth.size(); ++k) {
      const panmap::SynthFrame f = synth.frame(k);
      const panmap::FrameStats stats =
          mapper.integrate(f.rgbd, f.gt_pose.T_W_C, &f.panoptic, panmap::PoseSource::kGroundTruth);
      graph_ms.push_back(stats.graph_ms);
      total_ms.push_back(stats.total_ms);
      if ((k + 1) % static_cast<size_t>(every) != 0 && k + 1 != synth.size()) continue;
      const size_t rss = panmap::residentBytes();
      const size_t tsdf = mapper.map().memoryBytes();
      const size_t occupancy = mapper.occupancy() ? mapper.occupancy()->grid().memoryBytes() : 0;
      // Super-point graph and bookkeeping: estimated from their table slots and std::map nodes.
      const size_t graph =
          mapper.graphAccumulator().memoryBytes() + mapper.superpoints().memoryBytes();
      const double other = (static_cast<double>(rss) - tsdf - occupancy - graph) / kMiB;
      const size_t with_votes = superpointsWithVotes(mapper);
      const double graph_median_ms = takeMedian(&graph_ms);
      const double total_median_ms = takeMedian(&total_ms);
      std::printf(
          "| %zu | %.1f | %.1f | %.1f | %.1f | %.1f | %zu | %zu (%zu) | %zu | %zu | %.1f | %.1f "
          "|\n",
          k + 1, rss / kMiB, tsdf / kMiB, occupancy / kMiB, graph / kMiB, other,
          mapper.map().numBlocks(), mapper.superpoints().states().size(), with_votes,
          mapper.superpoints().coObservations().size(), mapper.graphAccumulator().numEdges(),
          graph_median_ms, total_median_ms);
      std::fflush(stdout);
      const double elapsed_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "\r  %zu/%zu frames, %.0f s", k + 1, synth.size(), elapsed_s);
      samples.push_back({{"frame", k + 1},
                         {"resident_bytes", rss},
                         {"tsdf_bytes", tsdf},
                         {"occupancy_bytes", occupancy},
                         {"graph_bytes_estimated", graph},
                         {"blocks", mapper.map().numBlocks()},
                         {"superpoints", mapper.superpoints().states().size()},
                         {"superpoints_with_votes", with_votes},
                         {"co_observed_pairs", mapper.superpoints().coObservations().size()},
                         {"graph_edges", mapper.graphAccumulator().numEdges()},
                         {"graph_median_ms", graph_median_ms},
                         {"total_median_ms", total_median_ms}});
    }
    std::fprintf(stderr, "\n");
    if (!json_path.empty()) {
      std::ofstream(json_path) << nlohmann::json{{"room", room},
                                                 {"frames", frames},
                                                 {"voxel_size_m", voxel},
                                                 {"threads", threads},
                                                 {"samples", samples}}
                                      .dump(2)
                               << "\n";
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-memory: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
