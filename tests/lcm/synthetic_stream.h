// A short synthetic input stream as encoded LCM messages, for session and live-mapper tests:
// room 1 rendered at 160x120 along a survey, clean masks, ground-truth poses.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/lcm/conversions.h"
#include "panmap/lcm/live_mapper.h"
#include "panmap/mapper/mapper.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/sequence.h"
#include "panmap/sim/trajectory.h"
#include "test_helpers.h"

namespace panmap {
namespace test {

/// One encoded message.
using Encoded = OutgoingMessage;
using panmap::encodeMessage;

/// The frames of the stream, decoded form.
struct SyntheticStream {
  std::vector<RgbdFrame> frames;
  std::vector<StampedPose> poses;
  std::vector<PanopticFrame> masks;

  /// Messages in capture order: pose, mask, frame for each frame.
  std::vector<Encoded> messages() const {
    std::vector<Encoded> out;
    for (size_t k = 0; k < frames.size(); ++k) {
      out.push_back(encodeMessage("CAMERA_POSE", toMessage(poses[k])));
      out.push_back(encodeMessage("PANOPTIC", toMessage(masks[k], ImageEncoding{})));
      out.push_back(encodeMessage("CAMERA_RGBD", toMessage(frames[k], ImageEncoding{})));
    }
    return out;
  }
};

/// `n` frames of room 1, every 10th pose of a 30 Hz survey (rendered once per process).
inline const SyntheticStream& syntheticStream(size_t n = 12) {
  static std::map<size_t, SyntheticStream> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  const ProceduralRoom room = generateRoom(1);
  SurveyConfig survey;
  survey.num_frames = static_cast<int>(10 * n);
  std::vector<StampedPose> trajectory = planSurvey(room.mesh, survey, 1);
  std::vector<StampedPose> every_tenth;
  for (size_t k = 0; k < trajectory.size() && every_tenth.size() < n; k += 10) {
    every_tenth.push_back(trajectory[k]);
  }
  SynthConfig config;
  config.camera = PinholeCamera{131.25, 131.25, 79.5, 59.5, 160, 120};
  config.masks = SegmenterNoiseConfig::fromPreset("clean");
  config.poses = PoseDriftConfig::fromPreset("gt");
  SequenceSynthesizer synth(room.mesh, every_tenth, config);
  SyntheticStream stream;
  for (size_t k = 0; k < synth.size(); ++k) {
    SynthFrame f = synth.frame(k);
    stream.frames.push_back(f.rgbd);
    stream.poses.push_back(f.input_pose);
    stream.masks.push_back(f.panoptic);
  }
  return cache.emplace(n, std::move(stream)).first->second;
}

/// The map file of a mapper (config, TSDF, votes, super-points, graph, occupancy), byte for
/// byte: two mappers in the same state give the same bytes.
inline std::string mapBytes(const Mapper& mapper) {
  TempDir dir;
  mapper.save(dir.path("map.panmap"));
  return fileBytes(dir.path("map.panmap"));
}

/// A mapper config fast enough for tests on the stream (4 cm voxels, one thread).
inline MapperConfig streamMapperConfig() {
  MapperConfig config;
  config.map.voxel_size_m = 0.04f;
  config.num_threads = 1;
  return config;
}

}  // namespace test
}  // namespace panmap
