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

namespace {

template <typename T>
void appendAttribute(std::vector<T>* mine, size_t my_count, const std::vector<T>& theirs,
                     size_t their_count) {
  if (mine->empty() && theirs.empty()) return;
  mine->resize(my_count, T());
  if (theirs.empty()) {
    mine->resize(my_count + their_count, T());
  } else {
    mine->insert(mine->end(), theirs.begin(), theirs.end());
  }
}

}  // namespace

void LabelledMesh::append(const LabelledMesh& other) {
  const size_t mine = vertices.size();
  const size_t theirs = other.vertices.size();
  appendAttribute(&colors, mine, other.colors, theirs);
  appendAttribute(&semantic, mine, other.semantic, theirs);
  appendAttribute(&instance, mine, other.instance, theirs);
  appendAttribute(&superpoint, mine, other.superpoint, theirs);
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  const Eigen::Vector3i offset = Eigen::Vector3i::Constant(static_cast<int>(mine));
  for (const Eigen::Vector3i& f : other.faces) faces.push_back(f + offset);
}

}  // namespace panmap
