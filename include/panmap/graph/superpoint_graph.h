#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include <Eigen/Core>
#include <boost/container/flat_map.hpp>

namespace panmap {

/// Values per class (NYU40 id), sorted by class. A flat map (one array): a super-point or an edge
/// carries one to a few classes, and std::map's node per class made building and solving a
/// building's graph (300k edges) allocation-bound.
using ClassValues = boost::container::flat_map<int32_t, double>;

/// A vertex of the super-point graph (paper III-C): one live super-point.
struct GraphVertex {
  int32_t id = 0;                                      ///< super-point label L_S (> 0)
  int32_t num_voxels = 0;                              ///< voxels whose argmax label it is
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< world frame, metres
  int32_t instance = 0;  ///< initial instance (frame counting), 0 = none
  int32_t semantic = 0;  ///< initial class (frame counting), 0 = none
  /// Share of the frames that showed it in which no mask of a known class covered it (the
  /// frame counts' class 0): what the network left void.
  double void_share = 0.0;
  ClassValues scores;  ///< P_nu^C(L_S) per class C (Eq. 5); absent = 0
};

/// An edge of the super-point graph: the panoptic-spatial confidence that two super-points
/// belong to the same object of class C.
struct GraphEdge {
  int32_t a = 0;  ///< super-point id, a < b
  int32_t b = 0;
  ClassValues confidences;  ///< P_eps^C(a, b) per class C (Eq. 6); absent = 0
  /// P_sep^C(a, b) per thing class C: the same sum over frames that showed a and b under two
  /// different masks of class C (evidence of two objects; not in the paper); absent = 0.
  ClassValues separations;
  /// P_apart(a, b): the same sum (without P_s) over frames that showed a and b under two
  /// different masks of any classes, for pairs co-observed under one mask (not in the paper).
  double apart = 0.0;
};

/// The super-point graph handed to the final optimisation.
struct SuperpointGraph {
  std::vector<int32_t> classes;     ///< the label space the optimiser may assign (NYU40 ids)
  std::vector<int32_t> background;  ///< classes counted as background C_0 (stuff)
  /// Edge of the map's voxels, metres: num_voxels * voxel_size_m^2 is about a surface area.
  double voxel_size_m = 0.0;
  std::vector<GraphVertex> vertices;  ///< sorted by id
  std::vector<GraphEdge> edges;       ///< sorted by (a, b)
};

/// What the graph says about one reported object (InstanceEvidence, in physical units).
struct ObjectEvidence {
  float area_m2 = 0.0f;      ///< surface it covers: voxels * voxel_size_m^2
  float support = 0.0f;      ///< score-weighted observations as its class per voxel
  float class_share = 0.0f;  ///< share of its observations that said its class
  bool operator==(const ObjectEvidence& o) const {
    return area_m2 == o.area_m2 && support == o.support && class_share == o.class_share;
  }
};

/// What the optimisation decided.
struct GraphLabels {
  std::map<int32_t, int32_t> semantic;  ///< super-point id -> class
  std::map<int32_t, int32_t> instance;  ///< super-point id -> instance (0 = none)
  /// instance id -> confidence in [0, 1] that it is a real object (OptimiserConfig::Objects)
  std::map<int32_t, float> instance_confidence;
  std::map<int32_t, ObjectEvidence> instance_evidence;  ///< instance id -> its evidence
  int fragments_folded = 0;       ///< fragment instances folded into a neighbouring instance
  int fragments_dropped = 0;      ///< fragment instances left out (their super-points: instance 0)
  int consensus_groups = 0;       ///< groups of several classes given one (class consensus)
  int consensus_superpoints = 0;  ///< super-points whose class the consensus changed
  double solve_ms = 0.0;
};

}  // namespace panmap
