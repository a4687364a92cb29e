#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/graph/graph_accumulator.h"
#include "panmap/graph/optimiser.h"
#include "panmap/graph/superpoint_graph.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {

class Mapper;

/// A voxel is on an object's surface when observed and |sdf| is at most this many voxels. The
/// integrator's distances are projective (depth differences), 1 / cos(viewing angle) times the
/// Euclidean ones: a voxel holding a surface point (Euclidean <= sqrt(3)/2 voxel) reads up to
/// ~2 voxels when seen at 60 degrees. Free space carved after an object left reads the whole
/// truncation distance (4 voxels by default), so its stale votes stay out.
constexpr float kObjectSurfaceBandVoxels = 2.0f;

/// One mapped object instance (DESIGN 4: objects.json and PANMAP_OBJECTS), world frame W
/// (z up). Both boxes enclose the cells of every counted voxel, not only their centres, so they
/// contain the observed surface and exceed it by at most a cell's reach: one voxel per side
/// along world axes, v (|cos yaw| + |sin yaw|) per side along the oriented box's horizontal axes.
struct MappedObject {
  int32_t id = 0;           ///< instance id, as in mesh_instance.ply's `instance` (> 0)
  int32_t class_id = 0;     ///< NYU40 id: the class of most of its voxels (ties: smaller id)
  float confidence = 0.0f;  ///< in [0, 1], see computeObjects()
  int32_t num_voxels = 0;   ///< surface voxels whose super-point belongs to the instance
  Eigen::Vector3d centroid_W = Eigen::Vector3d::Zero();    ///< mean voxel centre, metres
  Eigen::Vector3d aabb_min_W = Eigen::Vector3d::Zero();    ///< axis-aligned box, metres
  Eigen::Vector3d aabb_max_W = Eigen::Vector3d::Zero();    ///< axis-aligned box, metres
  Eigen::Vector3d obb_center_W = Eigen::Vector3d::Zero();  ///< oriented box centre, metres
  /// Oriented box rotation, box frame B to world; a rotation about world z only (yaw).
  Eigen::Quaterniond q_W_B = Eigen::Quaterniond::Identity();
  /// Oriented box side lengths along B's x, y, z, metres; x is the longer horizontal side.
  Eigen::Vector3d obb_extent_m = Eigen::Vector3d::Zero();
  std::vector<int32_t> superpoints;  ///< live super-point ids with counted voxels, ascending
  /// What the confidence was computed from (labels->instance_evidence; zero without labels).
  ObjectEvidence evidence;

  /// Exact equality of every field (round trips through files and messages are exact).
  bool operator==(const MappedObject& o) const {
    return id == o.id && class_id == o.class_id && confidence == o.confidence &&
           num_voxels == o.num_voxels && centroid_W == o.centroid_W && aabb_min_W == o.aabb_min_W &&
           aabb_max_W == o.aabb_max_W && obb_center_W == o.obb_center_W &&
           q_W_B.coeffs() == o.q_W_B.coeffs() && obb_extent_m == o.obb_extent_m &&
           superpoints == o.superpoints && evidence == o.evidence;
  }
};

/// How computeObjects() scores an instance that `labels` give no confidence (frame-count
/// instances: no optimiser answer yet, or none at all): with the evidence the optimiser would
/// read, the graph's class scores P_nu^C of its super-points, and the optimiser's logistic
/// model (objectConfidence), so a confidence means the same whichever labels made the object.
struct ObjectScoring {
  const GraphAccumulator* graph = nullptr;  ///< P_nu^C of each live super-point (not owned)
  OptimiserConfig::Objects model;           ///< the confidence model
};

/// The objects of a map, ascending by id. Every observed voxel within
/// kObjectSurfaceBandVoxels of the surface counts for the instance of its super-point (Eq. 2
/// argmax, merges resolved). Super-point labels follow Mapper::extractMesh: `labels` first,
/// frame counting for super-points it does not name, so ids match mesh_instance.ply.
/// Class: the class of most voxels. Confidence and evidence: labels->instance_confidence and
/// instance_evidence of the id when given; otherwise, with `scoring`, the model's confidence of
/// the instance's evidence: its counted voxels, and the sum over its super-points of P_nu^C of
/// each one's own class (support), as InstanceEvidence counts them; without `scoring`, the
/// voxel-weighted mean over its super-points of n_best / (n + 1), n the frames that assigned the
/// super-point to any instance and n_best those that chose its current one (stable super-points
/// seen often approach 1; one sighting gives 0.5), and no evidence.
/// Oriented box: yaw-only about world z (what ground robots plan with), the yaw of the
/// minimum-area rectangle around the footprint of the voxel centres (rotating calipers over
/// the convex hull). PCA was not used: its axes are undefined for square footprints (most
/// tables and stools), the minimum-area rectangle is exact for boxes of any aspect.
/// @param map the label-TSDF (voxel centres in the world frame)
/// @param tracker the super-points and their frame-count labels
/// @param labels optimised labels, or null for frame-count labels only
/// @param scoring how to score instances `labels` do not, or null (see above)
std::vector<MappedObject> computeObjects(const TsdfMap& map, const SuperpointTracker& tracker,
                                         const GraphLabels* labels,
                                         const ObjectScoring* scoring = nullptr);

/// computeObjects() of a mapper's current state; instances `labels` do not score are scored by
/// `model` with the mapper's graph (ObjectScoring).
std::vector<MappedObject> computeObjects(const Mapper& mapper, const GraphLabels* labels = nullptr,
                                         const OptimiserConfig::Objects& model = {});

/// Leaves out the objects whose id no entry of `mesh_instance` (mesh_instance.ply's per-vertex
/// instance) carries: a thin piece whose surface the mesh labels by its neighbour's voxels
/// would be an object a planner cannot find in the mesh. Returns how many were left out.
size_t keepObjectsOnMesh(const std::vector<int32_t>& mesh_instance,
                         std::vector<MappedObject>* objects);

/// Writes objects.json: {"utime", "objects": [{"id", "class", "class_name", "confidence",
/// "num_voxels", "centroid", "aabb_min", "aabb_max", "obb_center", "obb_orientation_wxyz",
/// "obb_extent", "superpoints"}]} (panmap-eval --confidences reads id and confidence).
/// Replaces the file whole (writeFileAtomically). Throws Error naming the file when it cannot be
/// written.
void writeObjectsJson(const std::string& path, const std::vector<MappedObject>& objects,
                      int64_t utime);

/// Reads a file written by writeObjectsJson() back (exact: doubles are written so that they
/// read back bit-identical). Throws Error naming the file and field on bad input.
std::vector<MappedObject> readObjectsJson(const std::string& path, int64_t* utime = nullptr);

}  // namespace panmap
