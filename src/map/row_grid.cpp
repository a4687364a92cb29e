#include "panmap/map/row_grid.h"

namespace panmap {

RowCamera RowCamera::of(const PinholeCamera& cam) {
  return {static_cast<float>(cam.fx), static_cast<float>(cam.fy), static_cast<float>(cam.cx),
          static_cast<float>(cam.cy)};
}

RowGrid::RowGrid(const Eigen::Isometry3f& T_W_C, const RowCamera& cam, float inv_voxel_size,
                 int v) {
  const Eigen::Matrix4f& M = T_W_C.matrix();
  const double inv_voxel = inv_voxel_size;
  const double x0 = -static_cast<double>(cam.cx) / cam.fx;
  const double y = (v - static_cast<double>(cam.cy)) / cam.fy;
  for (int r = 0; r < 3; ++r) {
    a[r] = static_cast<float>(inv_voxel * (M(r, 0) * x0 + M(r, 1) * y + M(r, 2)));
    b[r] = static_cast<float>(inv_voxel * M(r, 0) / cam.fx);
    t[r] = static_cast<float>(inv_voxel * M(r, 3));
  }
}

}  // namespace panmap
