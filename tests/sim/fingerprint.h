#pragma once

// Fingerprints (core/fingerprint.h) of generated data: a test pins the value measured before a
// change to show that the change left the output bit for bit as it was.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "panmap/core/fingerprint.h"
#include "panmap/core/labelled_mesh.h"
#include "panmap/core/pose.h"

namespace panmap {
namespace test {

/// Vertices, faces, classes, instances and colours of a mesh, in that order.
inline uint64_t fingerprint(const LabelledMesh& mesh) {
  Fingerprint f;
  for (const Eigen::Vector3f& v : mesh.vertices) f.add(v.data(), 3 * sizeof(float));
  for (const Eigen::Vector3i& t : mesh.faces) f.add(t.data(), 3 * sizeof(int));
  f.add(mesh.semantic.data(), mesh.semantic.size() * sizeof(int32_t));
  f.add(mesh.instance.data(), mesh.instance.size() * sizeof(int32_t));
  for (const Rgb8& c : mesh.colors) {
    f.add(&c.r, 1);
    f.add(&c.g, 1);
    f.add(&c.b, 1);
  }
  return f.value();
}

/// Time stamps and pose matrices of a trajectory.
inline uint64_t fingerprint(const std::vector<StampedPose>& trajectory) {
  Fingerprint f;
  for (const StampedPose& p : trajectory) {
    f.add(&p.utime, sizeof(p.utime));
    f.add(p.T_W_C.matrix().data(), 16 * sizeof(double));
  }
  return f.value();
}

}  // namespace test
}  // namespace panmap
