// FrameStoreWriter: frame store writes on a thread of their own, in order, exactly, with
// failures reported instead of lost, and nothing queued lost when it stops.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/loop/frame_store.h"
#include "panmap/loop/frame_store_writer.h"
#include "test_helpers.h"

namespace panmap {
namespace {

constexpr int kWidth = 32;
constexpr int kHeight = 24;

// A frame whose depth, labels and pose depend on k.
RgbdFrame frame(int k) {
  RgbdFrame f;
  f.utime = 1000 + k;
  f.camera.fx = f.camera.fy = 30.0 + k / 7.0;
  f.camera.cx = 15.5;
  f.camera.cy = 11.5;
  f.camera.width = kWidth;
  f.camera.height = kHeight;
  f.depth = DepthImage(kWidth, kHeight);
  for (size_t i = 0; i < f.depth.size(); ++i) f.depth.data()[i] = static_cast<uint16_t>(i * 7 + k);
  return f;
}

LabelImage labels(int k) {
  LabelImage l(kWidth, kHeight);
  for (size_t i = 0; i < l.size(); ++i) l.data()[i] = static_cast<int32_t>(i / 50 + k);
  return l;
}

Eigen::Isometry3d pose(int k) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.1 * k + 0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(k / 3.0, 0.5, -1.0 / 7.0);
  return T;
}

FrameStoreConfig config(const std::string& folder) {
  FrameStoreConfig c;
  c.folder = folder;
  return c;
}

TEST(FrameStoreWriter, FramesComeBackExactlyEvenWhileStillQueued) {
  test::TempDir dir;
  FrameStore store(config(dir.path("store")));
  FrameStoreWriter writer(&store, 3);
  for (int k = 0; k < 10; ++k) {
    writer.add(frame(k), pose(k), labels(k));
    // Right after add: load() waits for the write if it has not happened yet.
    const StoredFrame back = writer.load(frame(k).utime);
    EXPECT_EQ(back.rgbd.depth.data()[5], frame(k).depth.data()[5]) << k;
    EXPECT_TRUE(
        std::equal(back.labels.data(), back.labels.data() + back.labels.size(), labels(k).data()))
        << k;
    EXPECT_EQ(back.T_W_C.matrix(), pose(k).matrix()) << k;
  }
  writer.flush();
  EXPECT_EQ(writer.queued(), 0u);
  EXPECT_TRUE(writer.takeErrors().empty());
  std::vector<int64_t> expected;
  for (int k = 0; k < 10; ++k) expected.push_back(1000 + k);
  EXPECT_EQ(store.utimes(), expected);
}

TEST(FrameStoreWriter, AFailedWriteIsReportedOnceAndTheStoreKeepsTheRest) {
  test::TempDir dir;
  FrameStore store(config(dir.path("store")));
  store.add(frame(1), pose(1), labels(1));  // the writer's copy of frame 1 will be refused
  FrameStoreWriter writer(&store);
  writer.add(frame(0), pose(0), labels(0));
  writer.add(frame(1), pose(5), labels(5));
  writer.add(frame(2), pose(2), labels(2));
  writer.flush();
  const std::vector<std::string> errors = writer.takeErrors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("frame store: frame 1001 is already stored"), std::string::npos)
      << errors[0];
  EXPECT_TRUE(writer.takeErrors().empty());
  EXPECT_EQ(store.size(), 3u);
  EXPECT_EQ(store.load(1001).T_W_C.matrix(), pose(1).matrix());  // the first one stays
}

TEST(FrameStoreWriter, StoppingWritesEverythingQueued) {
  test::TempDir dir;
  FrameStore store(config(dir.path("store")));
  {
    FrameStoreWriter writer(&store, 16);
    for (int k = 0; k < 12; ++k) writer.add(frame(k), pose(k), labels(k));
  }
  EXPECT_EQ(store.size(), 12u);
  EXPECT_THROW(FrameStoreWriter(nullptr), Error);
  EXPECT_THROW(FrameStoreWriter(&store, 0), Error);
}

}  // namespace
}  // namespace panmap
