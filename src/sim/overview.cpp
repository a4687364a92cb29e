#include "panmap/sim/overview.h"

#include <cmath>

#include "panmap/core/error.h"
#include "panmap/sim/renderer.h"

namespace panmap {

ColorImage renderOverview(const LabelledMesh& mesh, int width, int height) {
  if (mesh.vertices.empty() || mesh.faces.empty()) return ColorImage(width, height);
  Eigen::AlignedBox3f box;
  for (const auto& v : mesh.vertices) box.extend(v);
  // Drop the faces near the top, so a room's interior shows.
  LabelledMesh cut = mesh;
  cut.faces.clear();
  const float top = box.max().z() - 0.2f;
  for (const auto& f : mesh.faces) {
    if (mesh.vertices[f[0]].z() > top && mesh.vertices[f[1]].z() > top &&
        mesh.vertices[f[2]].z() > top) {
      continue;
    }
    cut.faces.push_back(f);
  }
  RenderConfig config;
  config.texture_contrast = 0.0f;
  config.ambient = 0.45f;
  config.far_m = 1000.0f;
  const MeshRenderer renderer(cut, config);
  const Eigen::Vector3d centre = box.center().cast<double>();
  const Eigen::Vector3d size = box.sizes().cast<double>();
  const double extent = std::max(size.x(), size.y());
  // Camera south of the box, high up, looking down 50 degrees at the centre.
  const double pitch = 50.0 * M_PI / 180.0;
  const double fov_half = 0.5;  // rad, horizontal
  const double distance = 0.75 * extent / std::tan(fov_half) + 0.5 * size.z();
  const Eigen::Vector3d forward(0.0, std::cos(pitch), -std::sin(pitch));
  const Eigen::Vector3d eye = centre - distance * forward;
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  T_W_C.linear().col(0) = right;
  T_W_C.linear().col(1) = forward.cross(right);
  T_W_C.linear().col(2) = forward;
  T_W_C.translation() = eye;
  const double f = 0.5 * width / std::tan(fov_half);
  const PinholeCamera camera{f, f, 0.5 * width - 0.5, 0.5 * height - 0.5, width, height};
  RenderedView view = renderer.render(camera, T_W_C);
  for (size_t i = 0; i < view.color.size(); ++i) {
    if (view.depth_m.data()[i] <= 0.0f) view.color.data()[i] = Rgb8{255, 255, 255};
  }
  return view.color;
}

}  // namespace panmap
