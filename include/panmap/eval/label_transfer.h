#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// Default radius of the label transfer (DESIGN 8): 5 cm.
constexpr double kDefaultTransferDistanceM = 0.05;

/// Predicted labels carried over to the ground-truth vertices, one entry per GT vertex.
struct TransferredLabels {
  std::vector<int32_t> semantic;    ///< predicted NYU40 id, 0 = unlabelled
  std::vector<int32_t> instance;    ///< predicted instance id, 0 = none
  std::vector<int32_t> superpoint;  ///< predicted super-point id, 0 = none
  /// 1 where the GT vertex found a predicted vertex in range (the map observed it). Empty:
  /// every vertex did (labels built by hand).
  std::vector<uint8_t> reached;
  /// Distance from each GT vertex to the nearest predicted vertex, metres, in range or not
  /// (infinity without a predicted vertex). Empty: not known (labels built by hand).
  std::vector<float> distance_m;
  size_t num_transferred = 0;  ///< GT vertices that found a predicted vertex in range
};

/// For each ground-truth vertex, the labels of the nearest predicted vertex (nanoflann k-d
/// tree) if it lies within `max_distance_m` (inclusive: distance <= max_distance_m, computed in
/// double), else semantic 0, instance 0, superpoint 0. Label arrays the prediction lacks read
/// as 0. Throws Error naming the field when the prediction is inconsistent (LabelledMesh::check)
/// or max_distance_m is negative.
/// @param predicted predicted mesh (world frame)
/// @param gt_vertices ground-truth vertex positions (same world frame)
/// @param max_distance_m transfer radius in metres
TransferredLabels transferLabels(const LabelledMesh& predicted,
                                 const std::vector<Eigen::Vector3f>& gt_vertices,
                                 double max_distance_m = kDefaultTransferDistanceM);

}  // namespace panmap
