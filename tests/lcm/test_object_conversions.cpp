#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/lcm/object_conversions.h"
#include "test_helpers.h"

namespace panmap {
namespace {

std::vector<MappedObject> sampleObjects() {
  MappedObject a;
  a.id = 4;
  a.class_id = 5;
  a.confidence = 1.0f / 3.0f;
  a.num_voxels = 1234;
  a.centroid_W = Eigen::Vector3d(0.1, -2.5, 1.0 / 3.0);
  a.aabb_min_W = Eigen::Vector3d(-0.3, -2.9, 0.0);
  a.aabb_max_W = Eigen::Vector3d(0.5, -2.1, 0.7 + 1e-15);
  a.obb_center_W = Eigen::Vector3d(0.1, -2.5, 0.35);
  a.q_W_B = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  a.obb_extent_m = Eigen::Vector3d(0.7, 0.6, 0.7);
  a.superpoints = {3, 17, 250};
  MappedObject b;
  b.id = 9;
  b.class_id = 24;
  b.confidence = 0.0f;
  b.num_voxels = 1;
  return {a, b};
}

TEST(ObjectConversions, RoundTripIsExact) {
  const std::vector<MappedObject> objects = sampleObjects();
  const object_list_t msg = test::throughBytes(toMessage(objects, 987654321));
  EXPECT_EQ(msg.utime, 987654321);
  EXPECT_EQ(msg.num_objects, 2);
  EXPECT_EQ(msg.objects[0].category, 5);
  EXPECT_EQ(msg.objects[0].obb_orientation[0], objects[0].q_W_B.w());
  EXPECT_EQ(msg.objects[0].obb_orientation[3], objects[0].q_W_B.z());
  const std::vector<MappedObject> back = fromMessage(msg);
  EXPECT_EQ(back, objects);  // every field, exactly
  EXPECT_TRUE(fromMessage(toMessage(std::vector<MappedObject>{}, 5)).empty());
}

TEST(ObjectConversions, InconsistentMessagesAreRefused) {
  object_list_t msg = toMessage(sampleObjects(), 1);
  msg.num_objects = 3;
  test::expectError([&] { fromMessage(msg); }, {"objects message", "num_objects"});
  msg = toMessage(sampleObjects(), 1);
  msg.objects[0].num_superpoints = 2;
  test::expectError([&] { fromMessage(msg); }, {"object 4", "num_superpoints"});
  msg = toMessage(sampleObjects(), 1);
  msg.objects[1].obb_orientation[0] = 0.5;
  test::expectError([&] { fromMessage(msg); }, {"object 9", "unit quaternion"});
  msg = toMessage(sampleObjects(), 1);
  msg.objects[1].id = 0;
  test::expectError([&] { fromMessage(msg); }, {"object 0", "positive"});
}

}  // namespace
}  // namespace panmap
