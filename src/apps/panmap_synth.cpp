// panmap-synth: renders a labelled mesh (a procedural room, a building of them or a ScanNet
// scene's ground truth)
// along a camera trajectory into an LCM log with RGB-D frames, drifting poses and simulated
// panoptic masks, plus the ground truth to evaluate against.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>

#include <nlohmann/json.hpp>
#include "cli_checks.h"

#include "panmap/building/building.h"
#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/progress.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/ply.h"
#include "panmap/io/scannet_ground_truth.h"
#include "panmap/io/semantic_mask_reader.h"
#include "panmap/lcm/channels.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/log_writer.h"
#include "panmap/sim/instance_parts.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/sequence.h"
#include "panmap/sim/unannotation.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json masksJson(const panmap::SegmenterNoiseConfig& c) {
  return {{"preset", c.preset},
          {"window_frames", c.window_frames},
          {"miss_probability_small", c.miss_probability_small},
          {"miss_probability_large", c.miss_probability_large},
          {"miss_small_px", c.miss_small_px},
          {"miss_large_px", c.miss_large_px},
          {"miss_probability_occluded", c.miss_probability_occluded},
          {"boundary_mean_px", c.boundary_mean_px},
          {"boundary_grid_px", c.boundary_grid_px},
          {"confusion_probability", c.confusion_probability},
          {"confusion_groups", c.confusion_groups},
          {"merge_probability", c.merge_probability},
          {"split_probability", c.split_probability},
          {"split_min_extent_m", c.split_min_extent_m},
          {"false_positives_per_frame", c.false_positives_per_frame},
          {"clutter_stuff_probability", c.clutter_stuff_probability},
          {"clutter_thing_probability", c.clutter_thing_probability},
          {"clutter_thing_classes", c.clutter_thing_classes},
          {"clutter_thing_weights", c.clutter_thing_weights},
          {"sample_scores", c.sample_scores},
          {"true_score_beta", {c.true_score_alpha, c.true_score_beta}},
          {"wrong_score_beta", {c.wrong_score_alpha, c.wrong_score_beta}}};
}

json posesJson(const panmap::PoseDriftConfig& c) {
  return {{"preset", c.preset},
          {"translation_drift_per_m", c.translation_drift_per_m},
          {"rotation_drift_deg_per_m", c.rotation_drift_deg_per_m},
          {"rotation_drift_deg_per_90deg", c.rotation_drift_deg_per_90deg},
          {"bias_correlation_m", c.bias_correlation_m},
          {"jitter_translation_m", c.jitter_translation_m},
          {"jitter_rotation_deg", c.jitter_rotation_deg}};
}

json depthJson(const panmap::DepthNoiseConfig& c) {
  return {{"enabled", c.enabled},
          {"axial_sigma_m", "a + b (z - z0)^2"},
          {"axial_sigma_a_m", c.axial_sigma_a_m},
          {"axial_sigma_b_m", c.axial_sigma_b_m},
          {"axial_z0_m", c.axial_z0_m},
          {"lateral_sigma_px", c.lateral_sigma_px},
          {"quantization_m", c.quantization_m},
          {"range_m", {c.min_range_m, c.max_range_m}},
          {"grazing_dropout_deg", {c.grazing_start_deg, c.grazing_full_deg}},
          {"edge_ratio", c.edge_ratio},
          {"edge_dropout", c.edge_dropout}};
}

// False-colour PNGs of one frame, for looking at what the sequence contains.
void writePreview(const std::string& out_dir, const panmap::SynthFrame& f) {
  fs::create_directories(out_dir + "/preview");
  char stem[64];
  std::snprintf(stem, sizeof(stem), "%s/preview/%06lld", out_dir.c_str(),
                static_cast<long long>(f.rgbd.frame_id));
  panmap::writeFileBytes(std::string(stem) + "_color.png", panmap::encodePng(f.rgbd.color));
  panmap::ColorImage depth(f.rgbd.depth.width(), f.rgbd.depth.height());
  panmap::ColorImage masks(depth.width(), depth.height());
  for (size_t i = 0; i < depth.size(); ++i) {
    const auto g = static_cast<uint8_t>(std::min(255.0, f.rgbd.depth.data()[i] * 255.0 / 6000.0));
    depth.data()[i] = panmap::Rgb8{g, g, g};
    const uint32_t id = static_cast<uint32_t>(f.panoptic.segment_ids.data()[i]);
    const uint32_t h = id ? id * 2654435761u : 0u;
    masks.data()[i] = panmap::Rgb8{static_cast<uint8_t>(h >> 24), static_cast<uint8_t>(h >> 16),
                                   static_cast<uint8_t>(h >> 8)};
  }
  panmap::writeFileBytes(std::string(stem) + "_depth.png", panmap::encodePng(depth));
  panmap::writeFileBytes(std::string(stem) + "_masks.png", panmap::encodePng(masks));
}

}  // namespace

int main(int argc, char** argv) {
  panmap::applyMemoryPolicy(argv);  // panmap-mapper's allocation policy
  CLI::App app{
      "Render a labelled mesh along a camera trajectory into an LCM log (CAMERA_RGBD, "
      "CAMERA_POSE, PANOPTIC) with sensor noise, segmenter errors and SLAM-like pose drift, "
      "and write the ground truth beside it:\n  OUT/sequence.lcmlog, OUT/gt/mesh.ply, "
      "OUT/gt/instances.txt, OUT/gt/trajectory_gt.txt, OUT/gt/trajectory_input.txt, "
      "OUT/info.json"};
  int64_t room_seed = -1;
  // The shipped data's copy, for runs from the repository's root (its scenes keep it apart).
  const std::string shipped_labels = "../shared/data/scannet-meta/scannetv2-labels.combined.tsv";
  std::string scannet_dir, scannet_labels;
  std::string trajectory_file, masks = "m2f", poses = "slam", out_dir;
  int frames = 300;
  uint64_t seed = 1;
  bool quiet = false, no_depth_noise = false;
  double image_scale = 1.0;
  int preview_every = 0;
  panmap::UnannotateConfig unannotate_config;
  std::string unannotated_masks = "painted";
  bool join_parts = false, semantic_masks = false;
  auto* source = app.add_option_group("source", "ground-truth mesh (one of)");
  // panmap::cli::nonNegative() would print the double range up to 1.8e308 in its message.
  const CLI::Validator seed_check(
      [](const std::string& text) {
        return !text.empty() && text[0] != '-' ? std::string()
                                               : "a seed is an integer >= 0, not " + text;
      },
      "SEED");
  source->add_option("--room", room_seed, "procedural room with this seed")->check(seed_check);
  int64_t building_seed = -1;
  panmap::BuildingConfig building_config;
  source
      ->add_option("--building", building_seed,
                   "procedural building with this seed: rooms of --room-style along a "
                   "corridor, walked once through every room at 5 Hz unless --frames or "
                   "--rate-hz say otherwise")
      ->check(seed_check);
  source->add_option("--scannet", scannet_dir,
                     "ScanNet scene folder (<scene>_vh_clean_2.ply, .aggregation.json, "
                     "_vh_clean_2.0.010000.segs.json)");
  source->require_option(1);
  std::string room_style = "boxes";
  app.add_option("--room-style", room_style,
                 "procedural room style: boxes (furniture only) or scannet (30-60 instances, small "
                 "objects, clutter against furniture and walls, unannotated piles)")
      ->capture_default_str()
      ->check(CLI::IsMember({"boxes", "scannet"}));
  app.add_option("--building-rooms", building_config.min_rooms,
                 "a building has at least this many rooms")
      ->capture_default_str()
      ->check(CLI::Range(1, 200));
  app.add_option("--building-area", building_config.min_floor_area_m2,
                 "a building has at least this much floor, square metres")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 20000.0));
  auto* labels_option = app.add_option("--scannet-labels", scannet_labels,
                                       "ScanNet label table (tsv); default: the one in the "
                                       "scene folder, its parent or its grandparent, else " +
                                           shipped_labels);
  app.add_option("--trajectory", trajectory_file, "TUM trajectory to follow instead of a survey");
  std::string recording;
  app.add_option("--recording", recording,
                 "a real recording of the scene instead of rendered frames: a dataset folder or "
                 "ScanNet .sens file as panmap-import reads it, whose depth, colour and poses (the "
                 "ground truth) go into the log as recorded, with masks from the mesh rendered "
                 "at each pose (--scannet with the scan's own reconstruction; "
                 "docs/SIMULATION.md)");
  size_t every = 1;
  app.add_option("--every", every,
                 "with --recording: take every Nth recorded frame (ScanNet records at 30 Hz: 6 "
                 "gives the accuracy suite's 5 Hz)")
      ->check(panmap::cli::positive());
  app.add_option("--frames", frames,
                 "frames to render (the survey ends where they do: see --cover-walk; with "
                 "--trajectory, every pose unless given)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  bool cover_walk = false;
  app.add_flag("--cover-walk", cover_walk,
               "render as many frames as walking the whole survey takes (every lap, at its "
               "0.35 m/s), --frames being the least: a scene larger than --frames can walk is "
               "then seen whole (a real scene's size is not known in advance)");
  double area_per_stop_m2 = panmap::SurveyConfig().area_per_stop_m2;
  app.add_option("--area-per-stop", area_per_stop_m2,
                 "a survey spreads one stop per this much free floor, m^2, where that gives more "
                 "than 10 (0: always 10; docs/SIMULATION.md)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  double rate_hz = 30.0;
  app.add_option("--rate-hz", rate_hz,
                 "frame rate of the survey (a lower rate covers more of the room per frame)")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 120.0));
  int laps = 1;
  app.add_option("--laps", laps,
                 "times the survey passes every area (odd laps forward, even laps backward)")
      ->capture_default_str()
      ->check(CLI::Range(1, 20));
  app.add_option("--masks", masks, "segmenter noise preset: clean, m2f, hard")
      ->capture_default_str()
      ->check(CLI::IsMember({"clean", "m2f", "hard"}));
  app.add_option("--poses", poses, "pose preset: gt, slam, slam-hard, light, heavy")
      ->capture_default_str()
      ->check(CLI::IsMember({"gt", "slam", "slam-hard", "light", "heavy"}));
  app.add_option("--seed", seed, "seed of trajectory, noise, masks and drift")
      ->check(panmap::cli::nonNegative())
      ->capture_default_str();
  app.add_flag("--no-depth-noise", no_depth_noise, "exact depth (quantised to 1 mm)");
  app.add_option("--image-scale", image_scale,
                 "images this many times 640x480 (same field of view; the noise models' pixel "
                 "sizes scale with them, docs/SIMULATION.md)")
      ->check(CLI::Range(0.25, 4.0));
  std::string depth_pattern_file;
  double depth_pattern_scale = 1.0;
  app.add_option("--depth-pattern", depth_pattern_file,
                 "add the fixed-pattern depth error of a real sensor to every frame: the sensor's "
                 "calibration as panmap-calibrate-depth writes it (the error is its negative; "
                 "docs/SIMULATION.md)")
      ->check(CLI::ExistingFile);
  app.add_option("--depth-pattern-scale", depth_pattern_scale,
                 "multiply that error by this (0.5: a sensor with half the Kinect's pattern)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  size_t correction_every = 0;
  panmap::CorrectionResidual residual;
  double residual_cm = 0.0, residual_deg = 0.0;
  app.add_option("--correction-every", correction_every,
                 "end the log with the loop-closure correction a SLAM back-end would publish on "
                 "PANMAP_POSE_CORRECTION once the survey is back at its start (--laps 2): the "
                 "ground-truth poses of every Nth frame (keyframes) and of the last one "
                 "(docs/LOOP_CLOSURE.md)")
      ->check(panmap::cli::positive());
  app.add_option("--correction-residual-cm", residual_cm,
                 "the correction's residual error: each keyframe pose off by this much per axis "
                 "(standard deviation, drawn with --seed)")
      ->check(panmap::cli::nonNegative());
  app.add_option("--correction-residual-deg", residual_deg,
                 "and turned by this much per axis (standard deviation)")
      ->check(panmap::cli::nonNegative());
  app.add_option("--unannotate", unannotate_config.fraction,
                 "leave this share of the ground truth's vertices without a class (whole objects "
                 "and clutter patches, drawn with --seed; vertices already without one count)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.95));
  app.add_option("--unannotated-masks", unannotated_masks,
                 "what the simulated network does on unannotated surfaces: painted (a network "
                 "labels stripped objects as what they are and clutter per the preset's clutter "
                 "rates) or empty (no mask on anything unannotated)")
      ->capture_default_str()
      ->check(CLI::IsMember({"painted", "empty"}));
  app.add_flag("--semantic-masks", semantic_masks,
               "a semantic network instead of a panoptic one: each frame's masks keep their "
               "classes and lose their instances, which come back as panmap-import "
               "--masks-format semantic makes them (each connected region of a thing class one "
               "instance)");
  app.add_flag("--join-parts", join_parts,
               "with --scannet: join same-class thing instances stacked above each other (a "
               "chair's seat and its star base) into one, where a derived annotation split one "
               "object into connected components (docs/SIMULATION.md)");
  app.add_option("--out", out_dir, "output folder")->required();
  app.add_option("--preview-every", preview_every,
                 "write colour, depth and mask PNGs of every Nth frame into OUT/preview (0 = none)")
      ->check(panmap::cli::nonNegative());
  app.add_flag("-q,--quiet", quiet, "no progress line");
  CLI11_PARSE(app, argc, argv);

  try {
    if (join_parts && scannet_dir.empty()) {
      throw panmap::Error("--join-parts needs --scannet (procedural rooms have whole objects)");
    }
    if (!recording.empty()) {
      // Recorded frames carry their own sensor, trajectory and rate.
      for (const char* flag : {"--trajectory", "--laps", "--rate-hz", "--cover-walk",
                               "--no-depth-noise", "--depth-pattern", "--image-scale"}) {
        if (app.count(flag)) {
          throw panmap::Error(std::string(flag) +
                              " does not apply to --recording (its frames "
                              "are recorded)");
        }
      }
    } else if (app.count("--every")) {
      throw panmap::Error("--every applies to --recording only");
    }
    const auto start = std::chrono::steady_clock::now();
    panmap::LabelledMesh mesh;
    json source_json;
    std::vector<Eigen::Vector2d> building_stops;
    if (building_seed >= 0) {
      if (room_style == "scannet") building_config.room.style = panmap::RoomStyle::kScanNetLike;
      const panmap::Building building =
          panmap::generateBuilding(static_cast<uint64_t>(building_seed), building_config);
      mesh = building.mesh;
      building_stops = panmap::buildingSurveyStops(building);
      source_json = {{"type", "procedural_building"},
                     {"building_seed", building_seed},
                     {"room_style", room_style},
                     {"rooms", building.rooms.size()},
                     {"floor_area_m2", building.floor_area_m2}};
      if (!quiet) {
        std::printf("building %lld: %zu rooms, %.0f m2 of floor, %zu triangles\n",
                    static_cast<long long>(building_seed), building.rooms.size(),
                    building.floor_area_m2, building.mesh.numFaces());
      }
    } else if (room_seed >= 0) {
      const panmap::ProceduralRoom room = panmap::generateRoom(
          static_cast<uint64_t>(room_seed),
          room_style == "scannet" ? panmap::RoomConfig::scanNetLike() : panmap::RoomConfig());
      mesh = room.mesh;
      source_json = {
          {"type", "procedural_room"}, {"room_seed", room_seed}, {"room_style", room_style}};
    } else {
      // The scene first: a missing folder was reported as a missing label table.
      if (!fs::is_directory(scannet_dir)) {
        throw panmap::Error("--scannet " + scannet_dir + ": no such folder");
      }
      // Unless given: the scene's own (ScanNet's layout), else the shipped fixtures' copy.
      if (labels_option->count() == 0) {
        scannet_labels = panmap::findScanNetLabelTable(scannet_dir);
        if (scannet_labels.empty() && fs::is_regular_file(shipped_labels)) {
          scannet_labels = shipped_labels;
        }
        if (scannet_labels.empty()) {
          throw panmap::Error("--scannet " + scannet_dir +
                              ": no scannetv2-labels.combined.tsv in it, its parent or its "
                              "grandparent; give it with --scannet-labels");
        }
      }
      const auto table = panmap::ScanNetLabelTable::load(scannet_labels);
      const panmap::ScanNetSceneFiles files = panmap::findScanNetSceneFiles(scannet_dir);
      const auto gt = panmap::loadScanNetGroundTruth(files.mesh_ply, files.aggregation_json,
                                                     files.segs_json, table);
      mesh = gt.mesh;
      source_json = {
          {"type", "scannet"}, {"dir", scannet_dir}, {"unknown_labels", gt.unknown_labels}};
      if (join_parts) {
        const std::vector<panmap::PartJoin> joins =
            panmap::joinStackedParts(&mesh, panmap::PartJoinConfig());
        json joined = json::array();
        for (const panmap::PartJoin& join : joins) {
          joined.push_back({{"part", join.part},
                            {"into", join.into},
                            {"class", join.class_id},
                            {"share", join.share}});
        }
        source_json["joined_parts"] = joined;
        if (!quiet) std::printf("joined %zu instance parts into larger ones\n", joins.size());
      }
    }

    // The world the network sees and the annotation evaluation sees (docs/SIMULATION.md).
    const panmap::UnannotatedMesh scene = panmap::unannotate(mesh, unannotate_config, seed);
    const panmap::LabelledMesh& gt_mesh = scene.ground_truth;
    mesh = unannotated_masks == "painted" ? scene.world : scene.ground_truth;

    panmap::SynthConfig config;
    config.seed = seed;
    config.masks = panmap::SegmenterNoiseConfig::fromPreset(masks);
    config.poses = panmap::PoseDriftConfig::fromPreset(poses);
    config.depth.enabled = !no_depth_noise;
    if (image_scale != 1.0) config = panmap::scaledImage(config, image_scale);
    if (!depth_pattern_file.empty()) {
      config.depth_pattern = panmap::sensorDepthPattern(
          panmap::DepthCalibration::load(depth_pattern_file), depth_pattern_scale);
    }
    std::vector<panmap::StampedPose> trajectory;
    panmap::SurveyConfig survey;
    if (!building_stops.empty()) {
      survey = panmap::buildingSurveyConfig();
      if (app.count("--frames")) survey.num_frames = frames;
      if (app.count("--rate-hz")) survey.rate_hz = rate_hz;
      rate_hz = survey.rate_hz;
    } else {
      survey.num_frames = frames;
      survey.rate_hz = rate_hz;
    }
    survey.laps = laps;
    survey.area_per_stop_m2 = area_per_stop_m2;
    panmap::SurveyPath walk;
    // A survey is planned unless the poses come from a file or a recording.
    const bool planned = trajectory_file.empty() && recording.empty();
    if (planned) {
      walk = building_stops.empty() ? panmap::planSurveyPath(mesh, survey, seed)
                                    : panmap::planSurveyPathThrough(mesh, survey, building_stops);
      if (walk.clearance_m < survey.clearance_m) {
        std::cerr << "panmap-synth: the survey walks " << walk.clearance_m
                  << " m from surfaces, not " << survey.clearance_m
                  << " m: the room is small or the way to a stop narrow\n";
      }
      const int needed = panmap::framesToWalk(walk, survey);
      if (cover_walk) {
        survey.num_frames = std::max(survey.num_frames, needed);
      } else if (survey.num_frames > 0 && survey.num_frames < needed) {
        // The walk is cut where the frames end: what lies beyond its end is never seen, and a
        // score over the whole scene then measures the survey, not the mapping.
        std::cerr << "panmap-synth: " << survey.num_frames << " frames walk "
                  << std::lround(100.0 * survey.num_frames / needed) << " % of the survey's "
                  << std::lround(walk.length_m) << " m (" << needed
                  << " frames at this rate walk all of it: --cover-walk or --frames " << needed
                  << ")\n";
      }
    } else if (cover_walk) {
      std::cerr << "panmap-synth: --cover-walk is ignored with --trajectory (its poses are the "
                << "frames)\n";
    }
    std::unique_ptr<panmap::DatasetReader> reader;
    std::vector<size_t> recorded_index;  // per rendered frame, its frame in the recording
    size_t recorded_without_pose = 0;
    if (!recording.empty()) {
      config.depth.enabled = false;  // the recording's own
      reader = panmap::openDataset(recording, panmap::DatasetOptions{});
      for (size_t i = 0; i < reader->size(); i += every) {
        if (app.count("--frames") && trajectory.size() >= static_cast<size_t>(frames)) break;
        const panmap::DatasetPose p = reader->pose(i);
        if (!p.T_W_C) {
          ++recorded_without_pose;  // ScanNet's -inf rows: no ground truth to score against
          continue;
        }
        panmap::StampedPose pose;
        pose.utime = p.utime;
        pose.frame_id = p.frame_id;
        pose.T_W_C = *p.T_W_C;
        trajectory.push_back(pose);
        recorded_index.push_back(i);
      }
      if (trajectory.empty()) throw panmap::Error(recording + ": no frame with a valid pose");
      if (recorded_without_pose > 0) {
        std::cerr << "panmap-synth: left out " << recorded_without_pose
                  << " recorded frames without a valid pose\n";
      }
    } else if (!building_stops.empty() && trajectory_file.empty()) {
      trajectory = panmap::planSurveyThrough(mesh, survey, building_stops, seed);
    } else if (!trajectory_file.empty()) {
      trajectory = panmap::readTumTrajectory(trajectory_file);
      // Frames at a repeated or earlier time are refused by the mapper one by one.
      for (size_t k = 1; k < trajectory.size(); ++k) {
        if (trajectory[k].utime <= trajectory[k - 1].utime) {
          throw panmap::Error(trajectory_file + ": pose " + std::to_string(k + 1) +
                              "'s timestamp is not after the one before (times must increase)");
        }
      }
      for (const char* flag : {"--laps", "--rate-hz"}) {
        if (app.count(flag)) {
          std::cerr << "panmap-synth: " << flag << " is ignored with --trajectory (its poses and "
                    << "timestamps are the frames)\n";
        }
      }
      // A recorded trajectory (ScanNet's poses: thousands at 30 Hz) is rendered whole unless
      // --frames asks for less; the default 300 cut such files to 10 s in silence.
      if (app.count("--frames") && static_cast<int>(trajectory.size()) > frames) {
        std::cerr << "panmap-synth: rendering the first " << frames << " of the trajectory's "
                  << trajectory.size() << " poses (--frames " << frames << ")\n";
        trajectory.resize(static_cast<size_t>(frames));
      }
    } else {
      trajectory = panmap::planSurvey(mesh, survey, seed);
    }

    fs::create_directories(out_dir + "/gt");
    {
      // Previews of an earlier run into the same folder would pass for this one's.
      std::error_code ignored;
      for (const auto& entry : fs::directory_iterator(out_dir + "/preview", ignored)) {
        if (entry.path().extension() == ".png") fs::remove(entry.path(), ignored);
      }
    }
    panmap::SequenceSynthesizer synth(mesh, trajectory, config);
    panmap::LogWriter log(out_dir + "/sequence.lcmlog");
    const panmap::ImageEncoding encoding;
    const auto pose_source =
        poses == "gt" ? panmap::PoseSource::kGroundTruth : panmap::PoseSource::kSlam;
    panmap::ProgressLine progress("synth", "frames", !quiet);
    const panmap::LabelTable nyu40 = panmap::LabelTable::nyu40Identity();
    panmap::PinholeCamera camera = config.camera;  // the recording's, with one
    double depth_scale_m = config.depth_scale_m;
    for (size_t k = 0; k < synth.size(); ++k) {
      const panmap::SynthFrame f =
          reader ? synth.frameFromRecording(k, reader->read(recorded_index[k]).rgbd)
                 : synth.frame(k);
      camera = f.rgbd.camera;
      depth_scale_m = f.rgbd.depth_scale_m;
      const int64_t utime = f.rgbd.utime;
      log.write(panmap::kChannelRgbd, utime, panmap::toMessage(f.rgbd, encoding));
      panmap::StampedPose pose;
      pose.utime = utime;
      pose.frame_id = f.rgbd.frame_id;
      pose.T_W_C = f.input_pose.T_W_C;
      pose.source = pose_source;
      log.write(panmap::kChannelPose, utime, panmap::toMessage(pose));
      log.write(
          panmap::kChannelPanoptic, utime,
          panmap::toMessage(
              semantic_masks ? panmap::withoutInstances(f.panoptic, nyu40) : f.panoptic, encoding));
      if (preview_every > 0 && k % static_cast<size_t>(preview_every) == 0)
        writePreview(out_dir, f);
      progress.update(k + 1, synth.size());
    }
    progress.finish();
    if (reader && synth.recordingDepthAgreement() < 0.5) {
      std::cerr << "panmap-synth: only " << std::lround(100.0 * synth.recordingDepthAgreement())
                << " % of the recorded depth lies within "
                << std::lround(100.0 * panmap::kRecordingAgreementM)
                << " cm of the mesh rendered at its poses: is the mesh the recording's scene, in "
                   "its world frame? (the masks come from it)\n";
    }
    size_t correction_poses = 0;
    if (correction_every > 0) {
      residual.sigma_m = residual_cm / 100.0;
      residual.sigma_rad = residual_deg * M_PI / 180.0;
      residual.seed = seed;
      const panmap::PoseCorrection correction =
          panmap::keyframeCorrection(synth.groundTruthTrajectory(), correction_every, 1, residual);
      log.write(panmap::kChannelPoseCorrection, correction.utime, panmap::toMessage(correction));
      correction_poses = correction.poses.size();
    }

    panmap::writePly(out_dir + "/gt/mesh.ply", gt_mesh);
    panmap::writeScanNetInstanceFile(out_dir + "/gt/instances.txt", gt_mesh);
    panmap::writeTumTrajectory(out_dir + "/gt/trajectory_gt.txt", synth.groundTruthTrajectory());
    panmap::writeTumTrajectory(out_dir + "/gt/trajectory_input.txt", synth.inputTrajectory());

    std::vector<Eigen::Isometry3d> gt_poses, input_poses;
    for (const auto& p : synth.groundTruthTrajectory()) gt_poses.push_back(p.T_W_C);
    for (const auto& p : synth.inputTrajectory()) input_poses.push_back(p.T_W_C);
    const double ate =
        gt_poses.size() >= 3 ? panmap::absoluteTrajectoryErrorRmse(input_poses, gt_poses) : 0.0;
    const panmap::CoverageStats cov = synth.coverage();
    const panmap::SegmenterNoiseStats& seg = synth.segmenterStats();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const json info = {
        {"seed", seed},
        {"source", source_json},
        {"frames", synth.size()},
        {"rate_hz", planned ? rate_hz : 0.0},
        {"camera",
         {{"fx", camera.fx},
          {"fy", camera.fy},
          {"cx", camera.cx},
          {"cy", camera.cy},
          {"width", camera.width},
          {"height", camera.height},
          {"depth_scale_m", depth_scale_m}}},
        {"recording",
         {{"path", recording},
          {"layout", reader ? reader->layoutName() : ""},
          {"every", recording.empty() ? 0 : every},
          {"frames_in_recording", reader ? reader->size() : 0},
          {"depth_agreement", synth.recordingDepthAgreement()},
          {"left_out_without_pose", recorded_without_pose}}},
        {"mesh",
         {{"vertices", mesh.numVertices()},
          {"faces", mesh.numFaces()},
          {"instances", synth.instances().size()}}},
        {"trajectory",
         {{"source", !recording.empty()        ? recording
                     : trajectory_file.empty() ? "survey"
                                               : trajectory_file},
          {"laps", planned ? laps : 0},
          {"walk_length_m", walk.length_m},
          // Share of the walk the frames reach (1 when they walk all of it or more).
          {"walk_covered", planned ? std::min(1.0, static_cast<double>(synth.size()) /
                                                       panmap::framesToWalk(walk, survey))
                                   : 0.0},
          {"planned_clearance_m", walk.clearance_m},
          {"stops", walk.stops.size()},
          {"free_area_m2", walk.free_area_m2},
          {"min_clearance_m", panmap::minClearance(synth.groundTruthTrajectory(), mesh)}}},
        {"masks", masksJson(config.masks)},
        {"semantic_masks", semantic_masks},
        {"unannotation",
         {{"fraction_requested", unannotate_config.fraction},
          {"fraction", scene.unannotated_fraction},
          {"stripped_instances", scene.stripped_instances},
          {"clutter_patches", scene.clutter_patches},
          {"clutter_instances", scene.clutter_instances},
          {"masks", unannotated_masks}}},
        {"poses", posesJson(config.poses)},
        {"correction",
         {{"every", correction_every},
          {"keyframes", correction_poses},
          {"residual_cm", residual_cm},
          {"residual_deg", residual_deg}}},
        {"depth_noise", depthJson(config.depth)},
        {"depth_pattern",
         {{"file", depth_pattern_file},
          {"scale", depth_pattern_file.empty() ? 0.0 : depth_pattern_scale},
          {"rms_mm", config.depth_pattern.rmsOffsetM() * 1000.0}}},
        {"coverage",
         {{"thing_instances", cov.thing_instances},
          {"seen_once", cov.seen_once},
          {"seen_from_3_views", cov.seen_from_3_views},
          {"fraction_seen_from_3_views", cov.fractionSeenFrom3Views()}}},
        {"measured",
         {{"input_ate_rmse_m", ate},
          {"miss_rate", seg.missRate()},
          {"small_miss_rate", seg.smallMissRate()},
          {"large_miss_rate", seg.largeMissRate()},
          {"confusion_rate", seg.confusionRate()},
          {"merge_rate", seg.mergeRate()},
          {"split_rate", seg.splitRate()},
          {"false_positives_per_frame", seg.falsePositivesPerFrame()},
          {"clutter_seen", seg.clutter_seen},
          {"clutter_stuff_rate", seg.clutterStuffRate()},
          {"clutter_thing_rate", seg.clutterThingRate()},
          {"mean_boundary_error_px", seg.meanBoundaryErrorPx()}}},
        {"log_bytes", log.bytes()},
        {"seconds", seconds}};
    std::ofstream(out_dir + "/info.json") << info.dump(2) << "\n";
    std::printf(
        "wrote %s: %zu frames, %.1f MB; input ATE %.3f m; %d/%d objects seen from >= 3 "
        "views; %.1f s\n",
        (out_dir + "/sequence.lcmlog").c_str(), synth.size(), log.bytes() / 1e6, ate,
        cov.seen_from_3_views, cov.thing_instances, seconds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-synth: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
