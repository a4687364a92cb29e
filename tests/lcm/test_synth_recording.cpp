// panmap-synth --recording: a recorded sequence's own depth, colour and poses, with masks from
// the scene's mesh rendered at each pose. A recording made of rendered frames must give back
// exactly the masks, drifted poses and depth that rendering them gives.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <lcm/lcm-cpp.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "panmap/core/pose.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/scannet_sens.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/lcm/channels.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/decode.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/sequence.h"
#include "panmap/sim/unannotation.h"
#include "test_helpers.h"

namespace panmap {
namespace {

constexpr uint64_t kSeed = 4;
constexpr int kFrames = 12;

// Room 3's survey as a recording keeps it: each pose as the floats a .sens stores, and the
// poses and times its reader gives back (the float matrix made a rotation again; frame number
// at 30 Hz), so that rendering and the recording see the very same poses.
struct Recordable {
  std::vector<StampedPose> trajectory;
  std::vector<Eigen::Matrix4f> stored;
};
Recordable recordableTrajectory(const LabelledMesh& mesh) {
  SurveyConfig survey;
  survey.num_frames = kFrames;
  survey.rate_hz = 5.0;
  Recordable r;
  r.trajectory = planSurvey(mesh, survey, kSeed);
  for (size_t i = 0; i < r.trajectory.size(); ++i) {
    r.stored.push_back(r.trajectory[i].T_W_C.matrix().cast<float>());
    r.trajectory[i].utime = std::llround(static_cast<double>(i) * 1e6 / 30.0);
    r.trajectory[i].T_W_C = nearestIsometry(r.stored[i].cast<double>());
  }
  return r;
}

SynthConfig recordingConfig() {
  SynthConfig config;
  config.seed = kSeed;
  config.depth.enabled = false;  // a recording brings its own depth
  return config;
}

TEST(SynthRecording, GivesTheMasksPosesAndDepthOfTheRenderedFrames) {
  test::TempDir dir;
  const LabelledMesh room = generateRoom(3).mesh;
  // panmap-synth's world: the room with its clutter given instances, nothing unannotated.
  const LabelledMesh world = unannotate(room, UnannotateConfig{}, kSeed).world;
  const Recordable recordable = recordableTrajectory(world);
  const std::vector<StampedPose>& trajectory = recordable.trajectory;
  SequenceSynthesizer rendered(world, trajectory, recordingConfig());

  ScanNetSensHeader header;
  const PinholeCamera& cam = recordingConfig().camera;
  header.intrinsic_depth(0, 0) = static_cast<float>(cam.fx);
  header.intrinsic_depth(1, 1) = static_cast<float>(cam.fy);
  header.intrinsic_depth(0, 2) = static_cast<float>(cam.cx);
  header.intrinsic_depth(1, 2) = static_cast<float>(cam.cy);
  header.intrinsic_color = header.intrinsic_depth;
  header.color_compression = static_cast<int32_t>(SensColorCompression::kRaw);
  header.color_width = header.depth_width = static_cast<uint32_t>(cam.width);
  header.color_height = header.depth_height = static_cast<uint32_t>(cam.height);
  std::vector<SynthFrame> expected;
  std::vector<ScanNetSensFrame> recorded;
  for (size_t k = 0; k < trajectory.size(); ++k) {
    expected.push_back(rendered.frame(k));
    ScanNetSensFrame f;
    f.camera_to_world = recordable.stored[k];
    const ColorImage& color = expected.back().rgbd.color;
    const auto* rgb = reinterpret_cast<const uint8_t*>(color.data());
    f.color.assign(rgb, rgb + color.size() * 3);
    f.depth = compressSensDepth(expected.back().rgbd.depth);
    recorded.push_back(std::move(f));
  }
  writeScanNetSens(dir.path("room3.sens"), header, recorded);

  const auto run = test::runCommand(test::binPath("panmap-synth") + " --room 3 --seed " +
                                    std::to_string(kSeed) + " --recording " +
                                    dir.path("room3.sens") + " --quiet --out " + dir.path("out"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream info_file(dir.path("out/info.json"));
  const nlohmann::json info = nlohmann::json::parse(info_file);
  EXPECT_EQ(info["frames"], kFrames);
  EXPECT_EQ(info["recording"]["layout"], "scannet-sens");
  EXPECT_EQ(info["trajectory"]["source"], dir.path("room3.sens"));
  EXPECT_EQ(info["camera"]["fx"], cam.fx);
  EXPECT_DOUBLE_EQ(info["recording"]["depth_agreement"].get<double>(), 1.0);  // its own mesh
  EXPECT_EQ(run.output.find("is the mesh the recording's scene"), std::string::npos);

  lcm::LogFile log(dir.path("out/sequence.lcmlog"), "r");
  ASSERT_TRUE(log.good());
  size_t depth_frames = 0, poses = 0, masks = 0;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    const std::string channel = e->channel;
    if (channel == kChannelRgbd) {
      rgbd_frame_t msg;
      ASSERT_TRUE(decodeExactly(e->data, e->datalen, &msg));
      const RgbdFrame f = fromMessage(msg);
      const RgbdFrame& want = expected.at(depth_frames++).rgbd;
      EXPECT_TRUE(std::equal(f.depth.data(), f.depth.data() + f.depth.size(), want.depth.data()));
      EXPECT_EQ(f.utime, want.utime);
    } else if (channel == kChannelPose) {
      pose_t msg;
      ASSERT_TRUE(decodeExactly(e->data, e->datalen, &msg));
      const StampedPose p = fromMessage(msg);
      // The drift of the `slam` preset, drawn with the seed over the same ground truth.
      EXPECT_TRUE(p.T_W_C.isApprox(expected.at(poses++).input_pose.T_W_C, 1e-9));
    } else if (channel == kChannelPanoptic) {
      panoptic_t msg;
      ASSERT_TRUE(decodeExactly(e->data, e->datalen, &msg));
      const PanopticFrame p = fromMessage(msg);
      const PanopticFrame& want = expected.at(masks++).panoptic;
      EXPECT_TRUE(std::equal(p.segment_ids.data(), p.segment_ids.data() + p.segment_ids.size(),
                             want.segment_ids.data()))
          << "frame " << masks - 1;
      EXPECT_EQ(p.segments.size(), want.segments.size());
    }
  }
  EXPECT_EQ(depth_frames, static_cast<size_t>(kFrames));
  EXPECT_EQ(poses, static_cast<size_t>(kFrames));
  EXPECT_EQ(masks, static_cast<size_t>(kFrames));

  // Every other frame, then the first 3 of those.
  const auto sparse = test::runCommand(test::binPath("panmap-synth") + " --room 3 --recording " +
                                       dir.path("room3.sens") +
                                       " --every 2 --frames 3 --quiet --out " + dir.path("sparse"));
  ASSERT_EQ(sparse.exit_code, 0) << sparse.output;
  const auto gt = readTumTrajectory(dir.path("sparse/gt/trajectory_gt.txt"));
  ASSERT_EQ(gt.size(), 3u);
  EXPECT_EQ(gt[2].utime, trajectory[4].utime);

  // Another room's mesh under room 3's recording: said, since its masks would be nonsense.
  const auto other =
      test::runCommand(test::binPath("panmap-synth") + " --room 4 --recording " +
                       dir.path("room3.sens") + " --quiet --out " + dir.path("other"));
  ASSERT_EQ(other.exit_code, 0) << other.output;
  EXPECT_NE(other.output.find("is the mesh the recording's scene, in its world frame?"),
            std::string::npos)
      << other.output;
}

TEST(SynthRecording, OptionsOfRenderedSequencesAreRefusedInOneLine) {
  test::TempDir dir;
  std::ofstream(dir.path("x.sens")) << "not a recording";
  for (const std::string args : {" --trajectory t.txt", " --no-depth-noise", " --laps 2"}) {
    const auto r = test::runCommand(test::binPath("panmap-synth") + " --room 3 --recording " +
                                    dir.path("x.sens") + args + " --out " + dir.path("o"));
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_EQ(test::countLines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("does not apply to --recording"), std::string::npos) << r.output;
  }
  const auto every = test::runCommand(test::binPath("panmap-synth") + " --room 3 --every 2" +
                                      " --out " + dir.path("o"));
  EXPECT_EQ(every.exit_code, 1);
  EXPECT_NE(every.output.find("--every applies to --recording only"), std::string::npos);
  const auto broken = test::runCommand(test::binPath("panmap-synth") + " --room 3 --recording " +
                                       dir.path("x.sens") + " --out " + dir.path("o"));
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_EQ(test::countLines(broken.output), 1) << broken.output;
  EXPECT_NE(broken.output.find(dir.path("x.sens")), std::string::npos) << broken.output;
}

}  // namespace
}  // namespace panmap
