// The simulated depth noise must leave depth segmentation working as on real frames (the
// paper's release keeps ~70 % of valid 7-Scenes pixels in segments); an uncorrelated per-pixel
// noise model broke it.
#include <gtest/gtest.h>

#include "panmap/render/renderer.h"
#include "panmap/segmentation/panoptic_geometric.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/trajectory.h"
#include "test_meshes.h"

namespace panmap {
namespace {

TEST(SyntheticSegmentation, NoisyDepthStillSegments) {
  const ProceduralRoom room = generateRoom(1);
  const MeshRenderer renderer(room.mesh);
  SurveyConfig survey;
  survey.num_frames = 300;
  const auto trajectory = planSurvey(room.mesh, survey, 1);
  PanopticGeometricSegmenter segmenter(DepthSegmentationConfig{}, SurfaceFusionConfig{});
  double share = 0.0;
  int frames = 0;
  for (size_t k = 0; k < trajectory.size(); k += 60) {
    RgbdFrame frame;
    frame.camera = test::kinectCamera();
    frame.depth =
        simulateDepth(renderer.render(frame.camera, trajectory[k].T_W_C), DepthNoiseConfig{}, k);
    const FrameSegmentation seg = segmenter.segment(frame, nullptr);
    size_t valid = 0, segmented = 0;
    for (size_t i = 0; i < frame.depth.size(); ++i) {
      valid += frame.depth.data()[i] > 0;
      segmented += seg.geometric.data()[i] > 0;
    }
    share += static_cast<double>(segmented) / valid;
    ++frames;
  }
  share /= frames;
  EXPECT_GT(share, 0.5);
  RecordProperty("segmented_share", std::to_string(share));
}

}  // namespace
}  // namespace panmap
