#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "panmap/map/row_grid.h"

namespace panmap {
namespace {

// Identity pose, fx = fy = 10, cx = 5, cy = 2, 0.25 m voxels: pixel (u, v) at depth d is the
// point ((u - 5) d / 10, (v - 2) d / 10, d), so each voxel coordinate is known by hand.
TEST(RowGrid, VoxelsOfAnIdentityPoseByHand) {
  const RowCamera cam{10.0f, 10.0f, 5.0f, 2.0f};
  const RowGrid row2(Eigen::Isometry3f::Identity(), cam, 4.0f, 2);
  // u = 5, v = 2 is the optical axis: x = y = 0, z = 1 m = voxel 4.
  EXPECT_EQ(row2.voxel(5, 1.0f), Eigen::Vector3i(0, 0, 4));
  // u = 0 at 2 m: x = -1 m = voxel -4 exactly; u = 15 at 1.3 m: x = 1.3 m -> voxel 5 (5.2).
  EXPECT_EQ(row2.voxel(0, 2.0f), Eigen::Vector3i(-4, 0, 8));
  EXPECT_EQ(row2.voxel(15, 1.3f), Eigen::Vector3i(5, 0, 5));
  // Row 0 at 1 m: y = -0.2 m -> voxel -1 (-0.8).
  const RowGrid row0(Eigen::Isometry3f::Identity(), cam, 4.0f, 0);
  EXPECT_EQ(row0.voxel(5, 1.0f), Eigen::Vector3i(0, -1, 4));
}

// Against the point back-projected and transformed in double, for random poses, pixels and
// depths: the same voxel wherever the point is not within a hair of a voxel face (there float
// rounding may go either way).
TEST(RowGrid, MatchesTheTransformedPointInDouble) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const RowCamera cam{525.0f, 527.5f, 319.5f, 239.5f};
  int compared = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const double voxel_m = trial % 2 ? 0.01 : 0.05;
    Eigen::Isometry3f T_W_C = Eigen::Isometry3f::Identity();
    T_W_C.linear() = Eigen::AngleAxisf(static_cast<float>(3.0 * unit(rng)),
                                       Eigen::Vector3f(static_cast<float>(unit(rng)),
                                                       static_cast<float>(unit(rng)),
                                                       static_cast<float>(unit(rng)))
                                           .normalized())
                         .toRotationMatrix();
    T_W_C.translation() =
        Eigen::Vector3f(static_cast<float>(unit(rng)), static_cast<float>(unit(rng)),
                        static_cast<float>(unit(rng))) *
        20.0f;
    const Eigen::Isometry3d T = T_W_C.cast<double>();
    for (int k = 0; k < 400; ++k) {
      const int u = static_cast<int>(rng() % 640), v = static_cast<int>(rng() % 480);
      const float d = static_cast<float>(0.3 + 4.0 * (unit(rng) + 1.0));
      const RowGrid grid(T_W_C, cam, static_cast<float>(1.0 / voxel_m), v);
      const Eigen::Vector3d p = T * Eigen::Vector3d((u - double{cam.cx}) * d / cam.fx,
                                                    (v - double{cam.cy}) * d / cam.fy, d);
      const Eigen::Vector3d g = p / voxel_m;
      bool near_face = false;
      for (int r = 0; r < 3; ++r) near_face |= std::abs(g[r] - std::round(g[r])) < 1e-3;
      if (near_face) continue;
      const Eigen::Vector3i expected(static_cast<int>(std::floor(g.x())),
                                     static_cast<int>(std::floor(g.y())),
                                     static_cast<int>(std::floor(g.z())));
      ASSERT_EQ(grid.voxel(u, d), expected) << "trial " << trial << " pixel " << u << "," << v;
      ++compared;
    }
  }
  EXPECT_GT(compared, 19000);  // the near-face skips must not empty the comparison
}

}  // namespace
}  // namespace panmap
