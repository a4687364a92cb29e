#include "panmap/map/interpolation.h"

#include <cmath>

namespace panmap {

bool interpolateSdf(const TsdfMap& map, const Eigen::Vector3f& p_W, float* sdf_m,
                    Eigen::Vector3f* gradient_W) {
  const float v = map.voxelSize();
  // Voxel centres sit at (i + 0.5) v: shift so that the lower corner centre is integer.
  const Eigen::Vector3f g = p_W / v - Eigen::Vector3f::Constant(0.5f);
  const Eigen::Vector3f base = g.array().floor();
  const Eigen::Vector3f t = g - base;
  float c[2][2][2];
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const Eigen::Vector3f centre =
            (base + Eigen::Vector3f(dx, dy, dz) + Eigen::Vector3f::Constant(0.5f)) * v;
        const Voxel* voxel = map.findVoxel(centre);
        if (!voxel || voxel->weight <= 0.0f) return false;
        c[dx][dy][dz] = voxel->sdf_m;
      }
    }
  }
  auto lerp = [](float a, float b, float s) { return a + s * (b - a); };
  const float c00 = lerp(c[0][0][0], c[1][0][0], t.x()), c10 = lerp(c[0][1][0], c[1][1][0], t.x());
  const float c01 = lerp(c[0][0][1], c[1][0][1], t.x()), c11 = lerp(c[0][1][1], c[1][1][1], t.x());
  const float c0 = lerp(c00, c10, t.y()), c1 = lerp(c01, c11, t.y());
  *sdf_m = lerp(c0, c1, t.z());
  if (gradient_W) {
    const float gx = lerp(lerp(c[1][0][0] - c[0][0][0], c[1][1][0] - c[0][1][0], t.y()),
                          lerp(c[1][0][1] - c[0][0][1], c[1][1][1] - c[0][1][1], t.y()), t.z());
    const float gy = lerp(lerp(c[0][1][0] - c[0][0][0], c[1][1][0] - c[1][0][0], t.x()),
                          lerp(c[0][1][1] - c[0][0][1], c[1][1][1] - c[1][0][1], t.x()), t.z());
    const float gz = c1 - c0;
    *gradient_W = Eigen::Vector3f(gx, gy, gz) / v;
  }
  return true;
}

}  // namespace panmap
