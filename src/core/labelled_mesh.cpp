#include "panmap/core/labelled_mesh.h"

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

}  // namespace panmap
