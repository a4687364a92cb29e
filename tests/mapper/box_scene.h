#pragma once

#include <cmath>
#include <map>
#include <memory>

#include <gtest/gtest.h>

#include "panmap/mapper/mapper.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/segmenter_noise.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {

// A floor, a wall, and two touching boxes of different classes (cabinet 3 and fridge 24),
// rendered exactly with ground-truth masks from several poses.
class BoxScene : public ::testing::Test {
 protected:
  BoxScene() : renderer_(makeScene()), segmenter_(SegmenterNoiseConfig::fromPreset("clean"), 1) {
    infos_[1] = InstanceInfo{2, 6.0f, true};
    infos_[2] = InstanceInfo{1, 6.0f, true};
    infos_[3] = InstanceInfo{3, 0.8f, false};
    infos_[4] = InstanceInfo{24, 1.6f, false};
  }
  static LabelledMesh makeScene() {
    LabelledMesh mesh;
    test::addQuad(&mesh, {-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}, 1, 2, 30);  // floor
    test::addQuad(&mesh, {1.6f, -3, 0}, {1.6f, 3, 0}, {1.6f, 3, 2.5f}, {1.6f, -3, 2.5f}, 2, 1,
                  30);                                                      // wall
    test::addBox(&mesh, {0.8f, -0.8f, 0.0f}, {1.4f, 0.0f, 0.9f}, 3, 3, 8);  // cabinet
    test::addBox(&mesh, {0.8f, 0.0f, 0.0f}, {1.4f, 0.7f, 1.6f}, 4, 24, 8);  // fridge, touching
    return mesh;
  }
  Eigen::Isometry3d pose(int k) const {
    const double a = -0.6 + 0.12 * k;
    const Eigen::Vector3d eye(1.1 - 2.2 * std::cos(a), 2.2 * std::sin(a), 1.5);
    return test::lookAt(eye, {1.1, 0.0, 0.6});
  }
  void frameAt(int k, RgbdFrame* frame, PanopticFrame* panoptic) {
    const RenderedView view = renderer_.render(test::kinectCamera(), pose(k));
    DepthNoiseConfig exact;
    exact.enabled = false;
    frame->camera = test::kinectCamera();
    frame->utime = k * 33333;
    frame->frame_id = k;
    frame->depth = simulateDepth(view, exact, 0);
    frame->color = view.color;
    *panoptic = segmenter_.segment(view.instance, view.semantic, k, infos_);
  }
  std::unique_ptr<Mapper> run(const MapperConfig& config, int frames) {
    auto mapper = std::make_unique<Mapper>(config);
    for (int k = 0; k < frames; ++k) {
      RgbdFrame frame;
      PanopticFrame panoptic;
      frameAt(k, &frame, &panoptic);
      mapper->integrate(frame, pose(k), &panoptic);
    }
    return mapper;
  }
  static MapperConfig config() {
    MapperConfig c;
    c.map.voxel_size_m = 0.02f;
    return c;
  }

  MeshRenderer renderer_;
  SegmenterNoise segmenter_;
  std::map<int32_t, InstanceInfo> infos_;
};

}  // namespace panmap
