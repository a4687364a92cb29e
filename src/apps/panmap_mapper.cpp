// panmap-mapper: the mapping process. Live (default): subscribes CAMERA_RGBD, CAMERA_POSE and
// PANOPTIC over LCM, maps in a worker thread, publishes status, objects and occupancy, and on
// PANMAP_COMMAND finish (or SIGINT/SIGTERM) asks panmap-optimizer for the final labels and
// writes the outputs. Offline (--log): maps every frame of a log as fast as it can and runs
// the final optimisation in-process; the same log and config give the same outputs.

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <nlohmann/json.hpp>
#include "cli_checks.h"

#include "panmap/command_t.hpp"
#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/process_memory.h"
#include "panmap/core/progress.h"
#include "panmap/graph/optimiser.h"
#include "panmap/io/atomic_file.h"
#include "panmap/io/output_path.h"
#include "panmap/lcm/live_mapper.h"
#include "panmap/lcm/object_conversions.h"
#include "panmap/lcm/offline_mapping.h"
#include "panmap/loop/frame_store.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/graph_json.h"
#include "panmap/mapper/objects.h"
#include "panmap/mapper/outputs.h"
#include "panmap/octomap_t.hpp"
#include "panmap/recovery/autosave.h"
#include "panmap/recovery/resume.h"

namespace {

std::atomic<bool> g_stop{false};
void onSignal(int) { g_stop = true; }

nlohmann::json spreadJson(const panmap::ValueSpread& s) {
  return {{"median", s.median}, {"p95", s.p95}, {"max", s.max}};
}

nlohmann::json sessionJson(const panmap::SessionStats& s) {
  nlohmann::json timings;
  for (const auto& [stage, t] : s.timings)
    timings[stage] = {{"median_ms", t.median_ms}, {"p95_ms", t.p95_ms}};
  return {{"heap_huge_pages", panmap::heapUsesHugePages()},
          {"messages", s.messages},
          {"frames_received", s.frames_received},
          {"frames_integrated", s.frames_integrated},
          {"rejected", s.rejected},
          {"geometry_only_frames", s.sync.geometry_only},
          {"geometry_only_queue_full", s.sync.geometry_only_queue_full},
          {"unmatched_panoptic", s.sync.unmatched_panoptic},
          {"panoptic_of_skipped_frames", s.sync.panoptic_of_skipped_frames},
          {"late_panoptic", s.sync.late_panoptic},
          {"panoptic_time_offset", s.sync.panoptic_time_offset},
          {"timings", timings},
          {"pose_refinement",
           {{"frames", s.refinement.frames},
            {"moved_m", spreadJson(s.refinement.moved_m)},
            {"turned_deg", spreadJson(s.refinement.turned_deg)}}},
          {"corrections",
           {{"received", s.corrections_received},
            {"applied", s.corrections_applied},
            {"superseded", s.corrections_superseded},
            {"frames_reintegrated", s.frames_reintegrated},
            {"last_repair_s", s.last_repair_s},
            {"repairs", s.repairs}}}};
}

nlohmann::json trackingJson(const panmap::Mapper& mapper) {
  static const char* kNames[] = {"accepted",     "accepted_partially", "too_few_points",
                                 "degenerate",   "low_inlier_ratio",   "correction_too_large",
                                 "solver_failed"};
  nlohmann::json out = nlohmann::json::object();
  for (int i = 0; i < panmap::kAlignmentStatusCount; ++i) {
    out[kNames[i]] = mapper.trackingCounts()[static_cast<size_t>(i)];
  }
  return out;
}

// Auto tracking's depth check (MapperConfig::depth_check) and what became of the poses.
nlohmann::json depthCheckJson(const panmap::Mapper& mapper) {
  const panmap::DepthPatternMonitor& check = mapper.depthCheck();
  const double pattern_m = check.patternRmsM();
  return {{"verdict", panmap::DepthPatternMonitor::name(check.verdict())},
          {"frames", check.frames()},
          {"pattern_mm",
           std::isfinite(pattern_m) ? nlohmann::json(1000.0 * pattern_m) : nlohmann::json(nullptr)},
          {"limit_mm", 1000.0 * mapper.config().depth_check.max_pattern_m},
          {"poses_corrected", mapper.posesCorrected()},
          {"poses_kept_as_given", mapper.posesKeptAsGiven()}};
}

// When the depth check found the sensor uncalibrated (the only way poses are kept as given):
// why, and what to do about it.
void printPoseConvention(const panmap::Mapper& mapper) {
  const std::string warning = mapper.poseConventionWarning();
  if (!warning.empty()) std::fprintf(stderr, "panmap-mapper: warning: %s\n", warning.c_str());
}

void printDepthCheck(const panmap::Mapper& mapper) {
  const panmap::DepthPatternMonitor& check = mapper.depthCheck();
  if (check.verdict() != panmap::DepthPatternMonitor::Verdict::kUncalibrated) return;
  std::printf(
      "  pose refinement withheld: over %d aligned frames the depth disagreed with the map in a "
      "fixed pattern of %.1f mm RMS (limit %.1f mm), the mark of an uncalibrated sensor that "
      "would pull good poses away; %lld poses kept as given. Calibrate the sensor "
      "(panmap-calibrate-depth, then --depth-calibration FILE) or force refinement with "
      "--tracking on\n",
      check.frames(), 1000.0 * check.patternRmsM(),
      1000.0 * mapper.config().depth_check.max_pattern_m,
      static_cast<long long>(mapper.posesKeptAsGiven()));
}

// Seconds each export step took, by step name.
nlohmann::json exportSeconds(const panmap::OutputSummary& outputs) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [step, seconds] : outputs.step_seconds) out[step] = seconds;
  return out;
}

nlohmann::json mapJson(const panmap::Mapper& mapper, const panmap::OutputSummary& outputs) {
  return {{"frames_total", mapper.framesIntegrated()},
          {"memory",
           {{"map_bytes", mapper.map().memoryBytes()},
            {"peak_rss_bytes", panmap::peakResidentBytes()},
            {"blocks", mapper.map().numBlocks()},
            {"voxels", mapper.map().numBlocks() * panmap::kBlockVoxels},
            {"voxels_with_votes", mapper.map().numVotedVoxels()}}},
          {"superpoints", mapper.superpoints().states().size()},
          {"superpoint_merges", mapper.superpoints().merges().size()},
          {"instances_frame_counting", mapper.superpoints().numInstances()},
          {"instances_in_mesh", outputs.instances_in_mesh},
          {"objects", outputs.objects},
          {"objects_off_mesh", outputs.objects_off_mesh},
          {"vote_evictions", mapper.voteEvictions()},
          {"tracking", trackingJson(mapper)},
          {"depth_check", depthCheckJson(mapper)},
          {"pose_convention_warning", mapper.poseConventionWarning()},
          {"mesh",
           {{"vertices", outputs.mesh_vertices},
            {"faces", outputs.mesh_faces},
            {"area_m2", outputs.mesh_area_m2}}},
          {"files", outputs.files},
          {"export_seconds", exportSeconds(outputs)},
          {"config",
           {{"voxel_size_m", mapper.config().map.voxel_size_m},
            {"truncation_voxels", mapper.config().integrator.truncation_voxels},
            {"geometry_only", mapper.config().fusion.geometry_only},
            {"semantic_consistency", mapper.config().superpoints.semantic_consistency},
            {"merge_threshold", mapper.config().superpoints.merge_threshold},
            {"threads", mapper.config().num_threads},
            {"depth_calibration", mapper.config().depth_calibration_file}}}};
}

nlohmann::json autosaveJson(const panmap::Autosaver* autosaver, double period_s) {
  if (!autosaver) return {{"period_s", 0}};
  const panmap::Autosaver::Stats s = autosaver->stats();
  return {{"period_s", period_s},
          {"written", s.written},
          {"waited_busy", s.waited_busy},
          {"waited_ms", s.waited_ms},
          {"failed", s.failed},
          {"last_bytes", s.last_bytes},
          {"last_serialize_ms", s.last_serialize_ms},
          {"last_write_ms", s.last_write_ms},
          {"ahead_of_store", s.ahead_of_store}};
}

nlohmann::json resumeJson(const std::optional<panmap::ResumePoint>& point) {
  if (!point) return nullptr;
  nlohmann::json lost = nlohmann::json::array();
  for (const auto& [id, utime] : point->lost) lost.push_back(id);
  return {{"snapshot", point->path},
          {"frames", point->frames},
          {"last_frame_id", point->last_frame_id},
          {"last_utime", point->last_utime},
          {"lost_frame_ids", lost},
          {"refused_snapshots", point->refused}};
}

// The autosave folder of an output folder (or the folder itself when it holds snapshots).
std::string autosaveDirOf(const std::string& dir) {
  const std::string sub = dir + "/autosave";
  return panmap::listAutosaves(dir).empty() ? sub : dir;
}

void writeJson(const std::string& path, const nlohmann::json& json) {
  // Rejection reasons may quote a channel name, which need not be UTF-8.
  panmap::writeFileAtomically(
      path, json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

// Frames mapped into no surface at all: wrong depth units, intrinsics or pose units look
// exactly like this. An exit 0 with an empty map would pass a script's check, so it is a
// failure (the outputs stay written, for a look). Returns the exit code.
int failIfNoSurface(const panmap::Mapper& mapper, size_t mesh_vertices) {
  if (mesh_vertices > 0 || mapper.framesIntegrated() == 0) return 0;
  const panmap::IntegratorConfig& c = mapper.config().integrator;
  std::fprintf(stderr,
               "panmap-mapper: error: %lld frames mapped but no surface came of them: no depth "
               "within %.2f-%.2f m, or frames that do not overlap (check the depth scale, the "
               "intrinsics and the poses' units)\n",
               static_cast<long long>(mapper.framesIntegrated()), c.min_depth_m, c.max_depth_m);
  return 1;
}

// report.json last: a failure to write it is one more failed output, named with the others.
void writeReport(const std::string& out_dir, const nlohmann::json& json,
                 panmap::OutputSummary* outputs) {
  const std::string path = out_dir + "/report.json";
  try {
    writeJson(path, json);
  } catch (const std::exception& e) {
    outputs->failed.push_back(e.what());
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
}

void printRejected(const std::map<std::string, int64_t>& rejected) {
  for (const auto& [reason, count] : rejected) {
    std::printf("  rejected %lld: %s\n", static_cast<long long>(count), reason.c_str());
  }
}

// What refinement did to the given poses, when it tracked any: a trusted SLAM system's poses
// moved by centimetres point at the depth sensor (docs/MAPPING.md, "Depth calibration").
void printRefinement(const panmap::PoseRefinementStats& r) {
  if (r.frames == 0) return;
  std::printf(
      "  pose refinement moved %lld tracked poses by %.1f cm median (p95 %.1f, max %.1f) and "
      "%.2f deg median (max %.2f)\n",
      static_cast<long long>(r.frames), 100.0 * r.moved_m.median, 100.0 * r.moved_m.p95,
      100.0 * r.moved_m.max, r.turned_deg.median, r.turned_deg.max);
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "panmap mapping process. Live (default): maps CAMERA_RGBD + CAMERA_POSE + PANOPTIC from "
      "LCM until PANMAP_COMMAND finish or Ctrl-C, then asks panmap-optimizer for the final "
      "labels. Offline (--log): maps a log as fast as it can, optimising in-process. Both write "
      "mesh_{semantic,instance,superpoint}.ply, objects.json, occupancy.bt, trajectory.txt, "
      "map.panmap, report.json, config.yaml and snapshot PNGs into --out (README, panmap-mapper)."};
  std::string log_path, out_dir, load_path, config_path, lcm_url;
  panmap::MapperConfig config;
  panmap::LiveOptions live;
  panmap::SessionOptions& options = live.session;
  bool quiet = false, geometry_only = false, spatial_only = false, no_snapshots = false;
  bool no_mask_edge_fill = false, no_mask_only_surfaces = false;
  bool no_regularise = false, no_refine = false, print_config = false, export_only = false;
  bool no_optimise = false;
  app.add_option("--log", log_path, "LCM log to map offline (omit for the live LCM mode)");
  app.add_option("--out", out_dir, "output folder")->required(false);
  app.add_option("--config", config_path,
                 "YAML config (see --print-config); command-line flags override it");
  app.add_flag("--print-config", print_config, "print the full default config and exit");
  app.add_option("--voxel-size", config.map.voxel_size_m, "voxel edge, metres")
      ->capture_default_str();
  app.add_option("--threads", config.num_threads, "integration threads")->capture_default_str();
  app.add_option("--max-frames", options.max_frames, "stop after N integrated frames (0 = all)")
      ->check(panmap::cli::nonNegative());
  app.add_flag("--geometry-only", geometry_only, "ignore panoptic masks (ablation)");
  app.add_flag("--no-mask-edge-fill", no_mask_edge_fill,
               "pixels of a mask outside every surface cast no vote (fusion.fill_mask_edges 0; "
               "as Voxblox++)");
  app.add_flag("--no-mask-only-surfaces", no_mask_only_surfaces,
               "a thing mask without a geometric segment (a small or far object) casts no vote "
               "(fusion.mask_only_surfaces 0; as Voxblox++)");
  int pair_interior_px = -1;
  app.add_option("--pair-interior-px", pair_interior_px,
                 "co-observation (Eq. 6) counts only pixels this far inside their mask's outline "
                 "(graph.pair_interior_px, default 2; 0: every pixel, as the paper and Voxblox++)");
  app.add_flag("--spatial-only", spatial_only,
               "merge super-points without the semantic consistency check (ablation, Voxblox++)");
  app.add_flag("--no-regularise", no_regularise,
               "skip the semantic regularisation (ablation, w/o III-C)");
  app.add_flag("--no-refine", no_refine, "skip the instance refinement (ablation, w/o III-D)");
  std::string tracking;
  app.add_option("--tracking", tracking,
                 "refine poses against the map: off, auto (poses flagged SLAM or odometry), on "
                 "(default: the config's tracking.mode, auto)")
      ->check(CLI::IsMember({"off", "auto", "on"}));
  std::string depth_calibration;
  app.add_option("--depth-calibration", depth_calibration,
                 "the depth sensor's calibration from panmap-calibrate-depth (overrides the "
                 "config's depth_calibration)");
  app.add_option("--load", load_path,
                 "continue a saved map.panmap (with --log: frames up to its newest are "
                 "skipped; mapping settings stay the map's own)");
  std::string resume_dir;
  app.add_option("--resume", resume_dir,
                 "continue after a crash from the newest good autosave of this output folder "
                 "(DIR/autosave); frames it already holds are skipped, lost ones reported")
      ->excludes("--load");
  double autosave_s = 60.0;
  app.add_option("--autosave-s", autosave_s,
                 "snapshot the map every S seconds of stream time into OUT/autosave (atomic, "
                 "two kept; 0: never). Default 60 live, off offline unless given")
      ->check(panmap::cli::atLeast(0.0, false, "a period in seconds >= 0 (0: never)"))
      ->capture_default_str();
  app.add_flag("--no-optimise", no_optimise,
               "offline and --export-only: write frame-count outputs without the final "
               "optimisation, as a live mapper does when no panmap-optimizer answers");
  app.add_flag("--export-only", export_only,
               "with --load: no mapping, only run the final optimisation and write the outputs");
  app.add_option("--channel-rgbd", options.channel_rgbd)->capture_default_str();
  app.add_option("--channel-pose", options.channel_pose)->capture_default_str();
  app.add_option("--channel-panoptic", options.channel_panoptic)->capture_default_str();
  app.add_option("--channel-correction", options.channel_correction)->capture_default_str();
  std::string frame_store_dir;
  app.add_option("--frame-store", frame_store_dir,
                 "keep every integrated frame in this folder (depth, pixel labels and panoptic "
                 "masks, ~120 kB each) so that loop-closure corrections on --channel-correction "
                 "repair the map (docs/LOOP_CLOSURE.md); without it corrections are refused and "
                 "counted");
  bool repair_reintegrate_only = false;
  app.add_flag("--repair-reintegrate-only", repair_reintegrate_only,
               "repair by re-integrating the stored frames with the super-points they had, "
               "never by mapping them again with their masks (faster; objects formed under "
               "large drift stay as they were)");
  bool repair_occupancy_last = false;
  app.add_flag("--repair-occupancy-last", repair_occupancy_last,
               "live repairs that map the frames again swap the occupancy tree in with the rest "
               "of the map, not first (by default planners get the repaired tree after one pass "
               "over the stored depth)");
  bool repair_reintegrate_first = false;
  app.add_flag("--repair-reintegrate-first", repair_reintegrate_first,
               "live repairs that map the frames again re-integrate them and swap that map in "
               "(geometry, labels, objects and occupancy repaired in about a third of the time; "
               "after the occupancy tree unless --repair-occupancy-last), then map them again");
  double correction_tolerance_ms = 1.0;
  app.add_option("--correction-tolerance-ms", correction_tolerance_ms,
                 "a corrected pose matches the mapped frame nearest in time within this (0: the "
                 "utime exactly); utimes further from every mapped frame are refused and named")
      ->capture_default_str()
      ->check(panmap::cli::nonNegative());
  std::vector<double> grid_shift;
  app.add_option("--grid-shift", grid_shift,
                 "X,Y,Z metres: move every pose by this before mapping, so the voxel grid falls "
                 "elsewhere on the same surfaces (a diagnostic: outputs are in the moved frame; "
                 "scripts/bench/noise_floor.py)")
      ->expected(3)
      ->delimiter(',');
  app.add_flag("--no-snapshots", no_snapshots, "skip the overview PNGs");
  std::string graph_json;
  app.add_option("--graph-json", graph_json,
                 "offline and --export-only: also write the super-point graph with its final "
                 "labels to this JSON file (why a super-point got its class or instance)");
  app.add_flag("-q,--quiet", quiet, "no progress line");
  auto* live_group = app.add_option_group("live", "live LCM mode");
  live_group->add_option("--lcm-url", lcm_url, "LCM URL (default: LCM_DEFAULT_URL or LCM's own)");
  live_group->add_option("--status-period-s", live.status_period_s, "PANMAP_STATUS period")
      ->capture_default_str();
  live_group
      ->add_option("--publish-period-s", live.publish_period_s,
                   "PANMAP_OBJECTS / PANMAP_OCTOMAP period (0: never)")
      ->capture_default_str();
  live_group
      ->add_option("--optimizer-timeout-s", live.optimiser_timeout_s,
                   "wait this long for panmap-optimizer's labels, then write unoptimised outputs")
      ->capture_default_str();
  live_group
      ->add_option("--optimizer-retry-s", live.optimiser_retry_s,
                   "publish the final graph again at this period until labels come (an "
                   "optimiser restarted meanwhile still answers)")
      ->capture_default_str();
  live_group
      ->add_option("--optimise-every-s", live.optimise_period_s,
                   "while mapping, send the graph to panmap-optimizer at this period; "
                   "PANMAP_OBJECTS and exports use its latest answer (0: only on the optimise "
                   "command)")
      ->capture_default_str();
  live_group
      ->add_option("--queue-frames", live.max_queued_frames,
                   "frames waiting for the mapper at most; the oldest is dropped beyond")
      ->capture_default_str();
  live_group
      ->add_option("--idle-scan-every", live.idle_scan_every_frames,
                   "while waiting for frames, refresh the graph's surface scan once this many "
                   "frames came since the last time, so the final optimisation reads only the "
                   "last few frames' blocks (0: never)")
      ->capture_default_str();
  live_group->add_option("--channel-status", live.channel_status)->capture_default_str();
  live_group->add_option("--channel-objects", live.channel_objects)->capture_default_str();
  live_group->add_option("--channel-octomap", live.channel_octomap)->capture_default_str();
  live_group->add_option("--channel-graph", live.channel_graph)->capture_default_str();
  live_group->add_option("--channel-labels", live.channel_labels)->capture_default_str();
  live_group->add_option("--channel-command", live.channel_command)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  panmap::applyMemoryPolicy(argv);

  try {
    panmap::PanmapConfig file_config;
    if (print_config) {
      std::printf("%s", panmap::configToYaml(file_config).c_str());
      return 0;
    }
    if (out_dir.empty()) out_dir = resume_dir;
    if (out_dir.empty()) throw panmap::Error("--out is required");
    panmap::checkOutputFolder(out_dir, "--out");
    // A loaded or resumed map keeps mapping with the settings it was made with: the config
    // file's keys and the flags below are checked against them instead of silently ignored.
    std::unique_ptr<panmap::Mapper> mapper;
    std::optional<panmap::ResumePoint> resumed;
    if (!resume_dir.empty()) {
      // An export (or a final export cut short) may have written a map newer than the newest
      // snapshot: the newer of the two is taken.
      resumed = panmap::resumeFrom(autosaveDirOf(resume_dir), {resume_dir + "/map.panmap"});
      mapper = std::move(resumed->mapper);
      options.resume_after_utime = resumed->last_utime;
    } else if (!load_path.empty()) {
      mapper = panmap::Mapper::load(load_path);
    }
    panmap::PanmapConfig base;
    if (mapper) base.mapper = mapper->config();
    const float flag_voxel = config.map.voxel_size_m;
    const int flag_threads = config.num_threads;
    file_config = config_path.empty() ? base : panmap::loadConfig(config_path, base);
    config = file_config.mapper;
    options.sync = file_config.sync;
    // Flags given on the command line win over the file.
    if (app.count("--voxel-size") > 0) config.map.voxel_size_m = flag_voxel;
    if (app.count("--threads") > 0) config.num_threads = flag_threads;
    if (!grid_shift.empty()) {
      options.grid_shift_m = Eigen::Vector3d(grid_shift[0], grid_shift[1], grid_shift[2]);
      if (!frame_store_dir.empty()) {
        throw panmap::Error("--grid-shift is a diagnostic of offline maps: not with --frame-store");
      }
    }
    if (geometry_only) config.fusion.geometry_only = true;
    if (!depth_calibration.empty()) {
      config.depth_calibration = std::make_shared<const panmap::DepthCalibration>(
          panmap::DepthCalibration::load(depth_calibration));
      config.depth_calibration_file = depth_calibration;
    }
    if (spatial_only) config.superpoints.semantic_consistency = false;
    if (no_mask_edge_fill) config.mask_edge_fill.enabled = false;
    if (no_mask_only_surfaces) config.fusion.mask_only_surfaces = false;
    if (app.count("--pair-interior-px") > 0) config.graph.pair_interior_px = pair_interior_px;
    if (tracking == "off") config.tracking_mode = panmap::MapperConfig::TrackingMode::kOff;
    if (tracking == "auto") config.tracking_mode = panmap::MapperConfig::TrackingMode::kAuto;
    if (tracking == "on") config.tracking_mode = panmap::MapperConfig::TrackingMode::kOn;
    panmap::OptimiserConfig optimiser = file_config.optimiser;
    if (no_regularise) optimiser.regularise = false;
    if (no_refine) optimiser.refine = false;
    if (mapper && !export_only) {
      const panmap::SettingDifference d = panmap::mapperSettingDifference(mapper->config(), config);
      if (!d.key.empty()) {
        throw panmap::Error(std::string(resumed ? "--resume" : "--load") +
                            ": the map was made with " + d.key + ": " + d.have +
                            ", this run asks for " + d.wanted +
                            "; a map keeps mapping with its own settings (leave the flag or key "
                            "out, or start a new map)");
      }
    }
    if (!mapper) mapper = std::make_unique<panmap::Mapper>(config);
    // Said once the settings agree: "resumed" followed by a refusal read as both.
    if (resumed) {
      std::fprintf(stderr, "panmap-mapper: %s\n", panmap::describeResume(*resumed).c_str());
    }
    // A map given with --load holds its frames: the same log given again must not map them
    // twice, so frames up to its newest are skipped, as --resume does.
    if (!resumed && !load_path.empty() && !mapper->trajectory().empty()) {
      options.resume_after_utime = mapper->trajectory().back().utime;
      std::fprintf(stderr,
                   "panmap-mapper: loaded %s: %zu frames; frames of the log up to its newest "
                   "(utime %lld) are skipped\n",
                   load_path.c_str(), mapper->trajectory().size(),
                   static_cast<long long>(options.resume_after_utime));
    }
    std::unique_ptr<panmap::FrameStore> frame_store;
    if (!frame_store_dir.empty() && !export_only) {
      panmap::FrameStoreConfig store_config;
      store_config.folder = frame_store_dir;
      frame_store = std::make_unique<panmap::FrameStore>(store_config);
      for (const std::string& problem : frame_store->problems()) {
        std::fprintf(stderr, "panmap-mapper: frame store: %s\n", problem.c_str());
      }
      // A new map must not inherit frames of another run: a repair would re-integrate them.
      if (frame_store->size() > 0 && load_path.empty() && resume_dir.empty()) {
        throw panmap::Error("frame store " + frame_store_dir + " already holds " +
                            std::to_string(frame_store->size()) +
                            " frames; give an empty folder, or --load / --resume their map");
      }
      // A map that holds frames its store lacks (a snapshot of a version that did not wait
      // for the store, or a store emptied by hand) cannot have those frames repaired.
      if (!load_path.empty() || !resume_dir.empty()) {
        size_t missing = 0;
        int64_t first_missing = 0;
        for (const panmap::StampedPose& p : mapper->trajectory()) {
          if (!frame_store->has(p.utime) && missing++ == 0) first_missing = p.utime;
        }
        if (missing > 0) {
          std::fprintf(stderr,
                       "panmap-mapper: warning: frame store %s lacks %zu of the map's %zu "
                       "frames (first: utime %lld): a correction that moves them is refused\n",
                       frame_store_dir.c_str(), missing, mapper->trajectory().size(),
                       static_cast<long long>(first_missing));
        }
      }
      options.frame_store = frame_store.get();
      options.repair.reassociate = !repair_reintegrate_only;
      options.repair.occupancy_first = !repair_occupancy_last;
      options.repair.reintegrate_first = repair_reintegrate_first;
      // Beyond 10^9 ms (11 days) every utime matches anyway; the cap keeps llround defined.
      options.repair.match_tolerance_us =
          std::llround(std::min(correction_tolerance_ms, 1e9) * 1000.0);
    }
    // Offline runs can be replayed from their log, so they autosave only when asked to.
    const bool offline = !log_path.empty() || export_only;
    if (offline && app.count("--autosave-s") == 0) autosave_s = 0.0;
    // From here on the run writes into OUT (autosaves, then the outputs): one process at a time.
    std::optional<panmap::OutputFolderLock> out_lock;
    out_lock.emplace(out_dir);
    std::unique_ptr<panmap::Autosaver> autosaver;
    if (autosave_s > 0.0 && !export_only) {
      panmap::Autosaver::Config autosave_config;
      autosave_config.dir = out_dir + "/autosave";
      // Snapshots of a run that did not finish are what it mapped: a new run would clear them
      // with its own at the end, so forgetting --resume once lost hours of map without a word.
      const std::vector<std::string> leftover = panmap::listResumeCandidates(autosave_config.dir);
      std::error_code error;
      const bool resuming_them = resumed && std::filesystem::equivalent(autosaveDirOf(resume_dir),
                                                                        autosave_config.dir, error);
      if (resuming_them) autosave_config.resumed_from = resumed->path;
      if (!leftover.empty() && !resuming_them) {
        throw panmap::Error(autosave_config.dir +
                            " holds snapshots of a run that did not finish (" + leftover.front() +
                            "): continue it with --resume " + out_dir + ", or remove " +
                            autosave_config.dir + " to start a new map there");
      }
      autosave_config.period_s = autosave_s;
      if (frame_store) {
        autosave_config.frame_stored = [store = frame_store.get()](int64_t utime) {
          return store->has(utime);
        };
      }
      autosaver = std::make_unique<panmap::Autosaver>(autosave_config);
    }
    // After the outputs are safely written the snapshots have served their purpose.
    auto finishAutosave = [&]() {
      // The outputs are written by now: snapshots left behind cost disk, not the map.
      try {
        if (autosaver) {
          autosaver->clear();
        } else if (resumed) {
          panmap::clearAutosaveFolder(autosaveDirOf(resume_dir));
        }
      } catch (const std::exception& e) {
        std::fprintf(stderr, "panmap-mapper: warning: autosave snapshots not removed: %s\n",
                     e.what());
      }
    };
    panmap::OutputOptions output_options;
    output_options.snapshots = !no_snapshots;
    output_options.sync = options.sync;

    if (export_only && load_path.empty()) throw panmap::Error("--export-only needs --load");
    if (export_only && !log_path.empty()) throw panmap::Error("--export-only takes no --log");
    if (no_optimise && log_path.empty() && !export_only) {
      throw panmap::Error(
          "--no-optimise needs --log or --export-only (live: run no panmap-optimizer)");
    }

    if (!log_path.empty() || export_only) {
      // Offline: every frame, in log order, optimisation in-process.
      panmap::OfflineReport report;
      if (!export_only) {
        panmap::ProgressLine progress("map", "MiB", !quiet);
        int64_t frames = 0;
        const auto start = std::chrono::steady_clock::now();
        report = panmap::mapLog(
            log_path, options, mapper.get(),
            [&](size_t done, size_t total) { progress.update(done >> 20, total >> 20); },
            [&](const panmap::SyncedFrame& f, const panmap::FrameStats&) {
              if (autosaver) autosaver->afterFrame(*mapper, f.frame.frame_id, f.frame.utime);
              ++frames;
              char note[64];
              std::snprintf(note, sizeof(note), "%lld frames, %.1f frames/s",
                            static_cast<long long>(frames), frames / (msSince(start) / 1000.0));
              progress.setNote(note);
            });
        progress.finish();
        // Empty outputs and exit 0 would pass a wrong file or channel name off as a map.
        if (report.frames_integrated == 0 && mapper->framesIntegrated() == 0) {
          for (const std::string& w : panmap::syncWarnings(report, options.sync)) {
            std::fprintf(stderr, "panmap-mapper: warning: %s\n", w.c_str());
          }
          throw panmap::Error("no frame mapped from " + log_path + ": " +
                              panmap::describeNothingMapped(report, options));
        }
        // Another log's frames would be mapped onto this map without a word: the map's own log
        // holds a frame at the map's newest utime.
        if (options.resume_after_utime != INT64_MIN && !report.resume_point_seen) {
          std::fprintf(stderr,
                       "panmap-mapper: warning: %s has no frame at the %s map's newest utime "
                       "(%lld): is it the log the map was made from?\n",
                       log_path.c_str(), resumed ? "resumed" : "loaded",
                       static_cast<long long>(options.resume_after_utime));
        }
        const std::string unread = panmap::describeUnreadChannels(report, options);
        if (!unread.empty()) {
          std::fprintf(stderr, "panmap-mapper: warning: log %s: %s\n", log_path.c_str(),
                       unread.c_str());
        }
        const std::string damage = panmap::describeLogDamage(report);
        if (!damage.empty()) {
          std::fprintf(stderr,
                       "panmap-mapper: warning: log %s: %s; its readable events were mapped\n",
                       log_path.c_str(), damage.c_str());
        }
      }
      const auto optimise_start = std::chrono::steady_clock::now();
      const panmap::SuperpointGraph graph = mapper->graph();
      const panmap::GraphLabels labels =
          no_optimise ? panmap::GraphLabels{} : panmap::optimise(graph, optimiser);
      const double optimise_ms = msSince(optimise_start);
      output_options.utime = report.last_frame_utime;
      output_options.final_export = true;  // nothing meshes this map after it
      panmap::OutputSummary outputs = panmap::writeOutputs(
          out_dir, mapper.get(), no_optimise ? nullptr : &labels, optimiser, output_options);
      // After the outputs, which create OUT: OUT/graph.json is the natural place for it.
      if (!graph_json.empty()) panmap::writeGraphJson(graph_json, graph, labels);
      nlohmann::json json = sessionJson(report);
      json["mode"] = export_only ? "export-only" : "offline";
      json["log"] = log_path;
      json["autosave"] = autosaveJson(autosaver.get(), autosave_s);
      json["resumed"] = resumeJson(resumed);
      json["events"] = report.events;
      json["log_damage"] = panmap::describeLogDamage(report);
      // The outputs are in the moved frame: a report that did not say so passed them off as
      // the log's (config.yaml cannot carry it: it is not a map setting).
      json["grid_shift_m"] = {options.grid_shift_m.x(), options.grid_shift_m.y(),
                              options.grid_shift_m.z()};
      json["wall_s"] = report.wall_s;
      json.update(mapJson(*mapper, outputs));
      json["graph"] = {{"vertices", graph.vertices.size()},
                       {"edges", graph.edges.size()},
                       {"edges_pruned", mapper->edgesPruned()},
                       {"optimised", !no_optimise},
                       {"optimise_ms", optimise_ms},
                       {"solve_ms", labels.solve_ms},
                       {"fragments_folded", labels.fragments_folded},
                       {"fragments_dropped", labels.fragments_dropped},
                       {"consensus_groups", labels.consensus_groups},
                       {"consensus_superpoints", labels.consensus_superpoints},
                       {"regularise", optimiser.regularise},
                       {"class_consensus", optimiser.class_consensus},
                       {"refine", optimiser.refine}};
      json["outputs_failed"] = outputs.failed;
      writeReport(out_dir, json, &outputs);
      finishAutosave();
      panmap::requireAllWritten(outputs, out_dir);
      std::printf(
          "mapped %lld frames in %.1f s (median %.1f ms/frame): %zu super-points, %zu "
          "instances after optimisation, %zu mesh vertices; outputs in %s\n",
          static_cast<long long>(report.frames_integrated), report.wall_s,
          report.timings.count("total") ? report.timings.at("total").median_ms : 0.0,
          mapper->superpoints().states().size(), outputs.instances_in_mesh, outputs.mesh_vertices,
          out_dir.c_str());
      printRejected(report.rejected);
      for (const std::string& w : panmap::syncWarnings(report, options.sync)) {
        std::fprintf(stderr, "panmap-mapper: warning: %s\n", w.c_str());
      }
      printRefinement(report.refinement);
      printDepthCheck(*mapper);
      printPoseConvention(*mapper);
      return failIfNoSurface(*mapper, outputs.mesh_vertices);
    }

    // Live: LCM in, LCM out. Repairs run beside the mapping: frames keep coming meanwhile.
    live.session.background_repair = true;
    lcm::LCM lcm(lcm_url);
    if (!lcm.good()) throw panmap::Error("cannot open LCM URL '" + lcm_url + "'");
    panmap::LiveMapper node(&lcm, live, mapper.get(),
                            [&](const panmap::SyncedFrame& f, const panmap::FrameStats&) {
                              if (autosaver) {
                                autosaver->afterFrame(*mapper, f.frame.frame_id, f.frame.utime);
                              }
                            });
    node.setWarningSource([&autosaver]() {
      std::vector<std::string> warnings;
      if (autosaver) {
        const panmap::Autosaver::Stats a = autosaver->stats();
        if (a.last_failed) {
          warnings.push_back("autosave: the last snapshot failed (" + std::to_string(a.failed) +
                             " so far): " + a.last_error + "; a crash now loses more than " +
                             "one period");
        }
      }
      return warnings;
    });
    node.setCommandHandler([&](int8_t command, const std::string& argument, panmap::Mapper* m,
                               const panmap::GraphLabels* labels) {
      std::string done;
      if (command == panmap::command_t::COMMAND_SAVE) {
        const std::string path = argument.empty() ? out_dir + "/map.panmap" : argument;
        m->save(path);
        done = "map saved to " + path;
      } else {
        const std::string dir = argument.empty() ? out_dir : argument;
        panmap::OutputOptions export_options = output_options;
        // Stamped with the newest frame mapped, as the final export and PANMAP_OBJECTS are.
        export_options.utime = m->trajectory().empty() ? 0 : m->trajectory().back().utime;
        panmap::requireAllWritten(panmap::writeOutputs(dir, m, labels, optimiser, export_options),
                                  dir);
        done = "outputs written to " + dir;
      }
      std::fprintf(stderr, "panmap-mapper: %s\n", done.c_str());
      return done;
    });
    // Objects and occupancy for planners: every publish period, and once more after the final
    // export with objects.json's own objects (the channels never carried the final map).
    auto planner_messages = [&live](const panmap::Mapper& m, int64_t utime,
                                    const std::vector<panmap::MappedObject>& objects) {
      std::vector<panmap::OutgoingMessage> out;
      out.push_back(panmap::encodeMessage(live.channel_objects, panmap::toMessage(objects, utime)));
      if (m.occupancy()) {
        panmap::octomap_t tree;
        tree.utime = utime;
        tree.resolution_m = m.occupancy()->resolution();
        tree.tree_type = "OcTree";
        tree.binary = true;
        const std::string data = m.occupancy()->toBinaryData();
        tree.data.assign(data.begin(), data.end());
        tree.size = static_cast<int32_t>(tree.data.size());
        out.push_back(panmap::encodeMessage(live.channel_octomap, tree));
      }
      return out;
    };
    node.setPeriodicPublisher([&planner_messages, &optimiser](panmap::Mapper* m, int64_t utime,
                                                              const panmap::GraphLabels* labels) {
      return planner_messages(*m, utime, panmap::computeObjects(*m, labels, optimiser.objects));
    });
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::fprintf(stderr,
                 "panmap-mapper: listening on %s, %s, %s; finish with PANMAP_COMMAND "
                 "or Ctrl-C\n",
                 options.channel_rgbd.c_str(), options.channel_pose.c_str(),
                 options.channel_panoptic.c_str());
    const auto start = std::chrono::steady_clock::now();
    const bool by_command = node.run(g_stop);
    std::fprintf(stderr, "panmap-mapper: %s; mapping what is queued\n",
                 by_command ? "finish command" : "signal");
    node.drain();
    const double wall_s = msSince(start) / 1000.0;
    // Empty outputs and exit 0 would pass a wrong URL or channel name off as a map, as offline.
    if (mapper->framesIntegrated() == 0) {
      const panmap::SessionStats nothing = node.stats();
      std::string why =
          std::to_string(node.framesReceived()) + " frames received on " + options.channel_rgbd;
      for (const auto& [reason, count] : nothing.rejected) {
        why += "; " + reason + " (" + std::to_string(count) + ")";
      }
      for (const std::string& w : panmap::syncWarnings(nothing, options.sync)) {
        std::fprintf(stderr, "panmap-mapper: warning: %s\n", w.c_str());
      }
      const std::string error = "no frame mapped (" + why + "): is the camera publishing on " +
                                (lcm_url.empty() ? std::string("LCM's default URL") : lcm_url) +
                                "? nothing written";
      node.publishFinished(false, error);
      finishAutosave();  // its journal holds no frame: nothing to resume
      throw panmap::Error(error);
    }
    g_stop = false;  // a second Ctrl-C cuts the wait for labels short
    std::fprintf(stderr,
                 "panmap-mapper: waiting up to %.0f s for panmap-optimizer's labels (Ctrl-C "
                 "again skips them)\n",
                 live.optimiser_timeout_s);
    const auto optimise_start = std::chrono::steady_clock::now();
    const std::optional<panmap::GraphLabels> labels = node.requestLabels(g_stop);
    const double optimise_ms = msSince(optimise_start);
    if (!labels && g_stop) {
      std::fprintf(stderr,
                   "panmap-mapper: labels skipped by a second signal: writing unoptimised "
                   "outputs (frame-count labels)\n");
    } else if (!labels) {
      std::fprintf(stderr,
                   "panmap-mapper: no labels from panmap-optimizer within %.0f s: writing "
                   "unoptimised outputs (frame-count labels)\n",
                   live.optimiser_timeout_s);
    }
    const panmap::SessionStats stats = node.stats();
    panmap::OutputOptions final_options = output_options;  // the export command keeps its own
    final_options.utime = stats.last_frame_utime;
    final_options.final_export = true;
    panmap::OutputSummary outputs;
    // map.panmap that cannot be written (a full disk, the folder gone) must not cost the map
    // that lives only in this process: it is kept, and save / export commands to another place
    // are served, until a finish command tries again or a signal gives it up.
    for (;;) {
      try {
        outputs = panmap::writeOutputs(out_dir, mapper.get(), labels ? &*labels : nullptr,
                                       optimiser, final_options);
        break;
      } catch (const std::exception& e) {
        const std::string why = std::string(e.what()) +
                                "; the map is kept: send save PATH or export DIR to another "
                                "place, or finish again once " +
                                out_dir + " can be written (Ctrl-C gives it up)";
        std::fprintf(stderr, "panmap-mapper: error: %s\n", why.c_str());
        node.publishFinished(false, why);
        g_stop = false;
        if (!node.serveCommandsAfterFailedFinish(g_stop)) throw;
        std::fprintf(stderr, "panmap-mapper: finish command; writing the outputs again\n");
      }
    }
    // `panmap-command finish` waits for this status: a failure must reach it too.
    try {
      nlohmann::json json = sessionJson(stats);
      json["mode"] = "live";
      json["lcm_url"] = lcm_url;
      json["autosave"] = autosaveJson(autosaver.get(), autosave_s);
      json["resumed"] = resumeJson(resumed);
      json["graph_requests_sent"] = node.graphRequestsSent();
      json["idle_scan_refreshes"] = node.idleScanRefreshes();
      json["frames_received"] = node.framesReceived();
      json["frames_dropped_behind"] = node.framesDropped();
      json["wall_s"] = wall_s;
      json.update(mapJson(*mapper, outputs));
      json["graph"] = {{"optimised", labels.has_value()},
                       {"edges_pruned", mapper->edgesPruned()},
                       {"optimise_ms", optimise_ms},
                       {"solve_ms", labels ? labels->solve_ms : 0.0},
                       {"fragments_folded", labels ? labels->fragments_folded : 0},
                       {"fragments_dropped", labels ? labels->fragments_dropped : 0}};
      json["outputs_failed"] = outputs.failed;
      writeReport(out_dir, json, &outputs);
      finishAutosave();
      panmap::requireAllWritten(outputs, out_dir);
    } catch (const std::exception& e) {
      node.publishFinished(false, e.what());
      throw;
    }
    node.publishNow(planner_messages(*mapper, final_options.utime, outputs.object_list));
    node.publishFinished(true, "outputs written to " + out_dir +
                                   (labels ? "" : " (unoptimised: frame-count labels)"));
    std::printf(
        "mapped %lld of %lld frames received (%lld dropped behind) in %.1f s: %zu "
        "super-points, %zu instances%s, %zu mesh vertices; outputs in %s\n",
        static_cast<long long>(stats.frames_integrated),
        static_cast<long long>(node.framesReceived()), static_cast<long long>(node.framesDropped()),
        wall_s, mapper->superpoints().states().size(), outputs.instances_in_mesh,
        labels ? " after optimisation" : " (unoptimised)", outputs.mesh_vertices, out_dir.c_str());
    printRejected(stats.rejected);
    for (const std::string& w : panmap::syncWarnings(stats, options.sync)) {
      std::fprintf(stderr, "panmap-mapper: warning: %s\n", w.c_str());
    }
    printRefinement(stats.refinement);
    printDepthCheck(*mapper);
    printPoseConvention(*mapper);
    return failIfNoSurface(*mapper, outputs.mesh_vertices);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-mapper: error: %s\n", e.what());
    return 1;
  }
}
