// Unannotated clutter in the simulated segmenter: class-0 instances painted into the stuff they
// touch, as a low-score thing, or left void, at the configured rates.
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/sim/segmenter_noise.h"

namespace panmap {
namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;

// A wall (top half) and floor (bottom half) with 24 clutter patches of 20x20 px: the first 12
// on the wall, the other 12 on the floor, each touching only its own stuff.
struct ClutterScene {
  LabelImage instances{kWidth, kHeight, 0};
  LabelImage semantics{kWidth, kHeight, 0};
  std::map<int32_t, InstanceInfo> infos;
  ClutterScene() {
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const bool wall = v < kHeight / 2;
        instances(u, v) = wall ? 1 : 2;
        semantics(u, v) = wall ? 1 : 2;
      }
    }
    infos[1] = InstanceInfo{1, 5.0f, true};
    infos[2] = InstanceInfo{2, 5.0f, true};
    for (int k = 0; k < 24; ++k) {
      const int32_t id = 100 + k;
      const int u0 = 10 + (k % 12) * 25, v0 = k < 12 ? 40 : 160;
      for (int v = v0; v < v0 + 20; ++v) {
        for (int u = u0; u < u0 + 20; ++u) instances(u, v) = id, semantics(u, v) = 0;
      }
      infos[id] = InstanceInfo{0, 0.2f, false};
    }
  }
};

TEST(ClutterPainting, OffByDefaultLeavesClutterVoid) {
  const ClutterScene scene;
  SegmenterNoise noise(SegmenterNoiseConfig::fromPreset("clean"), 5);
  const PanopticFrame frame = noise.segment(scene.instances, scene.semantics, 0, scene.infos);
  for (int k = 0; k < 24; ++k) {
    const int u = 20 + (k % 12) * 25, v = k < 12 ? 50 : 170;
    EXPECT_EQ(frame.segment_ids(u, v), 0) << "patch " << k;
  }
  EXPECT_EQ(frame.segments.size(), 2u);  // wall and floor only
}

TEST(ClutterPainting, RatesMatchTheConfigAndStuffPaintingUsesTheTouchingStuff) {
  const ClutterScene scene;
  SegmenterNoiseConfig config;
  config.clutter_stuff_probability = 0.5;
  config.clutter_thing_probability = 0.25;
  config.sample_scores = true;
  SegmenterNoise noise(config, 11);
  int seen = 0, stuff = 0, thing = 0, empty = 0;
  std::set<int32_t> thing_classes;
  for (int window = 0; window < 40; ++window) {
    const int f = window * config.window_frames;
    const PanopticFrame frame = noise.segment(scene.instances, scene.semantics, f, scene.infos);
    std::map<int32_t, const PanopticSegment*> by_id;
    for (const PanopticSegment& s : frame.segments) by_id[s.id] = &s;
    for (int k = 0; k < 24; ++k) {
      const int u = 20 + (k % 12) * 25, v = k < 12 ? 50 : 170;
      const int32_t id = frame.segment_ids(u, v);
      ++seen;
      if (id == 0) {
        ++empty;
        continue;
      }
      const PanopticSegment& s = *by_id.at(id);
      if (!s.is_thing) {
        ++stuff;
        EXPECT_EQ(s.category, k < 12 ? 1 : 2) << "patch " << k << " painted into the wrong stuff";
        // The whole patch is in that one segment (no boundary warp here).
        EXPECT_EQ(frame.segment_ids(u + 9, v + 9), id);
      } else {
        ++thing;
        thing_classes.insert(s.category);
        EXPECT_LT(s.score, 1.0f);
      }
    }
  }
  EXPECT_NEAR(static_cast<double>(stuff) / seen, 0.5, 0.07);
  EXPECT_NEAR(static_cast<double>(thing) / seen, 0.25, 0.06);
  EXPECT_NEAR(static_cast<double>(empty) / seen, 0.25, 0.06);
  EXPECT_EQ(thing_classes, (std::set<int32_t>{39, 40}));
  EXPECT_EQ(noise.stats().clutter_seen, seen);
  EXPECT_EQ(noise.stats().clutter_stuff, stuff);
  EXPECT_EQ(noise.stats().clutter_thing, thing);
  EXPECT_EQ(noise.stats().things_seen, 0);  // clutter is not counted as a thing
}

TEST(ClutterPainting, ChecksItsRates) {
  SegmenterNoiseConfig config;
  config.clutter_stuff_probability = 0.7;
  config.clutter_thing_probability = 0.4;
  EXPECT_THROW(config.check(), Error);
  config.clutter_thing_probability = 0.1;
  config.clutter_thing_classes = {1};  // wall is stuff
  config.clutter_thing_weights = {1.0};
  EXPECT_THROW(config.check(), Error);
  config.clutter_thing_classes = {40, 39};
  EXPECT_THROW(config.check(), Error);  // weights of another length
}

}  // namespace
}  // namespace panmap
