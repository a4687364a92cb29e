#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "panmap/core/image.h"

namespace panmap {

/// A triangle mesh whose vertices carry colour and integer labels. Ground-truth meshes
/// (procedural rooms, ScanNet) and panmap's output meshes share this type; ids travel as
/// integers, never as colours.
struct LabelledMesh {
  std::vector<Eigen::Vector3f> vertices;  ///< positions in the world frame, metres
  std::vector<Rgb8> colors;               ///< per vertex, or empty
  std::vector<int32_t> semantic;          ///< per vertex NYU40 id (0 = unlabelled), or empty
  std::vector<int32_t> instance;          ///< per vertex instance id (0 = none), or empty
  std::vector<int32_t> superpoint;        ///< per vertex super-point id (0 = none), or empty
  std::vector<Eigen::Vector3i> faces;     ///< triangles as vertex indices, counter-clockwise
                                          ///< seen from the side the normal points to

  /// Number of vertices.
  size_t numVertices() const { return vertices.size(); }
  /// Number of triangles.
  size_t numFaces() const { return faces.size(); }
  /// Total area of the triangles, square metres. Of two maps of the same frames, the one from
  /// the more consistent poses has less: misaligned frames double surfaces.
  double surfaceArea() const;
  /// "" when every per-vertex array is empty or as long as `vertices` and every face index is
  /// in range; otherwise the first problem found.
  std::string check() const;
};

}  // namespace panmap
