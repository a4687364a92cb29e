#include <cmath>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/eval/label_transfer.h"

namespace panmap {
namespace {

TEST(LabelTransfer, RespectsFiveCentimetreRadius) {
  LabelledMesh pred;
  pred.vertices = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}};
  pred.semantic = {5, 7};
  pred.instance = {3, 4};
  pred.superpoint = {9, 10};
  const std::vector<Eigen::Vector3f> gt = {
      {0.049f, 0.0f, 0.0f}, {0.051f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.04f}};
  const TransferredLabels t = transferLabels(pred, gt);
  EXPECT_EQ(t.semantic, (std::vector<int32_t>{5, 0, 5, 7}));
  EXPECT_EQ(t.instance, (std::vector<int32_t>{3, 0, 3, 4}));
  EXPECT_EQ(t.superpoint, (std::vector<int32_t>{9, 0, 9, 10}));
  EXPECT_EQ(t.reached, (std::vector<uint8_t>{1, 0, 1, 1}));
  EXPECT_EQ(t.num_transferred, 3u);
  // Distances to the nearest predicted vertex, out of range too.
  ASSERT_EQ(t.distance_m.size(), 4u);
  EXPECT_FLOAT_EQ(t.distance_m[0], 0.049f);
  EXPECT_FLOAT_EQ(t.distance_m[1], 0.051f);
  EXPECT_EQ(t.distance_m[2], 0.0f);
  EXPECT_FLOAT_EQ(t.distance_m[3], 0.04f);
}

TEST(LabelTransfer, MissingArraysReadAsZero) {
  LabelledMesh pred;
  pred.vertices = {{0.0f, 0.0f, 0.0f}};
  pred.semantic = {5};
  const TransferredLabels t = transferLabels(pred, {{0.01f, 0.0f, 0.0f}});
  EXPECT_EQ(t.semantic, (std::vector<int32_t>{5}));
  EXPECT_EQ(t.instance, (std::vector<int32_t>{0}));
  EXPECT_EQ(t.superpoint, (std::vector<int32_t>{0}));
}

TEST(LabelTransfer, EmptyPredictionLeavesEverythingUnlabelled) {
  const TransferredLabels t = transferLabels(LabelledMesh(), {{0.0f, 0.0f, 0.0f}});
  EXPECT_EQ(t.semantic, (std::vector<int32_t>{0}));
  EXPECT_EQ(t.reached, (std::vector<uint8_t>{0}));
  EXPECT_EQ(t.num_transferred, 0u);
  ASSERT_EQ(t.distance_m.size(), 1u);
  EXPECT_TRUE(std::isinf(t.distance_m[0]));  // nothing to be near
  EXPECT_THROW(transferLabels(LabelledMesh(), {}, -1.0), Error);
}

}  // namespace
}  // namespace panmap
