#include "panmap/core/labelled_mesh.h"

#include <Eigen/Geometry>

namespace panmap {

std::string LabelledMesh::check() const {
  const size_t n = vertices.size();
  if (!colors.empty() && colors.size() != n) return "colors has a different length than vertices";
  if (!semantic.empty() && semantic.size() != n)
    return "semantic has a different length than vertices";
  if (!instance.empty() && instance.size() != n)
    return "instance has a different length than vertices";
  if (!superpoint.empty() && superpoint.size() != n) {
    return "superpoint has a different length than vertices";
  }
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (faces[f][k] < 0 || static_cast<size_t>(faces[f][k]) >= n) {
        return "face " + std::to_string(f) + " refers to vertex " + std::to_string(faces[f][k]) +
               " of " + std::to_string(n);
      }
    }
  }
  return "";
}

double LabelledMesh::surfaceArea() const {
  double area = 0.0;
  for (const Eigen::Vector3i& f : faces) {
    const Eigen::Vector3d a = vertices[static_cast<size_t>(f[0])].cast<double>();
    const Eigen::Vector3d b = vertices[static_cast<size_t>(f[1])].cast<double>();
    const Eigen::Vector3d c = vertices[static_cast<size_t>(f[2])].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

}  // namespace panmap
