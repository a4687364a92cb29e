// The photometric consistency check on a textured wall seen by a camera sliding sideways:
// exact poses carry every pixel onto its own texture, a pose off by 2 cm does not.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/eval/photometric_consistency.h"

namespace panmap {
namespace {

constexpr double kWallDistance_m = 2.0;

/// Grey level of the wall at world (x, y): smooth, so bilinear sampling is nearly exact.
float texture(double x, double y) {
  return static_cast<float>(128.0 + 60.0 * std::sin(6.0 * x) + 50.0 * std::cos(5.0 * y));
}

PinholeCamera camera() {
  PinholeCamera c;
  c.fx = c.fy = 300.0;
  c.cx = 79.5;
  c.cy = 59.5;
  c.width = 160;
  c.height = 120;
  return c;
}

/// The frame seen from (x_m, 0, 0) looking along +z at the wall z = 2 m, exposure shifted by
/// `exposure` grey levels.
PhotometricFrame frameAt(int64_t utime, double x_m, float exposure = 0.0f) {
  PhotometricFrame f;
  f.utime = utime;
  f.camera = camera();
  f.depth_scale_m = 0.001;
  f.depth =
      DepthImage(f.camera.width, f.camera.height, static_cast<uint16_t>(kWallDistance_m * 1000.0));
  f.grey = Image<float>(f.camera.width, f.camera.height);
  for (int v = 0; v < f.camera.height; ++v) {
    for (int u = 0; u < f.camera.width; ++u) {
      const Eigen::Vector3d p = f.camera.backProject(u, v, kWallDistance_m);
      f.grey(u, v) = texture(x_m + p.x(), p.y()) + exposure;
    }
  }
  return f;
}

StampedPose posed(int64_t utime, double x_m) {
  StampedPose p;
  p.utime = utime;
  p.T_W_C.translation() = Eigen::Vector3d(x_m, 0.0, 0.0);
  return p;
}

struct Sequence {
  std::vector<PhotometricFrame> frames;
  std::vector<StampedPose> truth;
};

Sequence slide(float last_exposure = 0.0f) {
  Sequence s;
  for (int i = 0; i < 4; ++i) {
    const int64_t utime = 100000 * i;
    const double x = 0.05 * i;
    s.frames.push_back(frameAt(utime, x, i == 3 ? last_exposure : 0.0f));
    s.truth.push_back(posed(utime, x));
  }
  return s;
}

PhotometricConfig config() {
  PhotometricConfig c;
  c.frame_gaps = {1};
  c.pixel_stride = 2;
  c.min_gradient = 0.5;
  c.min_samples = 50;
  return c;
}

TEST(PhotometricConsistency, ExactPosesCarryEveryPixelOntoItsOwnTexture) {
  const Sequence s = slide();
  const auto r = photometricConsistency(s.frames, {s.truth}, config());
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].pairs, 3u);
  EXPECT_EQ(r[0].frames_posed, 4u);
  EXPECT_GT(r[0].samples, 3000u);
  EXPECT_LT(r[0].median_abs, 0.05);
}

TEST(PhotometricConsistency, APoseOffByTwoCentimetresScoresWorseOnTheSamePixels) {
  const Sequence s = slide();
  std::vector<StampedPose> off = s.truth;
  off[2].T_W_C.translation().x() += 0.02;  // 3 px at 2 m with f = 300
  const auto r = photometricConsistency(s.frames, {s.truth, off}, config());
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].samples, r[1].samples);  // scored on the same pixels
  EXPECT_LT(r[0].median_abs, 0.05);
  EXPECT_GT(r[1].median_abs, 1.0);  // two of the three pairs hold frame 2
  EXPECT_GT(r[1].mean_pair_median, 10.0 * r[0].mean_pair_median);
}

TEST(PhotometricConsistency, AnExposureChangeBetweenFramesCostsNothing) {
  const Sequence s = slide(25.0f);
  const auto r = photometricConsistency(s.frames, {s.truth}, config());
  EXPECT_LT(r[0].median_abs, 0.05);
}

TEST(PhotometricConsistency, FramesWithoutAPoseAreLeftOutAndNoPairIsAnError) {
  const Sequence s = slide();
  std::vector<StampedPose> gap = {s.truth[0], s.truth[1], s.truth[3]};
  const auto r = photometricConsistency(s.frames, {gap}, config());
  EXPECT_EQ(r[0].frames_posed, 3u);
  EXPECT_EQ(r[0].pairs, 1u);  // only (0, 1): frame 2 has no pose
  try {
    photometricConsistency(s.frames, {{s.truth[0]}}, config());
    FAIL() << "one pose gives no pair";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no frame pair"), std::string::npos) << e.what();
  }
}

TEST(PhotometricConsistency, MismatchedImageSizesAreNamed) {
  Sequence s = slide();
  s.frames[1].grey = Image<float>(80, 60);
  try {
    photometricConsistency(s.frames, {s.truth}, config());
    FAIL() << "sizes disagree";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame 100000"), std::string::npos) << e.what();
  }
  PhotometricConfig bad = config();
  bad.frame_gaps = {0};
  EXPECT_THROW(bad.check(), Error);
}

}  // namespace
}  // namespace panmap
