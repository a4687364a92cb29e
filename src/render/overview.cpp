#include "panmap/render/overview.h"

#include <algorithm>
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/render/renderer.h"

namespace panmap {

OverviewColouring vertexColours(const LabelledMesh& mesh) {
  if (mesh.colors.empty()) return [](size_t) { return Rgb8{180, 180, 180}; };
  return [&mesh](size_t v) { return mesh.colors[v]; };
}

std::vector<ColorImage> renderOverviews(const LabelledMesh& mesh,
                                        const std::vector<OverviewColouring>& colourings, int width,
                                        int height) {
  if (mesh.vertices.empty() || mesh.faces.empty()) {
    return std::vector<ColorImage>(colourings.size(), ColorImage(width, height));
  }
  Eigen::AlignedBox3f box;
  for (const auto& v : mesh.vertices) box.extend(v);
  RenderConfig config;
  config.texture_contrast = 0.0f;
  config.ambient = 0.45f;
  config.far_m = 1000.0f;
  // Drop the faces near the top, so a room's interior shows.
  config.max_face_height_m = box.max().z() - 0.2f;
  // The mesh is shared, not copied, and no per-face array is kept: only the picture's faces
  // are shaded, by the colourings below.
  config.keep_face_data = false;
  const MeshRenderer renderer(
      std::shared_ptr<const LabelledMesh>(std::shared_ptr<const LabelledMesh>(), &mesh), config);
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
  Image<int32_t> face;
  Image<float> cos_incidence;
  renderer.renderFaces(camera, T_W_C, &face, &cos_incidence);
  const std::vector<Eigen::Vector3i>& faces = renderer.mesh().faces;
  std::vector<ColorImage> pictures;
  for (const OverviewColouring& colouring : colourings) {
    ColorImage picture(width, height);
    for (size_t i = 0; i < picture.size(); ++i) {
      const int32_t fi = face.data()[i];
      if (fi < 0) {
        picture.data()[i] = Rgb8{255, 255, 255};
        continue;
      }
      // MeshRenderer's shading without texture: headlight plus ambient, rounded.
      const float shade = config.ambient + (1.0f - config.ambient) * cos_incidence.data()[i];
      picture.data()[i] = shadedColour(colouring(static_cast<size_t>(faces[fi][0])), shade);
    }
    pictures.push_back(std::move(picture));
  }
  return pictures;
}

}  // namespace panmap
