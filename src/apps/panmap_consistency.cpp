// panmap-consistency: how well trajectories of one RGB-D sequence agree with its colour
// images. Each frame's depth pixels are carried into later frames by the trajectory's poses
// and the grey levels compared. Depth-based tracking never looks at colour, so this judges a
// refined trajectory and a dataset's recorded one without taking either as the truth.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/progress.h"
#include "panmap/eval/photometric_consistency.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/tum_trajectory.h"

int main(int argc, char** argv) {
  panmap::applyMemoryPolicy(argv);  // panmap-mapper's allocation policy
  CLI::App app{
      "Photometric consistency of camera trajectories over an RGB-D dataset folder: the median "
      "grey-level difference between each frame's strongly textured pixels and where the "
      "poses carry them in later frames (after a per-pair exposure offset). Lower is more "
      "consistent. Every trajectory is scored on the same pixels: those all of them carry "
      "unoccluded into the later frame. Colour must be registered to depth (7-Scenes is treated as "
      "registered)."};
  std::string data_dir, layout = "auto", json_path;
  std::vector<std::string> trajectories;
  panmap::PhotometricConfig config;
  size_t max_frames = 0;
  app.add_option("--data", data_dir,
                 "dataset folder, or a ScanNet .sens file (as panmap-import "
                 "reads it)")
      ->required();
  app.add_option("--layout", layout, "auto, 7scenes, scannet, scannet-sens, tum or folder")
      ->capture_default_str();
  app.add_option("--max-frames", max_frames,
                 "read at most this many frames, from the first (0: all; as panmap-import "
                 "--max-frames: every frame is held in memory)")
      ->capture_default_str();
  app.add_option("--traj", trajectories, "TUM trajectory to score (repeat for several)")
      ->required();
  app.add_option("--gaps", config.frame_gaps, "frame gaps of the pairs (1,3,10 or 1 3 10)")
      ->capture_default_str()
      ->delimiter(',');
  app.add_option("--stride", config.pixel_stride, "pixel stride")->capture_default_str();
  app.add_option("--min-gradient", config.min_gradient, "grey levels per pixel")
      ->capture_default_str();
  app.add_option("--json", json_path, "write the results as JSON to this file");
  CLI11_PARSE(app, argc, argv);

  try {
    config.check();
    // Trajectories first: a bad file fails before the frames are read.
    std::vector<std::vector<panmap::StampedPose>> poses;
    for (const std::string& path : trajectories) poses.push_back(panmap::readTumTrajectory(path));
    panmap::DatasetOptions options;
    options.layout = panmap::parseDatasetLayout(layout);
    const auto reader = panmap::openDataset(data_dir, options);
    const size_t count = max_frames ? std::min(max_frames, reader->size()) : reader->size();
    std::vector<panmap::PhotometricFrame> frames;
    frames.reserve(count);
    panmap::ProgressLine progress("read", "frames");
    for (size_t i = 0; i < count; ++i) {
      panmap::DatasetFrame frame = reader->read(i);
      if (frame.rgbd.color.empty()) {
        throw panmap::Error(data_dir + ": frame " + std::to_string(i) + " has no colour image");
      }
      panmap::PhotometricFrame f;
      f.utime = frame.rgbd.utime;
      f.camera = frame.rgbd.camera;
      f.depth_scale_m = frame.rgbd.depth_scale_m;
      f.depth = std::move(frame.rgbd.depth);
      f.grey = panmap::toGrey(frame.rgbd.color);
      frames.push_back(std::move(f));
      progress.update(i + 1, count);
    }
    progress.finish();
    const std::vector<panmap::PhotometricResult> results =
        panmap::photometricConsistency(frames, poses, config);
    nlohmann::json out = nlohmann::json::array();
    for (size_t t = 0; t < trajectories.size(); ++t) {
      const panmap::PhotometricResult& r = results[t];
      std::printf(
          "%s: median |residual| %.3f grey levels (mean of pair medians %.3f), %zu pairs, "
          "%zu samples, %zu of %zu frames posed\n",
          trajectories[t].c_str(), r.median_abs, r.mean_pair_median, r.pairs, r.samples,
          r.frames_posed, frames.size());
      out.push_back({{"trajectory", trajectories[t]},
                     {"median_abs", r.median_abs},
                     {"mean_pair_median", r.mean_pair_median},
                     {"pairs", r.pairs},
                     {"samples", r.samples},
                     {"frames_posed", r.frames_posed}});
    }
    if (!json_path.empty()) {
      std::ofstream file(json_path);
      file << out.dump(2) << "\n";
      file.close();
      if (!file) throw panmap::Error(json_path + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-consistency: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
