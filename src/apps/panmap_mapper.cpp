// panmap-mapper: the mapping process. Offline mode (--log) maps every frame of an LCM log as
// fast as it can, runs the final optimisation in-process and writes the outputs; the live
// LCM mode arrives with roadmap issue 5.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "panmap/core/error.h"
#include "panmap/core/progress.h"
#include "panmap/io/image_codec.h"
#include "panmap/graph/optimiser.h"
#include "panmap/lcm/offline_mapping.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mesh/mesh_export.h"
#include "panmap/sim/overview.h"

namespace {

// Peak resident memory of this process, bytes.
size_t peakRssBytes() {
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<size_t>(usage.ru_maxrss) * 1024;
}

panmap::LabelledMesh recoloured(const panmap::LabelledMesh& mesh, panmap::Rgb8 (*colour)(int32_t),
                                const std::vector<int32_t>& ids) {
  panmap::LabelledMesh out = mesh;
  out.colors.resize(mesh.vertices.size());
  for (size_t i = 0; i < ids.size(); ++i) out.colors[i] = colour(ids[i]);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "panmap mapping process. Offline: maps an LCM log (CAMERA_RGBD, CAMERA_POSE, "
      "PANOPTIC) and writes mesh_{semantic,instance,superpoint}.ply, map.panmap, "
      "report.json and snapshot PNGs into --out."};
  std::string log_path, out_dir, load_path, config_path;
  panmap::MapperConfig config;
  panmap::OfflineOptions options;
  bool quiet = false, geometry_only = false, spatial_only = false, no_snapshots = false;
  bool no_regularise = false, no_refine = false, print_config = false;
  app.add_option("--log", log_path, "LCM log to map offline");
  app.add_option("--out", out_dir, "output folder");
  app.add_option("--config", config_path,
                 "YAML config (see --print-config); command-line flags override it");
  app.add_flag("--print-config", print_config, "print the full default config and exit");
  app.add_option("--voxel-size", config.map.voxel_size_m, "voxel edge, metres")
      ->capture_default_str();
  app.add_option("--threads", config.num_threads, "integration threads")->capture_default_str();
  app.add_option("--max-frames", options.max_frames, "stop after N integrated frames (0 = all)");
  app.add_flag("--geometry-only", geometry_only, "ignore panoptic masks (ablation)");
  app.add_flag("--spatial-only", spatial_only,
               "merge super-points without the semantic consistency check (ablation, Voxblox++)");
  app.add_flag("--no-regularise", no_regularise,
               "skip the semantic regularisation (ablation, w/o III-C)");
  app.add_flag("--no-refine", no_refine, "skip the instance refinement (ablation, w/o III-D)");
  app.add_option("--load", load_path, "resume from a map.panmap snapshot");
  app.add_option("--channel-rgbd", options.channel_rgbd)->capture_default_str();
  app.add_option("--channel-pose", options.channel_pose)->capture_default_str();
  app.add_option("--channel-panoptic", options.channel_panoptic)->capture_default_str();
  app.add_flag("--no-snapshots", no_snapshots, "skip the overview PNGs");
  app.add_flag("-q,--quiet", quiet, "no progress line");
  CLI11_PARSE(app, argc, argv);

  try {
    panmap::PanmapConfig file_config;
    if (print_config) {
      std::printf("%s", panmap::configToYaml(file_config).c_str());
      return 0;
    }
    if (log_path.empty() || out_dir.empty()) throw panmap::Error("--log and --out are required");
    if (!config_path.empty()) {
      file_config = panmap::loadConfig(config_path);
      // Flags given on the command line win over the file.
      if (app.count("--voxel-size") == 0) config.map.voxel_size_m = file_config.mapper.map.voxel_size_m;
      if (app.count("--threads") == 0) config.num_threads = file_config.mapper.num_threads;
      const float voxel = config.map.voxel_size_m;
      const int threads = config.num_threads;
      config = file_config.mapper;
      config.map.voxel_size_m = voxel;
      config.num_threads = threads;
    }
    if (geometry_only) config.fusion.geometry_only = true;
    if (spatial_only) config.superpoints.semantic_consistency = false;
    config.superpoints.semantic_consistency = !spatial_only;
    std::unique_ptr<panmap::Mapper> mapper = load_path.empty()
                                                 ? std::make_unique<panmap::Mapper>(config)
                                                 : panmap::Mapper::load(load_path);
    std::filesystem::create_directories(out_dir);
    panmap::ProgressLine progress("map", "MiB", !quiet);
    const panmap::OfflineReport report = panmap::mapLog(
        log_path, options, mapper.get(),
        [&](size_t done, size_t total) { progress.update(done >> 20, total >> 20); });
    progress.finish();

    // The final optimisation, in-process (the live mode asks panmap-optimizer over LCM).
    const auto optimise_start = std::chrono::steady_clock::now();
    const panmap::SuperpointGraph graph = mapper->graph();
    panmap::OptimiserConfig optimiser = file_config.optimiser;
    if (no_regularise) optimiser.regularise = false;
    if (no_refine) optimiser.refine = false;
    const panmap::GraphLabels labels = panmap::optimise(graph, optimiser);
    const double optimise_ms = std::chrono::duration<double, std::milli>(
                                   std::chrono::steady_clock::now() - optimise_start)
                                   .count();
    const panmap::LabelledMesh mesh = mapper->extractMesh(&labels);
    std::set<int32_t> instances_in_mesh;
    for (int32_t id : mesh.instance) {
      if (id > 0) instances_in_mesh.insert(id);
    }
    panmap::writeLabelledMeshes(out_dir, mesh);
    mapper->save(out_dir + "/map.panmap");
    if (!no_snapshots && !mesh.faces.empty()) {
      panmap::writeFileBytes(out_dir + "/snapshot_semantic.png",
                             panmap::encodePng(panmap::renderOverview(
                                 recoloured(mesh, &panmap::semanticColor, mesh.semantic))));
      panmap::writeFileBytes(out_dir + "/snapshot_instance.png",
                             panmap::encodePng(panmap::renderOverview(
                                 recoloured(mesh, &panmap::idColor, mesh.instance))));
      panmap::writeFileBytes(out_dir + "/snapshot_superpoint.png",
                             panmap::encodePng(panmap::renderOverview(
                                 recoloured(mesh, &panmap::idColor, mesh.superpoint))));
      panmap::writeFileBytes(out_dir + "/snapshot_color.png",
                             panmap::encodePng(panmap::renderOverview(mesh)));
    }

    nlohmann::json timings;
    for (const auto& [stage, t] : report.timings)
      timings[stage] = {{"median_ms", t.median_ms}, {"p95_ms", t.p95_ms}};
    const nlohmann::json json = {
        {"log", log_path},
        {"events", report.events},
        {"frames_integrated", report.frames_integrated},
        {"frames_total", mapper->framesIntegrated()},
        {"rejected", report.rejected},
        {"geometry_only_frames", report.sync.geometry_only},
        {"unmatched_panoptic", report.sync.unmatched_panoptic},
        {"timings", timings},
        {"wall_s", report.wall_s},
        {"memory",
         {{"map_bytes", mapper->map().memoryBytes()},
          {"peak_rss_bytes", peakRssBytes()},
          {"blocks", mapper->map().numBlocks()},
          {"voxels", mapper->map().numBlocks() * panmap::kBlockVoxels}}},
        {"superpoints", mapper->superpoints().states().size()},
        {"superpoint_merges", mapper->superpoints().merges().size()},
        {"instances_frame_counting", mapper->superpoints().numInstances()},
        {"instances_in_mesh", instances_in_mesh.size()},
        {"vote_evictions", mapper->voteEvictions()},
        {"graph", {{"vertices", graph.vertices.size()}, {"edges", graph.edges.size()},
                   {"optimise_ms", optimise_ms}, {"solve_ms", labels.solve_ms},
                   {"regularise", optimiser.regularise}, {"refine", optimiser.refine}}},
        {"mesh", {{"vertices", mesh.numVertices()}, {"faces", mesh.numFaces()}}},
        {"config",
         {{"voxel_size_m", mapper->config().map.voxel_size_m},
          {"truncation_voxels", mapper->config().integrator.truncation_voxels},
          {"geometry_only", mapper->config().fusion.geometry_only},
          {"semantic_consistency", mapper->config().superpoints.semantic_consistency},
          {"merge_threshold", mapper->config().superpoints.merge_threshold},
          {"threads", mapper->config().num_threads}}}};
    std::ofstream(out_dir + "/report.json") << json.dump(2) << "\n";
    // The exact parameters the outputs were made with (a loaded map brings its own).
    std::ofstream(out_dir + "/config.yaml")
        << panmap::configToYaml(panmap::PanmapConfig{mapper->config(), optimiser});
    std::printf(
        "mapped %lld frames in %.1f s (median %.1f ms/frame): %zu super-points, %zu "
        "instances after optimisation, %zu mesh vertices; outputs in %s\n",
        static_cast<long long>(report.frames_integrated), report.wall_s,
        report.timings.count("total") ? report.timings.at("total").median_ms : 0.0,
        mapper->superpoints().states().size(), instances_in_mesh.size(), mesh.numVertices(),
        out_dir.c_str());
    for (const auto& [reason, count] : report.rejected) {
      std::printf("  rejected %lld: %s\n", static_cast<long long>(count), reason.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-mapper: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
