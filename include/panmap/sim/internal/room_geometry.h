#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/labelled_mesh.h"
#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_shape.h"

namespace panmap {
namespace internal {
namespace room {

/// A solid of the room for the hidden-face test: a box or a vertical cylinder inscribed in it.
struct Solid {
  Box3 box;
  bool cylinder = false;
  float inner_radius_m = 0.0f;  ///< of the tessellated cylinder: its sides are chords
};

/// Tessellates rectangles and vertical cylinders into triangles whose edges are at most
/// max_edge_m (square cells of side max_edge / sqrt 2, so the diagonal fits too), leaving out
/// the cells nobody can see: those whose samples, pushed a little along the normal, all land in
/// another solid or outside the room.
class MeshWriter {
 public:
  /// @param solids every solid of every object, in the order addBox/addCylinder get their
  ///     `self` indices.
  /// @param mesh receives the vertices (with the current label) and faces; must outlive this.
  MeshWriter(const RoomShape& shape, float ceiling_m, float max_edge_m, std::vector<Solid> solids,
             LabelledMesh* mesh);

  /// Colour, semantic and instance of the vertices added from now on.
  void setLabel(int32_t instance, int32_t semantic, const Rgb8& color) {
    instance_ = instance;
    semantic_ = semantic;
    color_ = color;
  }

  /// The axis-aligned rectangle with corners p00, p10 = p00 + u and p01 = p00 + v, facing
  /// u x v. `self` is the solid it bounds (-1 for walls, floor and ceiling). Grid vertices
  /// interpolate each coordinate between the exact corner values, so the edge a face shares with
  /// its neighbour has bit-identical vertices and a ray cannot slip between them into the box.
  void addRect(const Vector3f& p00, const Vector3f& p10, const Vector3f& p01, int self);

  /// The six faces of a box, each facing out.
  void addBox(const Box3& b, int self);

  /// A vertical cylinder inscribed in `b`: side, top and bottom discs.
  void addCylinder(const Box3& b, int self);

 private:
  static constexpr int kFree = -1, kOutside = -2;

  /// Sorted coordinates along `axis` where the blocked region can change: the faces of nearby
  /// solids and the walls, floor and ceiling.
  std::vector<float> cuts(int axis, const std::vector<int>& near) const;
  /// lo, the cuts strictly between lo and hi, hi.
  static std::vector<float> between(const std::vector<float>& cuts, float lo, float hi);
  /// Height of ring j of n from z0 to z1, exactly z1 at the top.
  static float zAt(float z0, float z1, int j, int n);
  /// Sides of the polygon that stands for a circle of this radius.
  int segmentsFor(float radius) const;
  /// Cells along a length, at least one.
  int cells(float length) const;
  /// Concentric rings of quads around a fan at the centre; `up` faces +z.
  void addDisc(const Vector2f& c, float r, float z, bool up, int segments, int rings,
               const std::vector<int>& near);
  /// Indices of the solids (but `self`) near a region: the only ones that can hide it.
  std::vector<int> nearbySolids(const Box3& region, int self) const;
  /// What hides p: kOutside (the room's outside), a box's index, else a cylinder's index, else
  /// kFree.
  int blocker(const Vector3f& p, const std::vector<int>& near) const;
  /// True when something hides p.
  bool blocked(const Vector3f& p, const std::vector<int>& near) const;
  /// True when all `count` samples sample(k) are hidden.
  template <typename Sample>
  bool hidden(Sample sample, int count, const std::vector<int>& near) const;
  /// Appends a vertex with the current label; returns its index.
  int32_t addVertex(const Vector3f& p);

  const RoomShape& shape_;
  float ceiling_m_;
  float cell_m_;
  std::vector<Solid> solids_;
  LabelledMesh* mesh_;
  int32_t instance_ = 0;
  int32_t semantic_ = 0;
  Rgb8 color_;
};

}  // namespace room
}  // namespace internal
}  // namespace panmap
