#pragma once

// Geometric checks of procedural rooms shared by the room tests.

#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/classes.h"
#include "panmap/core/labelled_mesh.h"
#include "panmap/sim/procedural_room.h"

namespace panmap {
namespace test {

/// Unit normal of a face (counter-clockwise vertices).
inline Eigen::Vector3f faceNormal(const LabelledMesh& mesh, const Eigen::Vector3i& f) {
  const Eigen::Vector3f& a = mesh.vertices[f[0]];
  return (mesh.vertices[f[1]] - a).cross(mesh.vertices[f[2]] - a).normalized();
}

/// Centroid of a face.
inline Eigen::Vector3f centroid(const LabelledMesh& mesh, const Eigen::Vector3i& f) {
  return (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / 3.0f;
}

/// Even-odd rule; points on the outline count as inside.
inline bool insidePolygon(const std::vector<Eigen::Vector2f>& poly, const Eigen::Vector2f& p,
                          float tol = 1e-4f) {
  bool inside = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2f a = poly[j], b = poly[i];
    const Eigen::Vector2f ab = b - a;
    const float t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0f, 1.0f);
    if ((a + t * ab - p).norm() <= tol) return true;
    if ((b.y() > p.y()) != (a.y() > p.y()) &&
        p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside;
}

/// Distance from a point to the polygon's outline.
inline float distanceToOutline(const std::vector<Eigen::Vector2f>& poly, const Eigen::Vector2f& p) {
  float best = 1e9f;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2f a = poly[j], ab = poly[i] - poly[j];
    const float t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0f, 1.0f);
    best = std::min(best, (a + t * ab - p).norm());
  }
  return best;
}

/// Distance from an x-y rectangle to the polygon's outline (0 when it touches it).
inline float rectToOutline(const std::vector<Eigen::Vector2f>& poly, const Eigen::AlignedBox2f& r) {
  float best = 1e9f;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    Eigen::AlignedBox2f wall(poly[j]);
    wall.extend(poly[i]);
    best =
        std::min(best, (r.min() - wall.max()).cwiseMax(wall.min() - r.max()).cwiseMax(0.0f).norm());
  }
  return best;
}

/// Twice-signed area over two: positive for counter-clockwise polygons.
inline float signedArea(const std::vector<Eigen::Vector2f>& poly) {
  float area = 0.0f;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    area += poly[j].x() * poly[i].y() - poly[i].x() * poly[j].y();
  }
  return 0.5f * area;
}

/// Bounding rectangle of a polygon.
inline Eigen::AlignedBox2f bounds2(const std::vector<Eigen::Vector2f>& poly) {
  Eigen::AlignedBox2f b;
  for (const Eigen::Vector2f& p : poly) b.extend(p);
  return b;
}

/// Distance between two boxes (0 when they touch or overlap).
inline float boxGap(const Eigen::AlignedBox3f& a, const Eigen::AlignedBox3f& b) {
  const Eigen::Vector3f gap = (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(0.0f);
  return gap.norm();
}

/// Volume two boxes share.
inline float overlapVolume(const Eigen::AlignedBox3f& a, const Eigen::AlignedBox3f& b) {
  const Eigen::AlignedBox3f i = a.intersection(b);
  return i.isEmpty() ? 0.0f : i.volume();
}

/// The evaluated classes among a room's objects.
inline std::set<int32_t> evaluatedIn(const ProceduralRoom& r) {
  std::set<int32_t> out;
  const std::vector<int32_t>& eval = evaluatedClasses();
  for (const RoomObject& o : r.objects) {
    if (std::find(eval.begin(), eval.end(), o.semantic) != eval.end()) out.insert(o.semantic);
  }
  return out;
}

/// Two things of one class whose boxes are within 1 cm.
inline bool hasTouchingSameClassPair(const ProceduralRoom& r) {
  for (size_t i = 0; i < r.objects.size(); ++i) {
    for (size_t j = i + 1; j < r.objects.size(); ++j) {
      const RoomObject &a = r.objects[i], &b = r.objects[j];
      if (isStuffClass(a.semantic) || a.semantic != b.semantic) continue;
      if (boxGap(a.box, b.box) <= 0.01f) return true;
    }
  }
  return false;
}

/// A chair whose box overlaps a table's in x-y, with every chair vertex above the table's
/// footprint below the table top: the chair is tucked in under it.
inline bool hasChairUnderTable(const ProceduralRoom& r) {
  constexpr int32_t kChair = 5, kTable = 7;
  for (const RoomObject& table : r.objects) {
    if (table.semantic != kTable) continue;
    const Eigen::AlignedBox2f top(table.box.min().head<2>(), table.box.max().head<2>());
    for (const RoomObject& chair : r.objects) {
      if (chair.semantic != kChair) continue;
      const Eigen::AlignedBox2f seat(chair.box.min().head<2>(), chair.box.max().head<2>());
      if (top.intersection(seat).isEmpty() || top.intersection(seat).volume() < 0.01f) continue;
      int under = 0;
      bool clear = true;
      for (size_t v = 0; v < r.mesh.numVertices(); ++v) {
        if (r.mesh.instance[v] != chair.instance) continue;
        const Eigen::Vector3f& p = r.mesh.vertices[v];
        if (p.x() <= top.min().x() || p.x() >= top.max().x() || p.y() <= top.min().y() ||
            p.y() >= top.max().y()) {
          continue;
        }
        ++under;
        clear = clear && p.z() < table.box.max().z() - 0.02f;
      }
      if (under >= 10 && clear) return true;
    }
  }
  return false;
}

/// A picture on a wall: a thin slab within 3 cm of the outline, above the floor.
inline bool hasPictureOnWall(const ProceduralRoom& r) {
  for (const RoomObject& o : r.objects) {
    if (o.semantic != 11 || o.box.min().z() < 0.5f) continue;
    const Eigen::Vector2f c = o.box.center().head<2>();
    if (distanceToOutline(r.floor_polygon, c) < 0.03f &&
        o.box.sizes().head<2>().minCoeff() <= 0.03f) {
      return true;
    }
  }
  return false;
}

}  // namespace test
}  // namespace panmap
