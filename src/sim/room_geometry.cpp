#include "panmap/sim/internal/room_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace panmap {
namespace internal {
namespace room {
namespace {

// Hidden-face test: a surface sample pushed this far along its normal that lands inside a
// solid (or outside the room) cannot be seen.
constexpr float kPushM = 0.002f;
constexpr double kPi = 3.14159265358979323846;

bool solidContains(const Solid& s, const Vector3f& p, float tol) {
  if (p.z() < s.box.min().z() - tol || p.z() > s.box.max().z() + tol) return false;
  if (!s.cylinder) {
    return p.x() >= s.box.min().x() - tol && p.x() <= s.box.max().x() + tol &&
           p.y() >= s.box.min().y() - tol && p.y() <= s.box.max().y() + tol;
  }
  const Vector2f c = s.box.center().head<2>();
  return (p.head<2>() - c).squaredNorm() <= s.inner_radius_m * s.inner_radius_m;
}

}  // namespace

MeshWriter::MeshWriter(const RoomShape& shape, float ceiling_m, float max_edge_m,
                       std::vector<Solid> solids, LabelledMesh* mesh)
    : shape_(shape),
      ceiling_m_(ceiling_m),
      cell_m_(max_edge_m / std::sqrt(2.0f)),
      solids_(std::move(solids)),
      mesh_(mesh) {
  for (Solid& s : solids_) {
    const float r = 0.5f * s.box.sizes().x();
    s.inner_radius_m = r * static_cast<float>(std::cos(kPi / segmentsFor(r)));
  }
}

// Sample 0 first: most cells are visible at their centre and stop there.
template <typename Sample>
bool MeshWriter::hidden(Sample sample, int count, const std::vector<int>& near) const {
  for (int k = 0; k < count; ++k) {
    if (!blocked(sample(k), near)) return false;
  }
  return true;
}

void MeshWriter::addRect(const Vector3f& p00, const Vector3f& p10, const Vector3f& p01, int self) {
  const Vector3f u = p10 - p00, v = p01 - p00;
  if (u.squaredNorm() == 0.0f || v.squaredNorm() == 0.0f) return;
  const Vector3f n = u.cross(v).normalized();
  const int nu = cells(u.norm()), nv = cells(v.norm());
  Box3 region(p00);
  region.extend(p10);
  region.extend(p01);
  region.extend(p10 + v);
  const std::vector<int> near = nearbySolids(region, self);
  std::vector<int32_t> index(static_cast<size_t>(nu + 1) * (nv + 1), -1);
  auto lerp = [](float a, float b, int i, int count) {
    return i == count ? b : a + (b - a) * (static_cast<float>(i) / static_cast<float>(count));
  };
  auto vertex = [&](int i, int j) {
    int32_t& id = index[static_cast<size_t>(j) * (nu + 1) + i];
    if (id < 0) {
      Vector3f p;
      for (int k = 0; k < 3; ++k) {
        p[k] = p10[k] != p00[k]   ? lerp(p00[k], p10[k], i, nu)
               : p01[k] != p00[k] ? lerp(p00[k], p01[k], j, nv)
                                  : p00[k];
      }
      id = addVertex(p);
    }
    return id;
  };
  // A cell is hidden when the blocked region of the plane just in front of it covers it.
  // That region is a union of axis-aligned rectangles (solids' sections, the outside of a
  // rectilinear room), so testing the centre of every piece the rectangles' edges cut the
  // cell into is exact: a 1 cm gap between two doors keeps the cells behind it.
  int ua = 0, va = 0, na = 0;
  u.cwiseAbs().maxCoeff(&ua);
  v.cwiseAbs().maxCoeff(&va);
  n.cwiseAbs().maxCoeff(&na);
  const float plane = p00[na] + (n[na] > 0.0f ? kPushM : -kPushM);
  const std::vector<float> cuts_u = cuts(ua, near), cuts_v = cuts(va, near);
  auto covered = [&](float u0, float u1, float v0, float v1) {
    std::vector<float> su = between(cuts_u, u0, u1), sv = between(cuts_v, v0, v1);
    for (size_t a = 0; a + 1 < su.size(); ++a) {
      for (size_t b = 0; b + 1 < sv.size(); ++b) {
        Vector3f p;
        p[ua] = 0.5f * (su[a] + su[a + 1]);
        p[va] = 0.5f * (sv[b] + sv[b + 1]);
        p[na] = plane;
        const int by = blocker(p, near);
        if (by == kFree) return false;
        if (by == kOutside || !solids_[by].cylinder) continue;
        // A disc's section is not cut into rectangles: all four corners must be on it.
        for (int corner = 0; corner < 4; ++corner) {
          Vector3f q = p;
          q[ua] = su[a + (corner & 1)];
          q[va] = sv[b + (corner >> 1)];
          if (!solidContains(solids_[by], q, kTolM)) return false;
        }
      }
    }
    return true;
  };
  for (int j = 0; j < nv; ++j) {
    const float va0 = lerp(p00[va], p01[va], j, nv), va1 = lerp(p00[va], p01[va], j + 1, nv);
    for (int i = 0; i < nu; ++i) {
      const float ua0 = lerp(p00[ua], p10[ua], i, nu), ua1 = lerp(p00[ua], p10[ua], i + 1, nu);
      Vector3f centre;
      centre[ua] = 0.5f * (ua0 + ua1);
      centre[va] = 0.5f * (va0 + va1);
      centre[na] = plane;
      if (blocked(centre, near) &&
          covered(std::min(ua0, ua1), std::max(ua0, ua1), std::min(va0, va1), std::max(va0, va1))) {
        continue;
      }
      const int32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1),
                    d = vertex(i, j + 1);
      mesh_->faces.emplace_back(a, b, c);
      mesh_->faces.emplace_back(a, c, d);
    }
  }
}

void MeshWriter::addBox(const Box3& b, int self) {
  const float x0 = b.min().x(), y0 = b.min().y(), z0 = b.min().z();
  const float x1 = b.max().x(), y1 = b.max().y(), z1 = b.max().z();
  addRect({x1, y0, z0}, {x1, y1, z0}, {x1, y0, z1}, self);  // +x
  addRect({x0, y0, z0}, {x0, y0, z1}, {x0, y1, z0}, self);  // -x
  addRect({x0, y1, z0}, {x0, y1, z1}, {x1, y1, z0}, self);  // +y
  addRect({x0, y0, z0}, {x1, y0, z0}, {x0, y0, z1}, self);  // -y
  addRect({x0, y0, z1}, {x1, y0, z1}, {x0, y1, z1}, self);  // +z
  addRect({x0, y0, z0}, {x0, y1, z0}, {x1, y0, z0}, self);  // -z
}

void MeshWriter::addCylinder(const Box3& b, int self) {
  const Vector2f c = b.center().head<2>();
  const float r = 0.5f * b.sizes().x();
  const float z0 = b.min().z(), z1 = b.max().z();
  const int segments = segmentsFor(r);
  const int nz = cells(z1 - z0);
  const int rings = cells(r);
  const std::vector<int> near = nearbySolids(b, self);
  auto rim = [&](float s, float radius, float z) {
    const double theta = 2.0 * kPi * static_cast<double>(s) / segments;
    return Vector3f(c.x() + radius * static_cast<float>(std::cos(theta)),
                    c.y() + radius * static_cast<float>(std::sin(theta)), z);
  };
  // Side: cells of (segment, height), wrapping around.
  std::vector<int32_t> side(static_cast<size_t>(segments) * (nz + 1), -1);
  auto sideVertex = [&](int s, int j) {
    int32_t& id = side[static_cast<size_t>(j) * segments + (s % segments)];
    if (id < 0) id = addVertex(rim(static_cast<float>(s % segments), r, zAt(z0, z1, j, nz)));
    return id;
  };
  for (int j = 0; j < nz; ++j) {
    for (int s = 0; s < segments; ++s) {
      auto sample = [&](int k) {
        static constexpr float kAt[3] = {0.5f, 0.0f, 1.0f};
        const float zs = z0 + (z1 - z0) * (static_cast<float>(j) + kAt[k / 3]) / nz;
        return rim(static_cast<float>(s) + kAt[k % 3], r + kPushM, zs);
      };
      if (hidden(sample, 9, near)) continue;
      const int32_t a = sideVertex(s, j), bb = sideVertex(s + 1, j), cc = sideVertex(s + 1, j + 1),
                    d = sideVertex(s, j + 1);
      mesh_->faces.emplace_back(a, bb, cc);
      mesh_->faces.emplace_back(a, cc, d);
    }
  }
  addDisc(c, r, z1, true, segments, rings, near);
  addDisc(c, r, z0, false, segments, rings, near);
}

std::vector<float> MeshWriter::cuts(int axis, const std::vector<int>& near) const {
  std::vector<float> out;
  for (int s : near) {
    out.push_back(solids_[s].box.min()[axis] - kTolM);
    out.push_back(solids_[s].box.max()[axis] + kTolM);
  }
  if (axis == 2) {
    out.push_back(0.0f);
    out.push_back(ceiling_m_);
  } else {
    for (const Vector2f& p : shape_.polygon) out.push_back(p[axis]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<float> MeshWriter::between(const std::vector<float>& cuts, float lo, float hi) {
  std::vector<float> out = {lo};
  for (auto it = std::upper_bound(cuts.begin(), cuts.end(), lo); it != cuts.end() && *it < hi;
       ++it) {
    out.push_back(*it);
  }
  out.push_back(hi);
  return out;
}

float MeshWriter::zAt(float z0, float z1, int j, int n) {
  return j == n ? z1 : z0 + (z1 - z0) * static_cast<float>(j) / static_cast<float>(n);
}

int MeshWriter::segmentsFor(float radius) const {
  return std::max(8,
                  static_cast<int>(std::ceil(2.0f * static_cast<float>(kPi) * radius / cell_m_)));
}

int MeshWriter::cells(float length) const {
  return std::max(1, static_cast<int>(std::ceil(length / cell_m_)));
}

void MeshWriter::addDisc(const Vector2f& c, float r, float z, bool up, int segments, int rings,
                         const std::vector<int>& near) {
  const float push = up ? kPushM : -kPushM;
  auto point = [&](int ring, int s) {
    const double theta = 2.0 * kPi * static_cast<double>(s % segments) / segments;
    // The rim is exactly the side's top or bottom ring: no slit between disc and side.
    const float radius =
        ring == rings ? r : r * static_cast<float>(ring) / static_cast<float>(rings);
    return Vector3f(c.x() + radius * static_cast<float>(std::cos(theta)),
                    c.y() + radius * static_cast<float>(std::sin(theta)), z);
  };
  int32_t centre = -1;
  std::vector<int32_t> index(static_cast<size_t>(rings) * segments, -1);
  auto vertex = [&](int ring, int s) {
    if (ring == 0) {
      if (centre < 0) centre = addVertex(Vector3f(c.x(), c.y(), z));
      return centre;
    }
    int32_t& id = index[static_cast<size_t>(ring - 1) * segments + (s % segments)];
    if (id < 0) id = addVertex(point(ring, s));
    return id;
  };
  const Vector3f lift(0.0f, 0.0f, push);
  for (int ring = 1; ring <= rings; ++ring) {
    for (int s = 0; s < segments; ++s) {
      const std::array<Vector3f, 4> corners = {point(ring - 1, s), point(ring, s),
                                               point(ring, s + 1), point(ring - 1, s + 1)};
      auto sample = [&](int k) {
        if (k == 0)
          return Vector3f(0.25f * (corners[0] + corners[1] + corners[2] + corners[3]) + lift);
        return Vector3f(corners[k - 1] + lift);
      };
      if (hidden(sample, 5, near)) continue;
      const int32_t a = vertex(ring - 1, s), b = vertex(ring, s), cc = vertex(ring, s + 1);
      if (ring == 1) {
        if (up) {
          mesh_->faces.emplace_back(a, b, cc);
        } else {
          mesh_->faces.emplace_back(a, cc, b);
        }
        continue;
      }
      const int32_t d = vertex(ring - 1, s + 1);
      if (up) {
        mesh_->faces.emplace_back(a, b, cc);
        mesh_->faces.emplace_back(a, cc, d);
      } else {
        mesh_->faces.emplace_back(a, cc, b);
        mesh_->faces.emplace_back(a, d, cc);
      }
    }
  }
}

std::vector<int> MeshWriter::nearbySolids(const Box3& region, int self) const {
  const Vector3f pad = Vector3f::Constant(kPushM + 2.0f * kTolM);
  const Box3 grown(region.min() - pad, region.max() + pad);
  std::vector<int> near;
  for (size_t s = 0; s < solids_.size(); ++s) {
    if (static_cast<int>(s) != self && grown.intersects(solids_[s].box)) {
      near.push_back(static_cast<int>(s));
    }
  }
  return near;
}

int MeshWriter::blocker(const Vector3f& p, const std::vector<int>& near) const {
  if (p.z() < -kTolM || p.z() > ceiling_m_ + kTolM) return kOutside;
  if (!shape_.contains(p.head<2>(), kTolM)) return kOutside;
  int found = kFree;
  for (int s : near) {
    if (!solidContains(solids_[s], p, kTolM)) continue;
    if (!solids_[s].cylinder) return s;
    found = s;
  }
  return found;
}

bool MeshWriter::blocked(const Vector3f& p, const std::vector<int>& near) const {
  return blocker(p, near) != kFree;
}

int32_t MeshWriter::addVertex(const Vector3f& p) {
  mesh_->vertices.push_back(p);
  mesh_->colors.push_back(color_);
  mesh_->semantic.push_back(semantic_);
  mesh_->instance.push_back(instance_);
  return static_cast<int32_t>(mesh_->vertices.size() - 1);
}

}  // namespace room
}  // namespace internal
}  // namespace panmap
