// Cost of a loop-closure repair (issue 22: 1,000 frames at 2 cm in <= 5 s while frames keep
// arriving at 5 Hz). Maps a real sequence with a frame store (frames beyond its length replay
// it back and forth with new times, so any repair size can be asked for), then corrects every
// 10th frame's pose by a slow drift-like move and repairs: once blocking (repairMap, the
// offline path), once on its own thread (BackgroundRepair, the live path) while new frames are
// mapped at the given rate. Prints the repair times, what loading the frames costs of it, and
// the mapping latency of the frames that arrived during the background repair. With --room S
// the frames are a ScanNet-like procedural room rendered with `m2f` masks (panmap-synth
// --room S --room-style scannet, surveyed twice at 5 Hz): the store keeps the masks and the
// repair maps the frames again, as it does for every labelled map (--segment-again: without the
// geometric segments kept in the store; --reintegrate-only: re-integration with the stored pixel
// labels instead, as panmap-mapper --repair-reintegrate-only).
//   panmap-bench-repair [--data DIR | --room S [--segment-again | --reintegrate-only]
//                       [--occupancy-last] [--reintegrate-first]]
//                       [--frames N] [--voxel-size M]
//                       [--threads N] [--rate-hz R] [--live-frames K]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/progress.h"
#include "panmap/core/value_spread.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/loop/background_repair.h"
#include "panmap/loop/frame_store.h"
#include "panmap/loop/map_repair.h"
#include "panmap/mapper/mapper.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/sequence.h"

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Frame i of a replay of `reader` back and forth (0 1 .. n-1 n-2 .. 1 0 1 ..), at 5 Hz.
panmap::DatasetFrame replayed(const panmap::DatasetReader& reader, size_t i) {
  const size_t n = reader.size();
  const size_t period = n > 1 ? 2 * (n - 1) : 1;
  const size_t k = i % period;
  panmap::DatasetFrame f = reader.read(k < n ? k : period - k);
  f.rgbd.utime = static_cast<int64_t>(i + 1) * 200000;
  f.rgbd.frame_id = static_cast<int64_t>(i);
  return f;
}

// A back-end's correction: every 10th frame (and the last) moved by a rotation and shift that
// grow along the trajectory, as drift removed at a loop closure does.
panmap::PoseCorrection driftCorrection(const std::vector<panmap::StampedPose>& trajectory,
                                       int64_t id) {
  panmap::PoseCorrection c;
  c.correction_id = id;
  c.utime = trajectory.back().utime;
  for (size_t i = 0; i < trajectory.size(); ++i) {
    if (i % 10 != 0 && i + 1 != trajectory.size()) continue;
    const double s = static_cast<double>(i) / static_cast<double>(trajectory.size());
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    D.linear() = Eigen::AngleAxisd(0.02 * s, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    D.translation() = Eigen::Vector3d(0.05 * s, -0.03 * s, 0.01 * s);
    panmap::StampedPose p = trajectory[i];
    p.T_W_C = D * p.T_W_C;
    c.poses.push_back(p);
  }
  return c;
}

// Frames prepared before the background repair starts (30 s at 5 Hz).
constexpr size_t kReadAhead = 150;

// A frame to map: from a dataset (no masks) or rendered (with masks).
struct InputFrame {
  panmap::RgbdFrame rgbd;
  std::optional<Eigen::Isometry3d> T_W_C;
  std::optional<panmap::PanopticFrame> panoptic;
};

}  // namespace

int main(int argc, char** argv) {
  panmap::applyMemoryPolicy(argv);  // panmap-mapper's allocation policy
  CLI::App app{
      "Time a loop-closure repair of N stored frames of a real sequence: blocking, and on its "
      "own thread while frames keep being mapped at a given rate."};
#ifdef PANMAP_DATA_DIR
  std::string data = std::string(PANMAP_DATA_DIR) + "/7scenes-200";
#else
  std::string data = "../shared/data/7scenes-200";
#endif
  int frames = 1000, threads = 2, live_frames = 0, room = -1;
  bool segment_again = false, reintegrate_only = false, occupancy_last = false;
  bool reintegrate_first = false;
  double rate_hz = 5.0;
  float voxel_size_m = 0.02f;
  app.add_option("--data", data, "dataset folder (7-Scenes, ScanNet export, TUM, folder)")
      ->capture_default_str();
  app.add_option("--room", room,
                 "render ScanNet-like procedural room S with m2f masks instead (labelled map: "
                 "the repair maps the frames again)");
  app.add_flag("--segment-again", segment_again,
               "store no geometric segments, so that the repair segments every frame again (what "
               "keeping them saves)");
  app.add_flag("--reintegrate-only", reintegrate_only,
               "with --room: repair by re-integration only (each frame votes again with the "
               "pixel labels of its first mapping, MapRepairConfig::reassociate off), as "
               "panmap-mapper --repair-reintegrate-only");
  app.add_flag("--occupancy-last", occupancy_last,
               "with --room: the background repair swaps the occupancy tree in with the rest of "
               "the map instead of first (MapRepairConfig::occupancy_first off)");
  app.add_flag("--reintegrate-first", reintegrate_first,
               "with --room: the background repair re-integrates the frames and swaps that map "
               "in (after the occupancy tree, unless --occupancy-last), then maps them again "
               "(MapRepairConfig::reintegrate_first)");
  app.add_option("--frames", frames, "frames in the map when the correction comes")
      ->capture_default_str();
  app.add_option("--voxel-size", voxel_size_m, "voxel size, metres")->capture_default_str();
  app.add_option("--threads", threads, "mapping threads")->capture_default_str();
  app.add_option("--rate-hz", rate_hz, "rate of the frames mapped during the background repair")
      ->capture_default_str();
  app.add_option("--live-frames", live_frames,
                 "frames offered during the background repair at most (0: until it is done)");
  CLI11_PARSE(app, argc, argv);
  namespace fs = std::filesystem;
  std::string temp_dir;
  try {
    if (frames < 1) throw panmap::Error("--frames must be at least 1");
    if (!(rate_hz > 0.0)) throw panmap::Error("--rate-hz must be positive");
    std::string pattern = (fs::temp_directory_path() / "panmap-bench-repair-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw panmap::Error("cannot create a temporary folder");
    temp_dir = pattern;
    // Frame i of the input: the dataset replayed back and forth, or the room's survey (planned
    // long enough for the frames mapped during the background repair too).
    std::unique_ptr<panmap::DatasetReader> reader;
    std::unique_ptr<panmap::SequenceSynthesizer> synth;
    if (room >= 0) {
      const panmap::ProceduralRoom scene =
          panmap::generateRoom(static_cast<uint64_t>(room), panmap::RoomConfig::scanNetLike());
      panmap::SurveyConfig survey;
      survey.num_frames = frames + 400;
      survey.rate_hz = 5.0;
      survey.laps = 2;
      panmap::SynthConfig synth_config;
      synth_config.seed = static_cast<uint64_t>(room);
      synth_config.poses = panmap::PoseDriftConfig::fromPreset("gt");
      synth = std::make_unique<panmap::SequenceSynthesizer>(
          scene.mesh, panmap::planSurvey(scene.mesh, survey, synth_config.seed), synth_config);
      data = "ScanNet-like room " + std::to_string(room) + ", m2f masks";
    } else {
      reader = panmap::openDataset(data, panmap::DatasetOptions{});
      if (reader->size() == 0) throw panmap::Error(data + ": no frames");
    }
    auto input = [&](size_t i) -> std::optional<InputFrame> {
      InputFrame in;
      if (synth) {
        if (i >= synth->size()) return std::nullopt;
        panmap::SynthFrame f = synth->frame(i);
        in.rgbd = std::move(f.rgbd);
        in.T_W_C = f.gt_pose.T_W_C;
        in.panoptic = std::move(f.panoptic);
        return in;
      }
      panmap::DatasetFrame f = replayed(*reader, i);
      in.rgbd = std::move(f.rgbd);
      in.T_W_C = f.T_W_C;
      return in;
    };

    panmap::MapperConfig config;
    config.map.voxel_size_m = voxel_size_m;
    config.num_threads = threads;
    config.tracking_mode = panmap::MapperConfig::TrackingMode::kOff;
    panmap::FrameStoreConfig store_config;
    store_config.folder = temp_dir + "/store";
    panmap::FrameStore store(store_config);
    panmap::Mapper mapper(config);
    std::vector<double> map_ms;
    size_t next = 0;
    // Frames read or rendered ahead of the background repair: a robot's frames come from its
    // camera and network, not from the mapper's cores, so producing them must not compete with
    // the repair being timed.
    std::deque<InputFrame> ahead;
    // Maps the next input frame and stores it as a live mapper does; false when there is none.
    auto mapNext = [&]() {
      std::optional<InputFrame> f;
      if (!ahead.empty()) {
        f = std::move(ahead.front());
        ahead.pop_front();
      } else {
        f = input(next++);
      }
      if (!f) return false;
      if (!f->T_W_C) return true;
      const panmap::PanopticFrame* panoptic = f->panoptic ? &*f->panoptic : nullptr;
      const auto start = Clock::now();
      const panmap::FrameStats s = mapper.integrate(f->rgbd, *f->T_W_C, panoptic);
      map_ms.push_back(msSince(start));
      const panmap::GeometricSegments geometric = mapper.lastGeometricSegments();
      store.add(f->rgbd, s.T_W_C, mapper.lastPixelLabels(), panoptic,
                panoptic && !segment_again ? &geometric : nullptr);
      return true;
    };
    panmap::ProgressLine progress("map + store", "frames");
    while (mapper.trajectory().size() < static_cast<size_t>(frames)) {
      if (!mapNext()) throw panmap::Error("the input ran out of frames");
      progress.update(mapper.trajectory().size(), frames);
    }
    progress.finish();
    const double map_median_ms = panmap::spreadOf(map_ms).median;
    const size_t n = mapper.trajectory().size();

    // What loading the frames alone costs (from the page cache, as right after mapping).
    std::vector<double> load_ms;
    double load_total_ms = 0.0;
    for (const panmap::StampedPose& p : mapper.trajectory()) {
      const auto start = Clock::now();
      const panmap::StoredFrame stored = store.load(p.utime);
      load_ms.push_back(msSince(start));
      load_total_ms += load_ms.back();
    }
    const panmap::PoseCorrection first = driftCorrection(mapper.trajectory(), 1);
    panmap::MapRepairConfig repair_config;
    repair_config.reassociate = !reintegrate_only;
    repair_config.occupancy_first = !occupancy_last;
    repair_config.reintegrate_first = reintegrate_first;
    const panmap::MapRepairResult blocking =
        panmap::repairMap(&mapper, &store, first, repair_config);
    std::printf("blocking repair:   %s\n", panmap::describe(blocking).c_str());
    std::printf("  loading frames   %.2f s alone (%.1f ms median per frame)\n",
                load_total_ms / 1000.0, panmap::spreadOf(load_ms).median);
    std::printf("  per frame        %.1f ms (mapping a frame before: %.1f ms median)\n",
                1000.0 * blocking.reintegration.seconds / static_cast<double>(n), map_median_ms);
    if (!blocking.reintegration.stage_median_ms.empty()) {
      // Where a remap's time goes (occupancy runs beside the super-point stage).
      std::string stages;
      for (const auto& [name, ms] : blocking.reintegration.stage_median_ms) {
        char part[64];
        std::snprintf(part, sizeof(part), "%s%s %.2f", stages.empty() ? "" : ", ", name.c_str(),
                      ms);
        stages += part;
      }
      std::printf("  stages, median ms per frame: %s; ids carried over in %.2f s\n", stages.c_str(),
                  blocking.reintegration.carry_over_s);
    }

    // On its own thread while frames keep coming at rate_hz.
    panmap::BackgroundRepair repair(&mapper, &store, repair_config);
    const panmap::PoseCorrection second = driftCorrection(mapper.trajectory(), 2);
    map_ms.clear();
    const auto period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
    const size_t read_ahead = live_frames > 0 ? static_cast<size_t>(live_frames) : kReadAhead;
    while (ahead.size() < read_ahead) {
      std::optional<InputFrame> f = input(next++);
      if (!f) break;
      ahead.push_back(std::move(*f));
    }
    const size_t prepared = ahead.size();
    const auto start = Clock::now();
    repair.start(second);
    std::optional<panmap::MapRepairResult> done;
    auto due = Clock::now();
    int offered = 0;
    while (!done) {
      if (live_frames > 0 && offered >= live_frames) {
        done = repair.finish();
        break;
      }
      std::this_thread::sleep_until(due);  // the camera's rate, not a wait for the repair
      due += period;
      if (!mapNext()) {  // the rendered survey is over: wait for the repair
        done = repair.finish();
        break;
      }
      ++offered;
      repair.frameIntegrated();
      done = repair.poll();
    }
    const double wall_s = msSince(start) / 1000.0;
    std::printf("background repair: %s\n", panmap::describe(*done).c_str());
    std::printf(
        "  %d frames mapped meanwhile at %.1f Hz: %.1f ms median, %.1f ms p95 each "
        "(before: %.1f ms median); swapped in %.2f s after the correction\n",
        offered, rate_hz, panmap::spreadOf(map_ms).median, panmap::spreadOf(map_ms).p95,
        map_median_ms, wall_s);
    if (static_cast<size_t>(offered) > prepared) {
      std::printf("  (%zu of them %s while the repair ran: more than the %zu prepared ahead)\n",
                  static_cast<size_t>(offered) - prepared, synth ? "rendered" : "decoded",
                  prepared);
    }
    std::printf("machine: %u hardware threads; %zu frames of %s at %.0f cm, mapping threads %d\n",
                std::thread::hardware_concurrency(), n, data.c_str(), voxel_size_m * 100.0,
                threads);
    fs::remove_all(temp_dir);
    return done && done->reintegration.completed ? 0 : 1;
  } catch (const std::exception& e) {
    if (!temp_dir.empty()) fs::remove_all(temp_dir);
    std::fprintf(stderr, "panmap-bench-repair: %s\n", e.what());
    return 1;
  }
}
