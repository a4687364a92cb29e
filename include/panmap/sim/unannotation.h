#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// How much of a labelled mesh to leave without a class, as real annotations do (a typical
/// ScanNet scene leaves clutter, unlabelled furniture parts and scan borders unannotated).
struct UnannotateConfig {
  /// Target share of the mesh's vertices without a class afterwards, vertices already without
  /// one included; 0 strips nothing.
  double fraction = 0.0;
  /// Share of the stripped vertices taken as whole thing instances (an object nobody
  /// annotated); the rest are clutter patches.
  double object_share = 0.5;
  /// Clutter patches: the vertices connected to a random seed vertex within this radius,
  /// drawn uniformly from [min, max] metres, whatever class they had (clutter touches walls,
  /// floors and furniture alike).
  float patch_radius_min_m = 0.15f;
  float patch_radius_max_m = 0.45f;
  /// Throws Error naming the bad field.
  void check() const;
};

/// A mesh with part of its annotation removed, in the two views a simulation needs.
struct UnannotatedMesh {
  /// What the scene holds, for the renderer and the simulated network: stripped objects keep
  /// their class and instance (a network still sees a chair nobody annotated); clutter patches
  /// and connected regions of class-0 vertices become class-0 instances of their own (ids above
  /// the mesh's), which the segmenter paints as unannotated clutter.
  LabelledMesh world;
  /// What evaluation sees: every stripped vertex (and every class-0 vertex) has class 0 and
  /// instance 0.
  LabelledMesh ground_truth;
  std::vector<int32_t> stripped_instances;  ///< whole instances stripped, ascending
  int clutter_patches = 0;                  ///< clutter patches cut
  int clutter_instances = 0;                ///< class-0 instances in `world` (patches included)
  double unannotated_fraction = 0.0;        ///< share of vertices without a class in GT
};

/// Strips annotation from a labelled mesh (semantic and instance per vertex required): whole
/// thing instances (stuff never) in random order until `object_share` of the vertices to strip
/// is reached or no instance fits, then clutter patches until the target fraction is reached.
/// Deterministic for a seed. Throws Error when the mesh lacks labels or the config is invalid.
UnannotatedMesh unannotate(const LabelledMesh& mesh, const UnannotateConfig& config,
                           uint64_t seed);

}  // namespace panmap
