/// @file bench_open3d.cpp
/// @brief panmap-bench-open3d: Open3D's ScalableTSDFVolume integration timed on exactly the
/// frames panmap-bench-mapping maps, so the two can be compared side by side.
///
/// Issue 9 asks for "label-TSDF integration alone at least 2x faster than Open3D's
/// ScalableTSDFVolume at the same voxel size". This tool produces the Open3D side of that
/// comparison; the panmap side is the "integration" stage of panmap-bench-mapping.
///
/// What is measured: the wall time of each open3d::pipelines::integration::ScalableTSDFVolume::
/// Integrate() call (std::chrono::steady_clock), median and p95 over the frames, with RGB8
/// colour, sdf_trunc = truncation_voxels * voxel size and Open3D's defaults otherwise (16^3
/// voxel units, depth sampling stride 4 to find the units in view). Not timed: decoding
/// (every frame is decoded first, as in panmap-bench-mapping) and the conversion of a frame into
/// an open3d::geometry::RGBDImage (uint16 depth to float metres, cut to [min, max] depth like
/// our IntegratorConfig), reported apart as "rgbd_conversion". After the last frame the mesh is
/// extracted once (marching cubes) and its vertex count and bounds are reported, so a wrong
/// conversion (depth scale, transposed extrinsic) shows up as a mesh in the wrong place.
///
/// Frames: from a dataset folder (panmap::openDataset, frames without a valid pose skipped, as
/// panmap-bench-mapping does) or from an LCM log (CAMERA_RGBD and CAMERA_POSE decoded and matched
/// by panmap::FrameSynchronizer with the same defaults as panmap-mapper --log; poses are used as
/// recorded, i.e. without the pose refinement our mapper applies to SLAM poses).
///
/// What Open3D does per frame (its algorithm, unchanged here): it back-projects every 4th
/// pixel to find the 16^3-voxel units within sdf_trunc of the surface, then projects every voxel
/// of those units (one OpenMP loop per unit) and updates all that lie in front of the surface or
/// less than sdf_trunc behind it, free space included (clamped to +1); weights are not capped.
/// Ours (ProjectiveIntegrator) allocates 8^3 blocks along the truncation band of every few rays.
///
/// Threads: Open3D 0.16's loops are `omp parallel for num_threads(EstimateMaxThreads())`, and
/// EstimateMaxThreads() is omp_get_max_threads() only when OMP_NUM_THREADS (or OMP_DYNAMIC) is
/// set, else the number of physical cores: omp_set_num_threads() alone is ignored. So --threads N
/// sets OMP_NUM_THREADS=N in the environment (read by Open3D at every call) and calls libgomp's
/// omp_set_num_threads(N) (libgomp read the variable when it was loaded, before main; looked up
/// at run time as the target does not link OpenMP itself). --threads 0 leaves both alone.
/// Reported: the threads Open3D will use, and the CPU time per wall time of the Integrate calls
/// (close to the thread count when the threads really run side by side).
///
/// Load: on a shared machine wall times have random spikes. With one thread the per-frame CPU
/// time ("integration_cpu") stays close to the unloaded wall time. With two, Open3D suffers far
/// more than ours: its OpenMP region per unit (hundreds per frame) waits at a barrier whenever
/// one of its threads is descheduled, and libgomp's spinning inflates the CPU time as well;
/// "integration_cpu_per_wall" well under the thread count, or --per-frame, shows such runs.
///
///   panmap-bench-open3d [--data DIR | --log FILE] [--voxel-size M] [--threads N] [--frames N]
///       [--truncation-voxels V] [--min-depth-m M] [--max-depth-m M] [--json FILE]
///       [--mesh FILE.ply] [--per-frame] [--markdown-row]
#include <dlfcn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include <open3d/Open3DConfig.h>
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Parallel.h>

#include "panmap/core/error.h"
#include "panmap/core/process_memory.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/decode.h"
#include "panmap/lcm/mapping_session.h"
#include "panmap/mapper/frame_sync.h"

namespace {

using Clock = std::chrono::steady_clock;

/// A decoded frame and its camera-to-world pose.
struct InputFrame {
  panmap::RgbdFrame rgbd;
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
};

/// Frames read, and what was left out with the reason.
struct Input {
  std::vector<InputFrame> frames;
  std::string layout;                       ///< dataset layout, or "lcm-log"
  std::map<std::string, int64_t> rejected;  ///< reason -> frames (or messages)
  int64_t log_events = 0;                   ///< events read from a log
};

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// CPU time of the process (all threads, user + system), milliseconds.
double cpuMs() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * t.tv_sec + 1e-6 * t.tv_nsec;
}

Input readDataset(const std::string& dir, int max_frames) {
  const auto reader = panmap::openDataset(dir, panmap::DatasetOptions{});
  const size_t n = max_frames > 0 ? std::min<size_t>(max_frames, reader->size()) : reader->size();
  Input input;
  input.layout = reader->layoutName();
  for (size_t i = 0; i < n; ++i) {
    panmap::DatasetFrame f = reader->read(i);
    if (!f.T_W_C) {  // panmap-bench-mapping skips these too
      ++input.rejected["frame: no pose"];
      continue;
    }
    input.frames.push_back({std::move(f.rgbd), *f.T_W_C});
  }
  return input;
}

/// The frames panmap-mapper --log would map: the same channels, decoding and synchroniser
/// (stream time = newest event timestamp), stopping after max_frames ready frames.
Input readLog(const std::string& path, int max_frames) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw panmap::Error("log " + path + " does not exist");
  lcm::LogFile log(path, "r");
  if (!log.good()) throw panmap::Error("cannot open log " + path);
  const panmap::SessionOptions options;
  panmap::FrameSynchronizer sync(options.sync);
  Input input;
  input.layout = "lcm-log";
  auto full = [&] { return max_frames > 0 && input.frames.size() >= size_t(max_frames); };
  auto take = [&](std::vector<panmap::SyncedFrame> ready) {
    for (panmap::SyncedFrame& f : ready) {
      if (full()) return;
      input.frames.push_back({std::move(f.frame), f.T_W_C});
    }
  };
  int64_t newest = INT64_MIN;
  while (!full()) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) break;
    ++input.log_events;
    newest = std::max(newest, e->timestamp);
    try {
      if (e->channel == options.channel_rgbd) {
        panmap::rgbd_frame_t msg;
        if (!panmap::decodeExactly(e->data, static_cast<size_t>(e->datalen), &msg)) {
          ++input.rejected["malformed " + e->channel];
          continue;
        }
        sync.addFrame(panmap::fromMessage(msg));
      } else if (e->channel == options.channel_pose) {
        panmap::pose_t msg;
        if (!panmap::decodeExactly(e->data, static_cast<size_t>(e->datalen), &msg)) {
          ++input.rejected["malformed " + e->channel];
          continue;
        }
        sync.addPose(panmap::fromMessage(msg));
      } else if (e->channel == options.channel_panoptic) {
        // Only its arrival matters here (a frame waits for its mask), not its content.
        panmap::panoptic_t msg;
        if (!panmap::decodeExactly(e->data, static_cast<size_t>(e->datalen), &msg)) {
          ++input.rejected["malformed " + e->channel];
          continue;
        }
        panmap::PanopticFrame panoptic;
        panoptic.utime = msg.utime;
        panoptic.frame_id = msg.frame_id;
        sync.addPanoptic(std::move(panoptic));
      } else {
        continue;
      }
    } catch (const panmap::Error& error) {
      ++input.rejected["bad " + e->channel + ": " + panmap::reasonOf(error.what())];
      continue;
    }
    take(sync.popReady(newest));
  }
  if (input.log_events == 0) throw panmap::Error(path + " is not an LCM log (no event read)");
  if (!full()) take(sync.flush());
  const panmap::SyncStats& s = sync.stats();
  if (s.rejected_no_pose) input.rejected["frame: no pose"] += s.rejected_no_pose;
  if (s.dropped_queue_full)
    input.rejected["frame: synchroniser queue full"] += s.dropped_queue_full;
  return input;
}

/// Open3D's input for one frame: depth as float metres (0 outside [min_depth_m, max_depth_m]),
/// colour RGB8 (mid grey when the frame has none).
std::shared_ptr<open3d::geometry::RGBDImage> toRgbdImage(const panmap::RgbdFrame& f,
                                                         double min_depth_m, double max_depth_m) {
  const int w = f.camera.width, h = f.camera.height;
  open3d::geometry::Image depth;
  depth.Prepare(w, h, 1, 2);
  // Open3D has no near limit: raw values below it become 0 (no measurement), like ours ignores
  // them. The far limit is Open3D's own depth_trunc.
  const double min_raw = min_depth_m / f.depth_scale_m;
  auto* d = depth.PointerAs<uint16_t>();
  const uint16_t* src = f.depth.data();
  for (size_t i = 0, n = size_t(w) * h; i < n; ++i) d[i] = src[i] < min_raw ? 0 : src[i];
  open3d::geometry::Image color;
  color.Prepare(w, h, 3, 1);
  if (f.color.width() == w && f.color.height() == h) {
    static_assert(sizeof(panmap::Rgb8) == 3, "Rgb8 is packed r, g, b");
    std::copy_n(reinterpret_cast<const uint8_t*>(f.color.data()), color.data_.size(),
                color.data_.begin());
  } else {
    std::fill(color.data_.begin(), color.data_.end(), uint8_t{128});
  }
  // depth_scale: raw units per metre.
  return open3d::geometry::RGBDImage::CreateFromColorAndDepth(
      color, depth, 1.0 / f.depth_scale_m, max_depth_m, /*convert_rgb_to_intensity=*/false);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Time Open3D's ScalableTSDFVolume::Integrate (RGB8) on the frames panmap-bench-mapping "
      "maps: median and p95 per frame, peak memory, mesh size and bounds (JSON on stdout)."};
  std::string data = "../shared/data/7scenes-200", json_path, log_path, mesh_path;
  double voxel_size_m = 0.01, truncation_voxels = 4.0, min_depth_m = 0.1, max_depth_m = 3.5;
  int threads = 2, frames = 0;
  bool markdown = false, per_frame = false;
  auto* data_opt =
      app.add_option("--data", data, "dataset folder (7-Scenes, ScanNet export or TUM)")
          ->capture_default_str();
  app.add_option("--log", log_path,
                 "read the frames of an LCM log instead (CAMERA_RGBD + CAMERA_POSE, matched as "
                 "panmap-mapper --log does)")
      ->excludes(data_opt);
  app.add_option("--frames", frames, "frames to integrate (0 = all)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--voxel-size", voxel_size_m, "metres")
      ->check(CLI::Range(1e-4, 1.0))
      ->capture_default_str();
  app.add_option("--truncation-voxels", truncation_voxels,
                 "sdf_trunc in voxels (our IntegratorConfig::truncation_voxels)")
      ->check(CLI::Range(0.5, 100.0))
      ->capture_default_str();
  app.add_option("--threads", threads,
                 "OpenMP threads for Open3D (0 = Open3D's default: OMP_NUM_THREADS if set, else "
                 "the physical cores)")
      ->check(CLI::Range(0, 256))
      ->capture_default_str();
  app.add_option("--min-depth-m", min_depth_m, "nearer depth is ignored (IntegratorConfig)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--max-depth-m", max_depth_m, "farther depth is ignored (Open3D's depth_trunc)")
      ->check(CLI::Range(0.01, 100.0))
      ->capture_default_str();
  app.add_option("--json", json_path, "also write the figures as JSON to this file");
  app.add_option("--mesh", mesh_path, "write the extracted mesh as PLY (to compare geometry)");
  app.add_flag("--per-frame", per_frame,
               "add every frame's Integrate wall and CPU time (ms) to the JSON, in frame order");
  app.add_flag("--markdown-row", markdown,
               "print one Markdown table row instead of JSON: | voxel | threads | frames | "
               "median / p95 ms | peak RSS MB |");
  CLI11_PARSE(app, argc, argv);
  try {
    if (min_depth_m >= max_depth_m) {
      throw panmap::Error("--min-depth-m must be below --max-depth-m");
    }
    open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);

    // Threads (see the header comment): both OMP_NUM_THREADS and OpenMP's team size.
    using OmpSetThreads = void (*)(int);
    using OmpGetMaxThreads = int (*)();
    const auto omp_set =
        reinterpret_cast<OmpSetThreads>(dlsym(RTLD_DEFAULT, "omp_set_num_threads"));
    const auto omp_max =
        reinterpret_cast<OmpGetMaxThreads>(dlsym(RTLD_DEFAULT, "omp_get_max_threads"));
    if (threads > 0) {
      setenv("OMP_NUM_THREADS", std::to_string(threads).c_str(), 1);
      if (omp_set) omp_set(threads);
    }
    const int open3d_threads = open3d::utility::EstimateMaxThreads();
    const int omp_threads = omp_max ? omp_max() : 1;
    if (threads > 0 && open3d_threads != threads) {
      throw panmap::Error("--threads " + std::to_string(threads) + ": Open3D would use " +
                          std::to_string(open3d_threads) +
                          (omp_set ? "" : " (no OpenMP runtime found)"));
    }
    const char* omp_env = std::getenv("OMP_NUM_THREADS");

    // Decode everything first: the benchmark times integration, not JPEG/PNG decoding.
    Input input = log_path.empty() ? readDataset(data, frames) : readLog(log_path, frames);
    const std::string source = log_path.empty() ? data : log_path;
    if (input.frames.empty()) throw panmap::Error("no frame with a pose in " + source);
    const size_t rss_before = panmap::residentBytes();

    const double sdf_trunc = truncation_voxels * voxel_size_m;
    open3d::pipelines::integration::ScalableTSDFVolume volume(
        voxel_size_m, sdf_trunc, open3d::pipelines::integration::TSDFVolumeColorType::RGB8);
    std::vector<double> integrate_ms, integrate_cpu_ms, convert_ms;
    for (size_t i = 0; i < input.frames.size(); ++i) {
      const InputFrame& in = input.frames[i];
      const panmap::PinholeCamera& cam = in.rgbd.camera;
      auto t0 = Clock::now();
      const auto rgbd = toRgbdImage(in.rgbd, min_depth_m, max_depth_m);
      const open3d::camera::PinholeCameraIntrinsic intrinsic(cam.width, cam.height, cam.fx, cam.fy,
                                                             cam.cx, cam.cy);
      const Eigen::Matrix4d extrinsic = in.T_W_C.inverse().matrix();  // world -> camera
      convert_ms.push_back(msSince(t0));
      const double cpu0 = cpuMs();
      t0 = Clock::now();
      volume.Integrate(*rgbd, intrinsic, extrinsic);
      integrate_ms.push_back(msSince(t0));
      integrate_cpu_ms.push_back(cpuMs() - cpu0);
      if (!markdown && (i + 1) % 50 == 0) {
        std::fprintf(stderr, "\rintegrated %zu / %zu frames", i + 1, input.frames.size());
      }
    }
    if (!markdown && input.frames.size() >= 50) std::fprintf(stderr, "\n");

    const auto t0 = Clock::now();
    const auto mesh = volume.ExtractTriangleMesh();
    const double mesh_ms = msSince(t0);
    if (!mesh_path.empty() && !open3d::io::WriteTriangleMesh(mesh_path, *mesh)) {
      throw panmap::Error("cannot write mesh " + mesh_path);
    }
    const size_t peak_rss = panmap::peakResidentBytes();
    const size_t units = volume.volume_units_.size();
    const size_t unit_voxels = size_t(volume.volume_unit_resolution_) *
                               volume.volume_unit_resolution_ * volume.volume_unit_resolution_;
    const Eigen::Vector3d lo = mesh->HasVertices() ? mesh->GetMinBound() : Eigen::Vector3d::Zero();
    const Eigen::Vector3d hi = mesh->HasVertices() ? mesh->GetMaxBound() : Eigen::Vector3d::Zero();

    const panmap::StageTiming integration = panmap::summariseTimes(integrate_ms);
    const panmap::StageTiming conversion = panmap::summariseTimes(convert_ms);
    const panmap::StageTiming integration_cpu = panmap::summariseTimes(integrate_cpu_ms);
    double integrate_wall_ms = 0.0, integrate_total_cpu_ms = 0.0;
    for (double ms : integrate_ms) integrate_wall_ms += ms;
    for (double ms : integrate_cpu_ms) integrate_total_cpu_ms += ms;
    const nlohmann::json integration_json = {{"median_ms", integration.median_ms},
                                             {"p95_ms", integration.p95_ms}};
    nlohmann::json out = {
        {"tool", "open3d ScalableTSDFVolume"},
        {"open3d_version", OPEN3D_VERSION},
        {"data", source},
        {"layout", input.layout},
        {"frames", integrate_ms.size()},
        {"frames_rejected", input.rejected},
        {"voxel_size_m", voxel_size_m},
        {"sdf_trunc_m", sdf_trunc},
        {"truncation_voxels", truncation_voxels},
        {"depth_range_m", {min_depth_m, max_depth_m}},
        {"threads", open3d_threads},
        {"threads_requested", threads},
        {"openmp",
         {{"runtime", omp_set != nullptr},
          {"omp_num_threads_env", omp_env ? omp_env : ""},
          {"omp_max_threads", omp_threads},
          {"open3d_max_threads", open3d_threads},
          {"integration_cpu_per_wall",
           integrate_total_cpu_ms / std::max(integrate_wall_ms, 1e-9)}}},
        {"integration", integration_json},
        // CPU time of all threads per Integrate call: with one thread, close to the wall time
        // of an unloaded machine even when others run (not so with two: libgomp spins).
        {"integration_cpu",
         {{"median_ms", integration_cpu.median_ms}, {"p95_ms", integration_cpu.p95_ms}}},
        {"integration_total_s", integrate_wall_ms / 1000.0},
        {"stages",
         {{"integration", integration_json},
          {"rgbd_conversion",
           {{"median_ms", conversion.median_ms}, {"p95_ms", conversion.p95_ms}}}}},
        {"volume_units", units},
        {"voxels", units * unit_voxels},
        {"rss_before_integration_bytes", rss_before},
        {"peak_rss_bytes", peak_rss},
        {"final_mesh_ms", mesh_ms},
        {"mesh_vertices", mesh->vertices_.size()},
        {"mesh_triangles", mesh->triangles_.size()},
        {"mesh_bounds_m", {{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}}}};
    if (per_frame) {
      out["per_frame_ms"] = integrate_ms;
      out["per_frame_cpu_ms"] = integrate_cpu_ms;
    }
    std::fprintf(stderr,
                 "open3d mesh: %zu vertices, bounds [%.3f %.3f %.3f] .. [%.3f %.3f %.3f] m\n",
                 mesh->vertices_.size(), lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
    if (markdown) {
      std::printf("| %g cm | %d | %zu | %.1f / %.1f | %.0f |\n", voxel_size_m * 100.0,
                  open3d_threads, integrate_ms.size(), integration.median_ms, integration.p95_ms,
                  peak_rss / 1048576.0);
    } else {
      std::printf("%s\n", out.dump(2).c_str());
    }
    if (!json_path.empty()) {
      std::ofstream file(json_path);
      if (!(file << out.dump(2) << "\n")) throw panmap::Error("cannot write " + json_path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-open3d: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
