// Telling how a pose file is written from the depth of frame pairs: each mistake undone exactly,
// each found on a rendered survey, a camera that does not move decides nothing.
#include <vector>

#include <gtest/gtest.h>

#include "panmap/convention/pose_convention.h"
#include "panmap/convention/pose_convention_watch.h"
#include "panmap/core/error.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/trajectory.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

Eigen::Isometry3d somePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -1.0, 0.4).normalized()).matrix();
  T.translation() = Eigen::Vector3d(1.5, -0.25, 2.0);
  return T;
}

// T as a reader parses it when the file held T's quaternion as w x y z: read as x y z w.
Eigen::Isometry3d readWithScalarFirst(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  Eigen::Isometry3d read = T;
  read.linear() = Eigen::Quaterniond(q.z(), q.w(), q.x(), q.y()).normalized().matrix();
  return read;
}

double difference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

TEST(PoseConvention, EachReadingUndoesItsMistakeExactly) {
  const Eigen::Isometry3d T = somePose();
  EXPECT_LT(difference(PoseConvention{}.apply(T), T), 1e-12);
  EXPECT_LT(difference(PoseConvention{1.0, false, true}.apply(T.inverse()), T), 1e-12);
  constexpr QuaternionInput kTum = QuaternionInput::kScalarLast;
  EXPECT_LT(difference(PoseConvention{1.0, true, false, kTum}.apply(readWithScalarFirst(T)), T),
            1e-12);
  // A pose_t filled from Eigen's coeffs() (x y z w) read as w x y z.
  const Eigen::Quaterniond q(T.linear());
  Eigen::Isometry3d coeffs = T;
  coeffs.linear() = Eigen::Quaterniond(q.x(), q.y(), q.z(), q.w()).normalized().matrix();
  EXPECT_LT(
      difference(PoseConvention{1.0, true, false, QuaternionInput::kScalarFirst}.apply(coeffs), T),
      1e-12);
  Eigen::Isometry3d mm = T;
  mm.translation() *= 1000.0;
  EXPECT_LT(difference(PoseConvention{0.001, false, false}.apply(mm), T), 1e-12);
  // All three at once: millimetres of T_C_W with the scalar first.
  Eigen::Isometry3d all = T.inverse();
  all.translation() *= 1000.0;
  EXPECT_LT(difference(PoseConvention{0.001, true, true, kTum}.apply(readWithScalarFirst(all)), T),
            1e-12);
  EXPECT_TRUE(PoseConvention{}.isIdentity());
  EXPECT_FALSE((PoseConvention{1.0, false, true}.isIdentity()));
  EXPECT_EQ((PoseConvention{1.0, false, false, kTum}.describe()),
            "camera-to-world, quaternion x y z w, metres");
  EXPECT_EQ((PoseConvention{1.0, true, false, kTum}.describe()),
            "camera-to-world, quaternion w x y z, metres");
  EXPECT_EQ((PoseConvention{1.0, true, false, QuaternionInput::kScalarFirst}.describe()),
            "camera-to-world, quaternion x y z w, metres");
  EXPECT_EQ((PoseConvention{0.001, false, true}.describe()), "world-to-camera, millimetres");
  EXPECT_EQ((PoseConvention{1.0, false, false, QuaternionInput::kNone, true}.describe()),
            "camera-to-world, metres, camera x forward, z up (a ROS body frame)");
  // A body frame's pose, T_W_body = T_W_optical T_optical_body, back to the optical frame's.
  Eigen::Isometry3d T_optical_body = Eigen::Isometry3d::Identity();
  T_optical_body.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  EXPECT_LT(difference(PoseConvention{1.0, false, false, QuaternionInput::kNone, true}.apply(
                           T * T_optical_body),
                       T),
            1e-12);
}

// Frames of procedural room 1's survey (30 Hz, 10 s), exact depth.
struct Survey {
  Survey() : room(generateRoom(1)), renderer(room.mesh) {
    SurveyConfig config;
    config.num_frames = 300;
    trajectory = planSurvey(room.mesh, config, 1);
    for (int k = 20; k < 60; k += 2) {
      frames.push_back(frameAt(k));
      poses.push_back(trajectory[k].T_W_C);
    }
    // Frames 2 and 6 survey frames apart (67 and 200 ms).
    for (int i = 0; i + 3 < static_cast<int>(frames.size()); i += 3) {
      pairs.emplace_back(i, i + 1);
      pairs.emplace_back(i, i + 3);
    }
  }
  // Survey frame k, rendered.
  RgbdFrame frameAt(int k) const {
    RgbdFrame frame;
    frame.camera = test::kinectCamera();
    frame.utime = trajectory[k].utime;
    DepthNoiseConfig noise;
    noise.enabled = false;
    frame.depth = simulateDepth(renderer.render(frame.camera, trajectory[k].T_W_C), noise, 0);
    return frame;
  }
  // The frames with their poses as `mistake` wrote them.
  std::vector<PoseSample> samples(
      const std::function<Eigen::Isometry3d(Eigen::Isometry3d)>& mistake) const {
    std::vector<PoseSample> out;
    for (size_t i = 0; i < frames.size(); ++i) out.push_back({frames[i], mistake(poses[i])});
    return out;
  }
  ProceduralRoom room;
  MeshRenderer renderer;
  std::vector<StampedPose> trajectory;
  std::vector<RgbdFrame> frames;
  std::vector<Eigen::Isometry3d> poses;
  std::vector<std::pair<int, int>> pairs;
};

const Survey& survey() {
  static const Survey* s = new Survey();  // rendered once, shared by the tests
  return *s;
}

TEST(DepthAgreement, AFrameAgreesWithItselfEverywhereAndNotWithAMovedCopy) {
  const Survey& s = survey();
  EXPECT_DOUBLE_EQ(depthAgreement(s.frames[0], s.poses[0], s.frames[0], s.poses[0]), 1.0);
  Eigen::Isometry3d moved = s.poses[0];
  moved.translation() += moved.linear() * Eigen::Vector3d(0.0, 0.0, 0.5);  // 50 cm forward
  EXPECT_LT(depthAgreement(s.frames[0], moved, s.frames[0], s.poses[0]), 0.2);
  RgbdFrame empty = s.frames[0];
  empty.depth = DepthImage(empty.depth.width(), empty.depth.height(), 0);
  EXPECT_EQ(depthAgreement(empty, s.poses[0], s.frames[0], s.poses[0]), 0.0);
}

TEST(DetectPoseConvention, FindsEachWayAFileCanBeWrittenOnARenderedSurvey) {
  const Survey& s = survey();
  struct Case {
    const char* what;
    std::function<Eigen::Isometry3d(Eigen::Isometry3d)> mistake;
    PoseConvention expected;
  };
  const std::vector<Case> cases = {
      {"as TUM writes it", [](Eigen::Isometry3d T) { return T; }, PoseConvention{}},
      {"world-to-camera", [](Eigen::Isometry3d T) { return Eigen::Isometry3d(T.inverse()); },
       PoseConvention{1.0, false, true}},
      {"scalar first", [](Eigen::Isometry3d T) { return readWithScalarFirst(T); },
       PoseConvention{1.0, true, false, QuaternionInput::kScalarLast}},
      {"millimetres",
       [](Eigen::Isometry3d T) {
         T.translation() *= 1000.0;
         return T;
       },
       PoseConvention{0.001, false, false}},
      {"a ROS camera_link (x forward, z up) for the optical frame",
       [](Eigen::Isometry3d T) {
         Eigen::Isometry3d T_optical_body = Eigen::Isometry3d::Identity();
         T_optical_body.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
         return Eigen::Isometry3d(T * T_optical_body);
       },
       PoseConvention{1.0, false, false, QuaternionInput::kScalarLast, true}},
      {"centimetres, world-to-camera",
       [](Eigen::Isometry3d T) {
         Eigen::Isometry3d inverse = T.inverse();
         inverse.translation() *= 100.0;
         return inverse;
       },
       PoseConvention{0.01, false, true}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const PoseConventionVerdict v = detectPoseConvention(
        s.samples(c.mistake), s.pairs, QuaternionInput::kScalarLast, PoseConventionChoice());
    EXPECT_EQ(v.convention.translation_scale, c.expected.translation_scale);
    EXPECT_EQ(v.convention.scalar_moved, c.expected.scalar_moved);
    EXPECT_EQ(v.convention.inverted, c.expected.inverted);
    EXPECT_EQ(v.convention.body_frame, c.expected.body_frame);
    EXPECT_EQ(v.changed, !c.expected.isIdentity()) << v.note;
    EXPECT_EQ(v.pairs, static_cast<int>(s.pairs.size()));
    EXPECT_GT(v.agreement_chosen, 0.6) << v.note;
    if (v.changed) {
      EXPECT_GE(v.agreement_chosen - v.agreement_as_read, 0.15) << v.note;
    }
  }
}

TEST(DetectPoseConvention, WhatTheUserFixedIsNotSearchedAndALowAgreementIsSaid) {
  const Survey& s = survey();
  PoseConventionChoice fixed;
  fixed.inverted = false;
  const PoseConventionVerdict v = detectPoseConvention(
      s.samples([](Eigen::Isometry3d T) { return Eigen::Isometry3d(T.inverse()); }), s.pairs,
      QuaternionInput::kScalarLast, fixed);
  EXPECT_FALSE(v.convention.inverted);
  EXPECT_FALSE(v.changed);
  EXPECT_NE(v.note.find("agrees on only"), std::string::npos) << v.note;
  // Quaternions not tried for a matrix file: scalar-first stays as read.
  const PoseConventionVerdict matrices =
      detectPoseConvention(s.samples([](Eigen::Isometry3d T) { return readWithScalarFirst(T); }),
                           s.pairs, QuaternionInput::kNone, PoseConventionChoice());
  EXPECT_FALSE(matrices.convention.scalar_moved);
}

TEST(DetectPoseConvention, ACameraThatDoesNotMoveDecidesNothing) {
  const Survey& s = survey();
  std::vector<PoseSample> still;
  for (int i = 0; i < 4; ++i) still.push_back({s.frames[0], s.poses[0]});
  const std::vector<std::pair<int, int>> pairs = {{0, 1}, {0, 2}, {1, 3}};
  // Every reading carries a frame onto itself: the file stays as read.
  for (const bool inverted : {false, true}) {
    std::vector<PoseSample> samples = still;
    if (inverted) {
      for (PoseSample& p : samples) p.T_as_read = p.T_as_read.inverse();
    }
    const PoseConventionVerdict v =
        detectPoseConvention(samples, pairs, QuaternionInput::kScalarLast, {});
    EXPECT_FALSE(v.changed);
    EXPECT_DOUBLE_EQ(v.agreement_as_read, 1.0);
  }
  const PoseConventionVerdict none =
      detectPoseConvention(still, {}, QuaternionInput::kScalarLast, {});
  EXPECT_FALSE(none.changed);
  EXPECT_NE(none.note.find("no two frames"), std::string::npos);
}

TEST(DetectPoseConvention, BadArgumentsAreNamed) {
  const Survey& s = survey();
  test::expectError(
      [&] {
        detectPoseConvention(s.samples([](Eigen::Isometry3d T) { return T; }), {{0, 999}},
                             QuaternionInput::kScalarLast, {});
      },
      {"pair names a frame"});
  PoseConventionConfig config;
  config.pixel_step = 0;
  test::expectError([&] { config.check(); }, {"pixel_step"});
  config = PoseConventionConfig();
  config.min_gain = 1.0;
  test::expectError([&] { config.check(); }, {"min_gain"});
}

// Live poses are checked by the mapper as they come: a pose_t filled world-to-camera (what
// ORB-SLAM3's TrackRGBD returns) or from Eigen's coeffs() (x y z w into the w x y z field).
TEST(PoseConventionWatch, NamesASendersConventionFromAWindowThatMoves) {
  const Survey& s = survey();
  using Sent = std::function<Eigen::Isometry3d(Eigen::Isometry3d)>;
  // Survey frames first .. last (30 Hz), each pose as `sent` makes it, with utimes shifted by
  // `shift`.
  auto feed = [&](PoseConventionWatch* watch, int first, int last, const Sent& sent,
                  int64_t shift = 0) {
    for (int k = first; k <= last; ++k) {
      RgbdFrame frame = s.frameAt(k);
      frame.utime += shift;
      watch->add(frame, sent(s.trajectory[k].T_W_C));
    }
  };
  const Sent as_is = [](Eigen::Isometry3d T) { return T; };
  const Sent inverted = [](Eigen::Isometry3d T) { return Eigen::Isometry3d(T.inverse()); };
  const Sent coeffs = [](Eigen::Isometry3d T) {
    const Eigen::Quaterniond q(T.linear());
    T.linear() = Eigen::Quaterniond(q.x(), q.y(), q.z(), q.w()).normalized().matrix();
    return T;
  };
  PoseConventionWatch right;
  feed(&right, 60, 90, as_is);
  EXPECT_FALSE(right.finding());
  EXPECT_EQ(right.warning(), "");

  PoseConventionWatch inverse;
  feed(&inverse, 60, 90, inverted);
  ASSERT_TRUE(inverse.finding());
  EXPECT_TRUE(inverse.finding()->convention.inverted);
  EXPECT_NE(inverse.warning().find("read as world-to-camera, quaternion w x y z, metres: check "
                                   "the sender's convention"),
            std::string::npos)
      << inverse.warning();

  PoseConventionWatch scalar_last;
  feed(&scalar_last, 60, 90, coeffs);
  ASSERT_TRUE(scalar_last.finding());
  EXPECT_TRUE(scalar_last.finding()->convention.scalar_moved);
  EXPECT_NE(scalar_last.warning().find("quaternion x y z w"), std::string::npos)
      << scalar_last.warning();

  // A camera standing still through the first window decides nothing; the next window, once
  // it moves, does.
  PoseConventionWatchConfig config;
  config.window_every_s = 10.0;
  PoseConventionWatch later(config);
  RgbdFrame still = s.frameAt(30);
  for (int i = 0; i < 30; ++i) {
    still.utime = s.trajectory[30].utime + i * 200000;
    later.add(still, inverted(s.trajectory[30].T_W_C));
  }
  EXPECT_FALSE(later.finding());
  feed(&later, 60, 90, inverted, 10000000);
  EXPECT_TRUE(later.finding());
  config.window_every_s = 1.0;
  test::expectError([&] { PoseConventionWatch bad(config); }, {"window_every_s"});
}

}  // namespace
}  // namespace panmap
