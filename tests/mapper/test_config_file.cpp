#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "panmap/calibration/depth_calibration.h"
#include "panmap/core/error.h"
#include "panmap/mapper/config_file.h"
#include "test_helpers.h"

namespace panmap {
namespace {

std::string write(const test::TempDir& dir, const std::string& text) {
  const std::string path = dir.path("config.yaml");
  std::ofstream(path) << text;
  return path;
}

TEST(ConfigFile, PrintedDefaultsReadBackUnchanged) {
  test::TempDir dir;
  PanmapConfig defaults;
  defaults.optimiser.class_thresholds[5] = {0.2, 0.3, 0.4};
  const PanmapConfig back = loadConfig(write(dir, configToYaml(defaults)));
  EXPECT_EQ(configToYaml(back), configToYaml(defaults));
  EXPECT_FLOAT_EQ(back.mapper.map.voxel_size_m, 0.01f);
  EXPECT_EQ(back.mapper.superpoints.merge_threshold, 3);
  EXPECT_DOUBLE_EQ(back.optimiser.thresholds(5).theta_L, 0.4);
  EXPECT_DOUBLE_EQ(back.optimiser.thresholds(7).theta_L, 0.3);  // the tuned default
}

TEST(ConfigFile, TheShippedDefaultIsWhatPrintConfigPrints) {
  // configs/default.yaml is what a user copies: it must hold every key with its default.
  std::ifstream in(test::fixtureDir("../../configs/default.yaml"));
  ASSERT_TRUE(in.good());
  const std::string shipped((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(shipped, configToYaml(PanmapConfig{}));
}

TEST(ConfigFile, PartialFilesKeepDefaults) {
  test::TempDir dir;
  const PanmapConfig c =
      loadConfig(write(dir,
                       "%YAML:1.0\n---\nmap:\n   voxel_size_m: 0.02\n"
                       "superpoints:\n   semantic_consistency: 0\n"
                       "optimiser:\n   classes:\n      - { class: 39, theta_D: 0.3 }\n"
                       "threads: 1\n"));
  EXPECT_FLOAT_EQ(c.mapper.map.voxel_size_m, 0.02f);
  EXPECT_FALSE(c.mapper.superpoints.semantic_consistency);
  EXPECT_EQ(c.mapper.num_threads, 1);
  EXPECT_DOUBLE_EQ(c.optimiser.thresholds(39).theta_D, 0.3);
  EXPECT_DOUBLE_EQ(c.optimiser.thresholds(39).theta_O, 0.05);  // the tuned default
  EXPECT_FLOAT_EQ(c.mapper.integrator.truncation_voxels, 4.0f);
}

// Plain YAML leaves OpenCV's "%YAML:1.0" directive out (it was refused as "Input file is
// invalid"); "%YAML 1.2" and a bare "---" are plain YAML too. A directive below a comment is an
// error in YAML as well, and is named.
TEST(ConfigFile, PlainYamlWithoutOpenCvsDirectiveIsRead) {
  test::TempDir dir;
  for (const std::string& head : {std::string(), std::string("---\n"),
                                  std::string("%YAML 1.2\n---\n"), std::string("%YAML:1.0\n")}) {
    const PanmapConfig c = loadConfig(write(dir, head + "# mine\nmap:\n  voxel_size_m: 0.05\n"));
    EXPECT_FLOAT_EQ(c.mapper.map.voxel_size_m, 0.05f) << head;
  }
  test::expectError(
      [&] { loadConfig(write(dir, "# mine\n%YAML:1.0\nmap:\n  voxel_size_m: 0.05\n")); },
      {"the %YAML directive must be the first line"});
}

TEST(ConfigFile, TrackingAndOccupancySections) {
  test::TempDir dir;
  const PanmapConfig c = loadConfig(write(dir,
                                          "%YAML:1.0\n---\ntracking:\n   mode: \"off\"\n"
                                          "   warmup_frames: 9\noccupancy:\n   enabled: 0\n"
                                          "   resolution_m: 0.1\n"));
  EXPECT_EQ(c.mapper.tracking_mode, MapperConfig::TrackingMode::kOff);
  EXPECT_EQ(c.mapper.tracking_warmup_frames, 9);
  EXPECT_FALSE(c.mapper.occupancy_enabled);
  EXPECT_DOUBLE_EQ(c.mapper.occupancy.resolution_m, 0.1);
  // An unquoted value with a comment after it reads the same.
  EXPECT_EQ(loadConfig(write(dir, "%YAML:1.0\n---\ntracking:\n   mode: on   # refine all\n"))
                .mapper.tracking_mode,
            MapperConfig::TrackingMode::kOn);
  test::expectError([&] { loadConfig(write(dir, "%YAML:1.0\n---\ntracking:\n   mode: always\n")); },
                    {"tracking.mode", "always"});
  test::expectError(
      [&] { loadConfig(write(dir, "%YAML:1.0\n---\noccupancy:\n   resolution_m: -1\n")); },
      {"resolution"});
}

TEST(ConfigFile, SyncSectionInTheUnitsAUserThinksIn) {
  test::TempDir dir;
  const PanmapConfig c = loadConfig(write(dir,
                                          "%YAML:1.0\n---\nsync:\n   mask_tolerance_ms: 8\n"
                                          "   wait_s: 1.5\n   masks_in_order: 0\n"
                                          "   max_queue: 60\n   max_pose_gap_ms: 600\n"));
  EXPECT_EQ(c.sync.mask_tolerance_us, 8000);
  EXPECT_EQ(c.sync.wait_us, 1500000);
  EXPECT_FALSE(c.sync.masks_in_order);
  EXPECT_EQ(c.sync.max_queue, 60u);
  EXPECT_EQ(c.sync.max_pose_gap_us, 600000);
  EXPECT_EQ(c.sync.pose_tolerance_us, SyncConfig{}.pose_tolerance_us);
  const PanmapConfig back = loadConfig(write(dir, configToYaml(c)));
  EXPECT_EQ(configToYaml(back), configToYaml(c));
  test::expectError([&] { loadConfig(write(dir, "%YAML:1.0\n---\nsync:\n   wait_s: -1\n")); },
                    {"sync.wait_s must be in [0, 3600]"});
  test::expectError([&] { loadConfig(write(dir, "%YAML:1.0\n---\nsync:\n   max_queue: 0\n")); },
                    {"sync.max_queue"});
  test::expectError([&] { loadConfig(write(dir, "%YAML:1.0\n---\nsync:\n   wait: 1\n")); },
                    {"unknown key sync.wait"});
}

TEST(ConfigFile, DriftFilterCorrectionSwitchesTheAlignerDefaults) {
  test::TempDir dir;
  EXPECT_EQ(MapperConfig().tracking_correction, MapperConfig::PoseCorrection::kPerFrame);
  EXPECT_DOUBLE_EQ(MapperConfig().tracking.prior_sigma_translation_m, 0.01);
  const PanmapConfig c = loadConfig(write(dir,
                                          "%YAML:1.0\n---\ntracking:\n   correction: filter\n"
                                          "   max_iterations: 5\n   measurement_sigma_m: 0.02\n"));
  EXPECT_EQ(c.mapper.tracking_correction, MapperConfig::PoseCorrection::kFilter);
  EXPECT_EQ(c.mapper.tracking.level_strides_px, (std::vector<int>{20, 10}));
  EXPECT_DOUBLE_EQ(c.mapper.tracking.prior_sigma_translation_m, 0.05);
  EXPECT_DOUBLE_EQ(c.mapper.tracking.weak_direction_damping, 0.0);
  EXPECT_EQ(c.mapper.tracking.max_iterations, 5);  // keys after the switch still apply
  EXPECT_DOUBLE_EQ(c.mapper.drift.measurement_sigma_m, 0.02);
  test::expectError(
      [&] { loadConfig(write(dir, "%YAML:1.0\n---\ntracking:\n   correction: smooth\n")); },
      {"tracking.correction", "smooth"});
  test::expectError(
      [&] { loadConfig(write(dir, "%YAML:1.0\n---\ntracking:\n   drift_per_m: -1\n")); },
      {"drift_per_m"});
}

TEST(ConfigFile, GraphPruningKeys) {
  test::TempDir dir;
  const PanmapConfig c =
      loadConfig(write(dir,
                       "%YAML:1.0\n---\ngraph:\n   prune_edges: 0\n"
                       "   edge_min_share: 0.25\n   surface_band_voxels: 1.5\n"));
  EXPECT_FALSE(c.mapper.graph.prune_edges);
  EXPECT_DOUBLE_EQ(c.mapper.graph.edge_min_share, 0.25);
  EXPECT_FLOAT_EQ(c.mapper.graph.surface_band_voxels, 1.5f);
  EXPECT_TRUE(PanmapConfig{}.mapper.graph.prune_edges);  // on by default
  test::expectError(
      [&] { loadConfig(write(dir, "%YAML:1.0\n---\ngraph:\n   edge_min_share: 2\n")); },
      {"edge_min_share"});
}

TEST(ConfigFile, BadKeysAndValuesNameTheKey) {
  test::TempDir dir;
  auto error = [&](const std::string& text) {
    try {
      loadConfig(write(dir, text));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(
      error("%YAML:1.0\n---\nmap:\n   voxel_sise_m: 0.02\n").find("unknown key map.voxel_sise_m"),
      std::string::npos);
  EXPECT_NE(error("%YAML:1.0\n---\nmapp:\n   voxel_size_m: 0.02\n").find("unknown section mapp"),
            std::string::npos);
  EXPECT_NE(error("%YAML:1.0\n---\nmap:\n   voxel_size_m: -1\n").find("voxel_size_m"),
            std::string::npos);
  EXPECT_NE(error("%YAML:1.0\n---\nsuperpoints:\n   merge_threshold: 2.5\n")
                .find("superpoints.merge_threshold"),
            std::string::npos);
  EXPECT_NE(error("%YAML:1.0\n---\nmap:\n   voxel_size_m: [1]\n").find("must be a number"),
            std::string::npos);
  EXPECT_NE(error("%YAML:1.0\n---\noptimiser:\n   weighting: \"voxels\"\n")
                .find("optimiser.weighting must be surface, shared or none"),
            std::string::npos);
  EXPECT_NE(error("%YAML:1.0\n---\noptimiser:\n   weighting: \"voxels\"\n").find("not \"voxels\""),
            std::string::npos);
  // A key that lost its indent was "not a YAML config (skipSpaces)": now its line and why.
  EXPECT_EQ(error("map:\nvoxel_size_m: 0.02\n"),
            dir.path("config.yaml") + ":2: not a YAML config: Incorrect indentation");
  // A component's check names the key the file holds, not the code's field.
  EXPECT_NE(error("objects:\n   min_area_m2: -1\n").find(": objects.min_area_m2"),
            std::string::npos)
      << error("objects:\n   min_area_m2: -1\n");
  EXPECT_NE(error("threads: 0\n").find(": threads must be"), std::string::npos)
      << error("threads: 0\n");
  EXPECT_NE(error("fusion:\n   stuff_confidence: 4\n").find(": fusion.stuff_confidence"),
            std::string::npos)
      << error("fusion:\n   stuff_confidence: 4\n");
  EXPECT_EQ(asConfigKeys("superpoint significant_overlap must be in (0, 1]"),
            "superpoints.significant_overlap must be in (0, 1]");
  EXPECT_EQ(asConfigKeys("cannot read x"), "cannot read x");
  EXPECT_EQ(asConfigKeys("integrator needs 0 <= min_depth_m < max_depth_m"),
            "integrator needs 0 <= min_depth_m < max_depth_m");
  // A class listed twice kept the later entry in silence; one beyond NYU40 was taken.
  EXPECT_NE(error("%YAML:1.0\n---\noptimiser:\n   classes:\n      - { class: 5, theta_D: 0.1 }\n"
                  "      - { class: 5, theta_D: 0.2 }\n")
                .find("optimiser.classes[] lists class 5 twice"),
            std::string::npos);
  EXPECT_NE(error("%YAML:1.0\n---\noptimiser:\n   classes:\n      - { class: 99, theta_D: 0.1 }\n")
                .find("needs a class of 1..40 (NYU40), not 99"),
            std::string::npos);
  EXPECT_THROW(loadConfig(dir.path("missing.yaml")), Error);
  EXPECT_FLOAT_EQ(loadConfig(write(dir, "")).mapper.map.voxel_size_m, 0.01f);  // all defaults
  test::expectError([&] { loadConfig(dir.path()); }, {"config " + dir.path() + " is a folder"});
}

TEST(ConfigFile, EnergyWeightingReadsEveryValue) {
  test::TempDir dir;
  EXPECT_EQ(PanmapConfig().optimiser.weighting, OptimiserConfig::Weighting::kSurface);
  const PanmapConfig none =
      loadConfig(write(dir, "%YAML:1.0\n---\noptimiser:\n   weighting: \"none\"\n"));
  EXPECT_EQ(none.optimiser.weighting, OptimiserConfig::Weighting::kNone);
  EXPECT_EQ(loadConfig(write(dir, configToYaml(none))).optimiser.weighting,
            OptimiserConfig::Weighting::kNone);
  const PanmapConfig shared =
      loadConfig(write(dir, "%YAML:1.0\n---\noptimiser:\n   weighting: \"shared\"\n"));
  EXPECT_EQ(loadConfig(write(dir, configToYaml(shared))).optimiser.weighting,
            OptimiserConfig::Weighting::kShared);
}

TEST(ConfigFile, LinkScaleRoundTripsAndABadValueIsNamed) {
  test::TempDir dir;
  const PanmapConfig geometric =
      loadConfig(write(dir, "%YAML:1.0\n---\noptimiser:\n   link_scale: \"geometric\"\n"));
  EXPECT_EQ(geometric.optimiser.link_scale, OptimiserConfig::LinkScale::kGeometric);
  EXPECT_EQ(loadConfig(write(dir, configToYaml(geometric))).optimiser.link_scale,
            OptimiserConfig::LinkScale::kGeometric);
  const PanmapConfig smaller = loadConfig(
      write(dir,
            "%YAML:1.0\n---\noptimiser:\n   link_scale: \"smaller\"\n   link_half_observations: 2\n"
            "   max_void_share: 0.875\n"));
  EXPECT_EQ(loadConfig(write(dir, configToYaml(smaller))).optimiser.link_half_observations, 2.0);
  EXPECT_EQ(loadConfig(write(dir, configToYaml(smaller))).optimiser.max_void_share, 0.875);
  // III-B refuses merges into super-points the optimiser leaves unlabelled: one key for both.
  EXPECT_EQ(smaller.mapper.superpoints.unlabelled_void_share, 0.875);
  // A bad value is named by the key the file holds, not by the setting derived from it.
  test::expectError(
      [&] { loadConfig(write(dir, "%YAML:1.0\n---\noptimiser:\n   max_void_share: 1.5\n")); },
      {"optimiser.max_void_share"});
  EXPECT_EQ(loadConfig(write(dir, configToYaml(smaller))).optimiser.link_scale,
            OptimiserConfig::LinkScale::kSmaller);
  try {
    loadConfig(write(dir, "%YAML:1.0\n---\noptimiser:\n   link_scale: \"mean\"\n"));
    FAIL() << "an unknown link_scale loads";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("optimiser.link_scale must be smaller or geometric"),
              std::string::npos)
        << e.what();
  }
}

// What `panmap-mapper --load MAP --config FILE` reads: the file restates or changes a loaded
// map's settings, and the keys it leaves out are the map's, not the defaults.
TEST(ConfigFile, ABaseFillsTheKeysTheFileLeavesOut) {
  test::TempDir dir;
  PanmapConfig base;
  base.mapper.map.voxel_size_m = 0.05f;
  base.mapper.num_threads = 1;
  base.mapper.superpoints.semantic_consistency = false;
  const PanmapConfig c = loadConfig(write(dir, "optimiser:\n   regularise: 0\n"), base);
  EXPECT_FLOAT_EQ(c.mapper.map.voxel_size_m, 0.05f);
  EXPECT_EQ(c.mapper.num_threads, 1);
  EXPECT_FALSE(c.mapper.superpoints.semantic_consistency);
  EXPECT_FALSE(c.optimiser.regularise);
  EXPECT_EQ(mapperSettingDifference(base.mapper, c.mapper).key, "");
  // Without a base the same file keeps the defaults.
  EXPECT_FLOAT_EQ(loadConfig(dir.path("config.yaml")).mapper.map.voxel_size_m, 0.01f);
}

// The difference as the mapper's error shows it.
std::string shown(const SettingDifference& d) { return d.key + ": " + d.have + " -> " + d.wanted; }

TEST(ConfigFile, MapperSettingDifferenceNamesTheFirstKey) {
  const MapperConfig defaults;
  EXPECT_EQ(mapperSettingDifference(defaults, defaults).key, "");
  MapperConfig other = defaults;
  other.fusion.geometry_only = true;
  EXPECT_EQ(shown(mapperSettingDifference(defaults, other)), "fusion.geometry_only: 0 -> 1");
  other = defaults;
  other.map.voxel_size_m = 0.05f;
  other.num_threads = 1;  // later in the file: the first difference is named
  EXPECT_EQ(shown(mapperSettingDifference(defaults, other)), "map.voxel_size_m: 0.01 -> 0.05");
  other = defaults;
  other.num_threads = 1;
  EXPECT_EQ(shown(mapperSettingDifference(defaults, other)), "threads: 2 -> 1");
  other = defaults;
  other.depth_calibration =
      std::make_shared<const DepthCalibration>(4, 4, 1, 1, 2, 1.0, std::vector<float>{0.0f, 0.01f});
  other.depth_calibration_file = "/cal.json";
  EXPECT_EQ(shown(mapperSettingDifference(defaults, other)),
            "depth_calibration: none -> \"/cal.json\"");
}

// A map keeps every setting the config file shows: --load compares them and must not find a
// difference the map file itself made.
TEST(ConfigFile, AMapFileKeepsEveryPrintedMapperSetting) {
  test::TempDir dir;
  MapperConfig config;
  config.num_threads = 1;
  config.map.voxel_size_m = 0.04f;
  config.fusion.geometry_only = true;
  config.superpoints.semantic_consistency = false;
  config.graph.pair_interior_px = 5;
  config.tracking_mode = MapperConfig::TrackingMode::kOff;
  config.mask_edge_fill.enabled = false;
  config.integrator.vote_stride_px = 3;
  Mapper(config).save(dir.path("m.panmap"));
  EXPECT_EQ(mapperSettingDifference(config, Mapper::load(dir.path("m.panmap"))->config()).key, "");
}

// OpenCV keeps the first of two equal keys: a section appended to a printed config to
// override it was silently ignored (the run mapped at 1 cm, not the 5 cm appended).
TEST(ConfigFile, AKeyTwiceInOneMappingIsNamed) {
  test::TempDir dir;
  const std::string appended =
      write(dir, configToYaml(PanmapConfig{}) + "map:\n   voxel_size_m: 0.05\n");
  test::expectError([&] { loadConfig(appended); }, {"'map' appears twice"});
  const std::string key = write(dir, "map:\n   voxel_size_m: 0.02\n   voxel_size_m: 0.05\n");
  test::expectError([&] { loadConfig(key); }, {key + ":3:", "'voxel_size_m' appears twice"});
  // The same key in two sections is two keys.
  EXPECT_NO_THROW(loadConfig(write(dir,
                                   "tracking:\n   mode: \"off\"\noccupancy:\n   enabled: 1\n"
                                   "fusion:\n   geometry_only: 0\n")));
}

// A switch took any number: 0.5 became off, -1 on.
TEST(ConfigFile, ASwitchIsZeroOrOne) {
  test::TempDir dir;
  for (const char* bad : {"0.5", "-1", "2"}) {
    const std::string path = write(dir, std::string("fusion:\n   geometry_only: ") + bad + "\n");
    test::expectError([&] { loadConfig(path); }, {"fusion.geometry_only is a switch: 0 or 1"});
  }
  EXPECT_TRUE(loadConfig(write(dir, "fusion:\n   geometry_only: 1\n")).mapper.fusion.geometry_only);
  EXPECT_TRUE(
      loadConfig(write(dir, "fusion:\n   geometry_only: true\n")).mapper.fusion.geometry_only);
  EXPECT_FALSE(loadConfig(write(dir, "fusion:\n   geometry_only: false # off\n"))
                   .mapper.fusion.geometry_only);
}

TEST(ConfigFile, ATabOutsideACommentIsNamed) {
  test::TempDir dir;
  const std::string path = write(dir, "map:\n\tvoxel_size_m: 0.02\n");
  test::expectError([&] { loadConfig(path); }, {path + ":2:", "tab in the indentation"});
  const std::string after_value = write(dir, "map:\n   voxel_size_m: 0.02\t# cm\n");
  test::expectError([&] { loadConfig(after_value); }, {after_value + ":2:", "tab at column 22"});
  // In a comment a tab is text.
  EXPECT_FLOAT_EQ(
      loadConfig(write(dir, "map:\n   voxel_size_m: 0.02 # a\tcm\n")).mapper.map.voxel_size_m,
      0.02f);
}

}  // namespace
}  // namespace panmap
