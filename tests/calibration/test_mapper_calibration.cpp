// The mapper with a depth calibration: every stage sees the corrected depth, refusals keep the
// map, map files and configs keep the calibration, and panmap-calibrate-depth's command line.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

#include <gtest/gtest.h>

#include "mapper/box_scene.h"
#include "panmap/calibration/depth_calibration.h"
#include "panmap/core/error.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/mapper.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// A calibration of 640x480 images that adds `offset_m` everywhere.
std::shared_ptr<const DepthCalibration> constantCalibration(float offset_m, int width = 640,
                                                            int height = 480) {
  return std::make_shared<const DepthCalibration>(width, height, 4, 3, 2, 1.0,
                                                  std::vector<float>(24, offset_m));
}

bool sameVoxels(const TsdfMap& a, const TsdfMap& b) {
  if (a.numBlocks() != b.numBlocks()) return false;
  for (size_t i = 0; i < a.numBlocks(); ++i) {
    const Block& x = *a.blocks()[i];
    const Block& y = *b.blocks()[i];
    if (x.index != y.index) return false;
    if (std::memcmp(x.voxels, y.voxels, sizeof(x.voxels)) != 0) return false;
  }
  return true;
}

class MapperCalibration : public BoxScene {};

TEST_F(MapperCalibration, EveryStageSeesTheCalibratedDepth) {
  MapperConfig calibrated_config = config();
  calibrated_config.depth_calibration = constantCalibration(0.01f);
  Mapper calibrated(calibrated_config);
  Mapper shifted(config());  // fed the same frames with 10 mm added by hand
  for (int k = 0; k < 4; ++k) {
    RgbdFrame frame;
    PanopticFrame panoptic;
    frameAt(k, &frame, &panoptic);
    calibrated.integrate(frame, pose(k), &panoptic);
    for (int v = 0; v < frame.depth.height(); ++v) {
      for (int u = 0; u < frame.depth.width(); ++u) {
        if (frame.depth(u, v)) frame.depth(u, v) += 10;
      }
    }
    shifted.integrate(frame, pose(k), &panoptic);
  }
  EXPECT_TRUE(sameVoxels(calibrated.map(), shifted.map()));
  EXPECT_EQ(calibrated.superpoints().states().size(), shifted.superpoints().states().size());
  // And the calibration did change the map.
  EXPECT_FALSE(sameVoxels(calibrated.map(), run(config(), 4)->map()));
}

TEST_F(MapperCalibration, AFrameOfAnotherSizeIsRefusedAndTheMapKept) {
  MapperConfig c = config();
  c.depth_calibration = constantCalibration(0.0f, 320, 240);
  Mapper mapper(c);
  RgbdFrame frame;
  PanopticFrame panoptic;
  frameAt(0, &frame, &panoptic);
  test::expectError([&] { mapper.integrate(frame, pose(0), &panoptic); },
                    {"depth calibration is for 320x240 images, the depth is 640x480"});
  EXPECT_EQ(mapper.map().numBlocks(), 0u);
  EXPECT_TRUE(mapper.trajectory().empty());
}

TEST_F(MapperCalibration, MapFilesKeepTheCalibration) {
  MapperConfig c = config();
  c.depth_calibration = constantCalibration(quantiseOffsetM(0.0042));
  c.depth_calibration_file = "/somewhere/sensor.json";
  auto mapper = run(c, 2);
  const auto loaded = Mapper::deserialize(mapper->serialize(), "test");
  ASSERT_TRUE(loaded->config().depth_calibration);
  EXPECT_EQ(*loaded->config().depth_calibration, *c.depth_calibration);
  EXPECT_EQ(loaded->config().depth_calibration_file, "/somewhere/sensor.json");
  EXPECT_EQ(loaded->serialize(), mapper->serialize());
  EXPECT_FALSE(Mapper::deserialize(run(config(), 1)->serialize(), "t")->config().depth_calibration);
}

// A loop-closure repair maps the stored frames (depth as read) again: at the same poses, a
// re-integration and a remap of a calibrated map give it back bit for bit.
TEST_F(MapperCalibration, RepairsCorrectTheStoredFramesTheSameWay) {
  MapperConfig c = config();
  c.depth_calibration = constantCalibration(0.01f);
  Mapper mapper(c);
  struct Stored {
    RgbdFrame frame;
    PanopticFrame panoptic;
    LabelImage labels;
  };
  std::map<int64_t, Stored> stored;
  for (int k = 0; k < 4; ++k) {
    Stored s;
    frameAt(k, &s.frame, &s.panoptic);
    mapper.integrate(s.frame, pose(k), &s.panoptic);
    s.labels = mapper.lastPixelLabels();
    stored[s.frame.utime] = s;
  }
  const std::vector<uint8_t> before = mapper.serialize();
  ASSERT_TRUE(mapper
                  .reintegrate(mapper.trajectory(),
                               [&](int64_t utime, RgbdFrame* frame, LabelImage* labels) {
                                 *frame = stored.at(utime).frame;
                                 *labels = stored.at(utime).labels;
                               })
                  .completed);
  EXPECT_EQ(mapper.serialize(), before);
  ASSERT_TRUE(
      mapper
          .remap(mapper.trajectory(),
                 [&](int64_t utime, RgbdFrame* frame, PanopticFrame* panoptic, GeometricSegments*) {
                   *frame = stored.at(utime).frame;
                   *panoptic = stored.at(utime).panoptic;
                   return true;
                 })
          .completed);
  EXPECT_TRUE(sameVoxels(mapper.map(), Mapper::deserialize(before, "before")->map()));
}

TEST(ConfigDepthCalibration, ARelativeFileIsReadBesideTheConfig) {
  test::TempDir dir;
  std::filesystem::create_directory(dir.path("cfg"));
  const DepthCalibration k(640, 480, 4, 3, 2, 1.0, std::vector<float>(24, quantiseOffsetM(0.003)));
  k.save(dir.path("cfg/sensor.json"));
  const std::string config_path = dir.path("cfg/config.yaml");
  std::ofstream(config_path) << "%YAML:1.0\n---\ndepth_calibration: \"sensor.json\"\n";
  const PanmapConfig c = loadConfig(config_path);
  ASSERT_TRUE(c.mapper.depth_calibration);
  EXPECT_EQ(*c.mapper.depth_calibration, k);
  EXPECT_EQ(c.mapper.depth_calibration_file, dir.path("cfg/sensor.json"));
  // The printed config names it and reads back the same.
  std::ofstream(dir.path("printed.yaml")) << configToYaml(c);
  EXPECT_EQ(*loadConfig(dir.path("printed.yaml")).mapper.depth_calibration, k);

  std::ofstream(config_path) << "%YAML:1.0\n---\ndepth_calibration: \"gone.json\"\n";
  test::expectError([&] { loadConfig(config_path); }, {"config.yaml", "gone.json", "cannot open"});
}

TEST(CalibrateDepthCli, LearnsFromALogAndRefusesBadInput) {
  test::TempDir dir;
  const auto synth =
      test::runCommand(test::binPath("panmap-synth") +
                       " --room 2 --frames 24 --poses gt --quiet --out " + dir.path("r"));
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string out = dir.path("sensor.json");
  const auto run = test::runCommand(test::binPath("panmap-calibrate-depth") + " --log " +
                                    dir.path("r/sequence.lcmlog") + " --out " + out +
                                    " --rounds 2 --cells 8 --calibration-voxel-size 0.02 -q");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // Ground-truth poses are not refined: one round, said so.
  EXPECT_NE(run.output.find("poses are not refined"), std::string::npos) << run.output;
  const DepthCalibration k = DepthCalibration::load(out);
  EXPECT_EQ(k.cellsX(), 8);
  EXPECT_EQ(k.cellsY(), 6);
  // Rendered depth has no fixed pattern, only noise that differs from frame to frame (and is
  // correlated over 8 px): what 24 frames leave in coarse 2 cm maps is well below a Kinect's
  // pattern (7 mm RMS on 7-Scenes, docs/MAPPING.md).
  EXPECT_LT(k.rmsOffsetM(), 0.003) << run.output;
  // The mapper takes it.
  const auto mapped = test::runCommand(test::binPath("panmap-mapper") + " --log " +
                                       dir.path("r/sequence.lcmlog") + " --out " + dir.path("m") +
                                       " --voxel-size 0.05 --geometry-only "
                                       "--no-snapshots --max-frames 3 --depth-calibration " +
                                       out);
  EXPECT_EQ(mapped.exit_code, 0) << mapped.output;

  const auto missing = test::runCommand(test::binPath("panmap-calibrate-depth") + " --log " +
                                        dir.path("none.lcmlog") + " --out " + out);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("none.lcmlog does not exist"), std::string::npos) << missing.output;
  const auto no_folder =
      test::runCommand(test::binPath("panmap-calibrate-depth") + " --log " +
                       dir.path("r/sequence.lcmlog") + " --out " + dir.path("none/sensor.json"));
  EXPECT_EQ(no_folder.exit_code, 1);
  EXPECT_NE(no_folder.output.find("--out " + dir.path("none/sensor.json") + ": folder " +
                                  dir.path("none") + " does not exist"),
            std::string::npos)
      << no_folder.output;
  // Checked before the rounds, not after them (the trajectory was found unwritable at the end).
  const auto no_trajectory_folder = test::runCommand(
      test::binPath("panmap-calibrate-depth") + " --log " + dir.path("r/sequence.lcmlog") +
      " --out " + out + " --trajectory-out " + dir.path("r") + " -q");
  EXPECT_EQ(no_trajectory_folder.exit_code, 1);
  EXPECT_EQ(test::countLines(no_trajectory_folder.output), 1) << no_trajectory_folder.output;
  EXPECT_NE(no_trajectory_folder.output.find("--trajectory-out " + dir.path("r") +
                                             " is a folder, not a file"),
            std::string::npos)
      << no_trajectory_folder.output;
  for (const std::string range : {"--first -5", "--first 4 --last 2", "--last -3"}) {
    const auto bad =
        test::runCommand(test::binPath("panmap-calibrate-depth") + " --log " +
                         dir.path("r/sequence.lcmlog") + " --out " + out + " " + range + " -q");
    EXPECT_NE(bad.exit_code, 0) << range;
    EXPECT_EQ(bad.output.find("round 1"), std::string::npos) << range << ": " << bad.output;
    EXPECT_LE(test::countLines(bad.output), 2) << range << ": " << bad.output;
  }
  const auto no_frames =
      test::runCommand(test::binPath("panmap-calibrate-depth") + " --log " +
                       dir.path("r/sequence.lcmlog") + " --out " + out + " --first 1000 -q");
  EXPECT_EQ(no_frames.exit_code, 1);
  EXPECT_NE(no_frames.output.find("no frames to learn from"), std::string::npos)
      << no_frames.output;
  // An empty log: the same one-line reason, and no progress line made of a division by zero.
  const std::string empty = dir.path("empty.lcmlog");
  std::ofstream(empty).close();
  const auto empty_log = test::runCommand(test::binPath("panmap-calibrate-depth") + " --log " +
                                          empty + " --out " + out);
  EXPECT_EQ(empty_log.exit_code, 1);
  EXPECT_NE(empty_log.output.find("no frames to learn from"), std::string::npos)
      << empty_log.output;
  EXPECT_EQ(empty_log.output.find("nan"), std::string::npos) << empty_log.output;
  const auto help = test::runCommand(test::binPath("panmap-calibrate-depth") + " --help");
  EXPECT_EQ(help.exit_code, 0);
}

// The log's poses drift, and tracking refines them against a map of depth with a fixed
// pattern, which bends the refined poses with it; the first round must learn at the poses as
// given: with one round, exactly what --tracking off learns.
TEST(CalibrateDepthCli, TheFirstRoundLearnsAtThePosesAsGiven) {
  test::TempDir dir;
  std::vector<float> offsets_m(2 * 6 * 8);
  for (size_t i = 0; i < offsets_m.size(); ++i)
    offsets_m[i] = quantiseOffsetM(((i * 7) % 11 - 5.0) * 0.002);  // +-1 cm, no structure
  DepthCalibration(640, 480, 8, 6, 2, 4.0, offsets_m).save(dir.path("sensor.json"));
  const auto synth = test::runCommand(
      test::binPath("panmap-synth") + " --room 2 --frames 40 --poses heavy --quiet " +
      "--depth-pattern " + dir.path("sensor.json") + " --out " + dir.path("r"));
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  auto calibrate = [&](const std::string& out, const std::string& flags) {
    const auto run = test::runCommand(
        test::binPath("panmap-calibrate-depth") + " --log " + dir.path("r/sequence.lcmlog") +
        " --out " + out + " --cells 8 --calibration-voxel-size 0.02 --passes 2 -q " + flags);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return run.output;
  };
  const std::string tracked = calibrate(dir.path("tracked.json"), "--rounds 1");
  // Tracking did refine the poses of that round ...
  EXPECT_EQ(tracked.find("(0 tracked"), std::string::npos) << tracked;
  calibrate(dir.path("given.json"), "--rounds 1 --tracking off");
  // ... and the calibration is the one learnt at the poses as given.
  EXPECT_EQ(DepthCalibration::load(dir.path("tracked.json")),
            DepthCalibration::load(dir.path("given.json")));
}

}  // namespace
}  // namespace panmap
