#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "panmap/graph/optimiser.h"
#include "panmap/mapper/frame_sync.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mapper/objects.h"

namespace panmap {

/// What to write besides the meshes and the map.
struct OutputOptions {
  bool snapshots = true;  ///< overview PNGs of the meshes (semantic, instance, super-point, colour)
  int64_t utime = 0;      ///< time of the map state (newest frame), written into objects.json
  /// The session's last export: the block meshes kept for live mesh updates are dropped and
  /// the mesh is made from scratch block by block (Mapper::extractFinalMesh), so neither
  /// they nor a copy of the mesh in pieces are held beside the welded mesh.
  bool final_export = false;
  /// The session's frame matching, written into config.yaml with the map's settings.
  SyncConfig sync;
};

/// What writeOutputs wrote.
struct OutputSummary {
  size_t mesh_vertices = 0;
  size_t mesh_faces = 0;
  double mesh_area_m2 = 0.0;     ///< LabelledMesh::surfaceArea()
  size_t instances_in_mesh = 0;  ///< distinct instance ids > 0 on mesh vertices
  size_t objects = 0;            ///< entries of objects.json
  /// objects.json's objects: a live mapper publishes them once more after its final export.
  std::vector<MappedObject> object_list;
  /// Instances left out of objects.json because no vertex of mesh_instance.ply carries them
  /// (a thin piece whose surface the mesh labels by its neighbour's voxels).
  size_t objects_off_mesh = 0;
  std::vector<std::string> files;  ///< file names written, in order
  /// Wall time of each step ("map.panmap", "mesh extraction", "meshes", "snapshots",
  /// "objects.json", "occupancy.bt", "trajectory.txt", "config.yaml"), seconds, in order.
  std::vector<std::pair<std::string, double>> step_seconds;
  /// Outputs that could not be written, one reason each (file and cause); the others were.
  std::vector<std::string> failed;
};

/// Writes a map's outputs (DESIGN 4) into `dir` (created when missing): mesh_semantic.ply,
/// mesh_instance.ply, mesh_superpoint.ply, objects.json, occupancy.bt (when enabled),
/// trajectory.txt (TUM, the poses as integrated), map.panmap, config.yaml (the exact parameters)
/// and the snapshot PNGs (removed when none are made: no faces, or options.snapshots off).
/// map.panmap is written first; when it cannot be, Error names it and nothing else is written.
/// A later output that cannot be written is recorded in OutputSummary::failed and the others
/// are written (requireAllWritten() turns that into an Error), so a caller can still report.
/// @param labels optimised labels, or null for the frame-count labels
/// @param optimiser the optimiser settings recorded in config.yaml
OutputSummary writeOutputs(const std::string& dir, Mapper* mapper, const GraphLabels* labels,
                           const OptimiserConfig& optimiser, const OutputOptions& options = {});

/// Throws Error naming the first output of `summary` that could not be written (and how many
/// more), saying that map.panmap in `dir` and the others were; returns when all were written.
void requireAllWritten(const OutputSummary& summary, const std::string& dir);

}  // namespace panmap
