#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

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
  /// Skip runs of consecutive faces whose bounds lie wholly outside the view frustum. The
  /// image is bit-identical either way (faces keep their order); off only to test that.
  bool cull = true;
  /// Faces whose three corners all lie higher than this (world z, metres) are not drawn: an
  /// overview's ceiling cut away. Infinite: every face.
  float max_face_height_m = std::numeric_limits<float>::infinity();
  /// Keep every face's normal, labels and colour (up to 23 bytes a face) for fast shading; off:
  /// each shaded pixel reads them through the mesh (the normal computed bit for bit the same),
  /// for meshes too large to hold twice (a building's).
  bool keep_face_data = true;
  /// Throws Error naming the bad field.
  void check() const;
};

/// `base` shaded by `shade` (>= 0), as MeshRenderer colours a pixel: each channel rounded to
/// the nearest value, saturating at 255.
inline Rgb8 shadedColour(Rgb8 base, float shade) {
  auto channel = [shade](uint8_t c) {
    return static_cast<uint8_t>(std::min(255.0f, static_cast<float>(c) * shade + 0.5f));
  };
  return Rgb8{channel(base.r), channel(base.g), channel(base.b)};
}

/// Rasterises a labelled mesh with a z-buffer (perspective-correct depth, near-plane
/// clipping, no back-face culling). A face takes the colour and labels of its first vertex.
class MeshRenderer {
 public:
  /// Precomputes face normals and labels. Throws Error if the mesh is inconsistent.
  explicit MeshRenderer(const LabelledMesh& mesh, const RenderConfig& config = RenderConfig());
  /// The same, taking the mesh over instead of copying it (a whole map's mesh is hundreds of MB).
  explicit MeshRenderer(LabelledMesh&& mesh, const RenderConfig& config = RenderConfig());
  /// The same, sharing the mesh (never changed through it).
  explicit MeshRenderer(std::shared_ptr<const LabelledMesh> mesh,
                        const RenderConfig& config = RenderConfig());

  /// Renders the view of a camera at T_W_C (camera to world, optical frame).
  RenderedView render(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C) const;

  /// Renders into an existing view (reuses its buffers: no allocation after the first frame).
  void render(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
              RenderedView* view) const;

  /// What render() shades, without the shading: the index of the face each pixel sees (-1 =
  /// none) and |cos| of its incidence angle (0 where no face). For pictures of one view in
  /// several colourings, rasterised once.
  void renderFaces(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                   Image<int32_t>* face, Image<float>* cos_incidence) const;

  /// The mesh being rendered.
  const LabelledMesh& mesh() const { return *mesh_; }

 private:
  struct Scratch;
  /// Consecutive faces [first_face, end_face) and the vertex indices they use.
  struct FaceRun {
    Eigen::AlignedBox3f box_W;
    int32_t first_face = 0, end_face = 0;
    int32_t first_vertex = 0, end_vertex = 0;
  };
  /// Runs that can draw a pixel: bounds not wholly behind the near plane, beyond the far plane
  /// or beside the image.
  std::vector<const FaceRun*> visibleRuns(const PinholeCamera& camera,
                                          const Eigen::Isometry3f& T_C_W) const;
  /// Draws face f (vertices in scratch->points_C), clipped at the near plane.
  void drawFace(const PinholeCamera& camera, int32_t f, float near, float far,
                Scratch* scratch) const;
  void rasterise(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                 Scratch* scratch) const;
  /// Clears the scratch's buffers for `camera`, rasterises, and returns the scratch.
  Scratch& rasteriseView(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C) const;
  /// |cos| of the angle between face f and the unit ray ray_W (inline: once per shaded pixel).
  float cosIncidence(int32_t f, const Eigen::Vector3f& ray_W) const {
    return std::abs((face_normals_W_.empty() ? faceNormal(f) : face_normals_W_[f]).dot(ray_W));
  }

  /// Face f's unit normal in the world frame.
  Eigen::Vector3f faceNormal(int32_t f) const;

  std::shared_ptr<const LabelledMesh> mesh_;
  RenderConfig config_;
  // Per face, with keep_face_data (else empty; labels and colours also when the mesh has none).
  std::vector<Eigen::Vector3f> face_normals_W_;
  std::vector<int32_t> face_instance_;
  std::vector<int32_t> face_semantic_;
  std::vector<Rgb8> face_color_;
  std::vector<FaceRun> runs_;
};

}  // namespace panmap
