#pragma once

#include <cmath>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/core/labelled_mesh.h"

namespace panmap {
namespace test {

/// Appends a quad a-b-c-d (two triangles) subdivided into n x n cells, with labels.
inline void addQuad(LabelledMesh* mesh, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                    const Eigen::Vector3f& c, const Eigen::Vector3f& d, int32_t instance,
                    int32_t semantic, int n = 1, Rgb8 color = Rgb8{200, 100, 50}) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const float s = static_cast<float>(i) / n, t = static_cast<float>(j) / n;
      mesh->vertices.push_back((1 - s) * (1 - t) * a + s * (1 - t) * b + s * t * c +
                               (1 - s) * t * d);
      mesh->instance.push_back(instance);
      mesh->semantic.push_back(semantic);
      mesh->colors.push_back(color);
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int v00 = base + i * (n + 1) + j;
      mesh->faces.emplace_back(v00, v00 + n + 1, v00 + n + 2);
      mesh->faces.emplace_back(v00, v00 + n + 2, v00 + 1);
    }
  }
}

/// Appends the six faces of an axis-aligned box, each subdivided n x n.
inline void addBox(LabelledMesh* mesh, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                   int32_t instance, int32_t semantic, int n = 1) {
  auto P = [&](int i, int j, int k) {
    return Eigen::Vector3f(i ? hi.x() : lo.x(), j ? hi.y() : lo.y(), k ? hi.z() : lo.z());
  };
  addQuad(mesh, P(0, 0, 0), P(0, 1, 0), P(0, 1, 1), P(0, 0, 1), instance, semantic, n);
  addQuad(mesh, P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1), instance, semantic, n);
  addQuad(mesh, P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1), instance, semantic, n);
  addQuad(mesh, P(0, 1, 0), P(1, 1, 0), P(1, 1, 1), P(0, 1, 1), instance, semantic, n);
  addQuad(mesh, P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), instance, semantic, n);
  addQuad(mesh, P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1), instance, semantic, n);
}

/// Appends a UV sphere (rings x segments), labelled.
inline void addSphere(LabelledMesh* mesh, const Eigen::Vector3f& centre, float radius,
                      int32_t instance, int32_t semantic, int rings = 96, int segments = 192) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (int r = 0; r <= rings; ++r) {
    const float theta = static_cast<float>(M_PI) * r / rings;
    for (int s = 0; s < segments; ++s) {
      const float phi = 2.0f * static_cast<float>(M_PI) * s / segments;
      mesh->vertices.push_back(centre + radius * Eigen::Vector3f(std::sin(theta) * std::cos(phi),
                                                                 std::sin(theta) * std::sin(phi),
                                                                 std::cos(theta)));
      mesh->instance.push_back(instance);
      mesh->semantic.push_back(semantic);
      mesh->colors.push_back(Rgb8{90, 160, 220});
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = base + r * segments + s, b = base + r * segments + (s + 1) % segments;
      const int c = a + segments, d = b + segments;
      mesh->faces.emplace_back(a, c, d);
      mesh->faces.emplace_back(a, d, b);
    }
  }
}

/// Camera at `eye` looking at `target` (optical frame; world z up).
inline Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  x.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

/// A 640x480 Kinect-like camera.
inline PinholeCamera kinectCamera() { return PinholeCamera{525.0, 525.0, 319.5, 239.5, 640, 480}; }

}  // namespace test
}  // namespace panmap
