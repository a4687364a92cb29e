#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// One object placed in a procedural room.
struct RoomObject {
  int32_t instance = 0;     ///< instance id in the mesh (> 0); stuff (wall, floor, ceiling) too
  int32_t semantic = 0;     ///< NYU40 id
  std::string name;         ///< e.g. "chair", "wall"
  Eigen::AlignedBox3f box;  ///< axis-aligned bounds, world frame, metres
  /// Bounds of the boxes and vertical cylinders the object is built from, world frame, metres
  /// (finer than `box` for free-space queries: a chair is legs, seat and back). Empty for stuff.
  std::vector<Eigen::AlignedBox3f> parts;
};

/// What a procedural room is furnished with.
enum class RoomStyle {
  /// Furniture of real sizes and the hard cases of the paper, nothing loose: the rooms the
  /// accuracy suite was first measured on (a seed's room never changes).
  kBoxes,
  /// kBoxes' furniture plus what a real ScanNet scan carries: 30-60 instances of 15 or more
  /// classes, small objects on every surface and on the floor, clutter pushed against walls,
  /// furniture and each other, and unannotated (class 0) piles on 5-10 % of the vertices.
  kScanNetLike,
};

/// Parameters of the procedural room generator.
struct RoomConfig {
  float min_width_m = 3.0f;    ///< room side lengths are drawn from [min, max]; >= 2 m
  float max_width_m = 9.0f;    ///< <= 30 m
  float min_ceiling_m = 2.5f;  ///< ceiling height drawn from [min, max]; >= 2.3 m
  float max_ceiling_m = 3.0f;  ///< <= 10 m
  /// Chance of an L-shaped floor plan: a rectangle of sides >= 5 m (when max_width_m allows)
  /// minus a corner, both arms >= 3 m wide.
  float l_shape_probability = 0.4f;
  float max_edge_m = 0.05f;  ///< every triangle edge is at most this long (dense GT vertices)
  int min_classes = 12;      ///< distinct evaluated classes (of the 18) to include, 0..18
  RoomStyle style = RoomStyle::kBoxes;  ///< what the room is furnished with
  /// Throws Error naming the bad field.
  void check() const;
  /// A ScanNet-like room (RoomStyle::kScanNetLike) 4-8 m wide: smaller rooms leave too few
  /// surfaces for the loose objects, larger ones too few instances per square metre.
  static RoomConfig scanNetLike();
};

/// A generated room: the labelled mesh and what is in it.
///
/// Conventions: z up, floor at z = 0, the floor's bounding rectangle is [0, W] x [0, D]. Walls
/// are one instance (id 1, class wall), the floor id 2, the ceiling id 3; objects follow from 4.
/// Every surface faces into the room (counter-clockwise seen from where a camera can be), and
/// faces nobody can see (a cabinet's back against the wall, the floor under a bed, the counter
/// top under the sink) are left out so that every ground-truth vertex is observable.
struct ProceduralRoom {
  LabelledMesh mesh;                           ///< z up, floor at z = 0, metres
  std::vector<RoomObject> objects;             ///< every instance of the mesh, stuff included
  std::vector<Eigen::Vector2f> floor_polygon;  ///< inner outline of the walls (x, y), CCW
  float ceiling_height_m = 0.0f;
  uint64_t seed = 0;
  /// The walkway: x-y rectangles (world, metres) that no object reaches into at any height,
  /// each at least 0.9 m wide; their union is a connected region (a ring around a central
  /// table when there is one), so a camera can walk a loop in it 0.3 m from every surface.
  std::vector<Eigen::AlignedBox2f> clear_floor;
};

/// Generates a furnished room. The same seed and config give the identical mesh (bit for bit
/// on one platform: sizes come from std::mt19937_64's raw output, not from std distributions).
/// Unannotated clutter of a ScanNet-like room has class 0 and an instance of its own (listed in
/// `objects` as "clutter"). Throws Error naming `min_classes` when that many evaluated classes
/// (or, for a ScanNet-like room, its instances and classes) do not fit in the room.
ProceduralRoom generateRoom(uint64_t seed, const RoomConfig& config = RoomConfig());

}  // namespace panmap
