#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/core/image.h"
#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// Everything a pinhole camera sees of a labelled mesh, before sensor noise.
struct RenderedView {
  Image<float> depth_m;        ///< z along the optical axis, metres; 0 = no surface
  ColorImage color;            ///< shaded, textured colour
  LabelImage instance;         ///< instance id of the visible surface, 0 = none
  LabelImage semantic;         ///< NYU40 id of the visible surface, 0 = none
  Image<float> cos_incidence;  ///< |cos| of the angle between view ray and surface normal
};

/// Rendering options.
struct RenderConfig {
  float near_m = 0.05f;            ///< near clipping plane, metres
  float far_m = 50.0f;             ///< nothing farther is drawn, metres
  float ambient = 0.3f;            ///< shading: ambient share of the brightness, the rest is a
                                   ///< headlight (Lambert term |n . ray|)
  float texture_cell_m = 0.08f;    ///< size of the per-object procedural texture's cells, metres
  float texture_contrast = 0.25f;  ///< brightness swing of that texture, 0..1
  /// Throws Error naming the bad field.
  void check() const;
};

/// Rasterises a labelled mesh with a z-buffer (perspective-correct depth, near-plane
/// clipping, no back-face culling). A face takes the colour and labels of its first vertex.
class MeshRenderer {
 public:
  /// Precomputes face normals and labels. Throws Error if the mesh is inconsistent.
  explicit MeshRenderer(const LabelledMesh& mesh, const RenderConfig& config = RenderConfig());

  /// Renders the view of a camera at T_W_C (camera to world, optical frame).
  RenderedView render(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C) const;

  /// Renders into an existing view (reuses its buffers: no allocation after the first frame).
  void render(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
              RenderedView* view) const;

  /// The mesh being rendered.
  const LabelledMesh& mesh() const { return mesh_; }

 private:
  struct Scratch;
  void rasterise(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                 Scratch* scratch) const;

  LabelledMesh mesh_;
  RenderConfig config_;
  std::vector<Eigen::Vector3f> face_normals_W_;
  std::vector<int32_t> face_instance_;
  std::vector<int32_t> face_semantic_;
  std::vector<Rgb8> face_color_;
};

}  // namespace panmap
