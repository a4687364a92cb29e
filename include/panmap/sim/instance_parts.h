#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// When a part of a thing instance counts as a part of a larger one in the floor plan. An
/// annotation derived as connected components of same-class vertices (the shipped
/// scene0470's) splits an office chair into its seat and back and its star base wherever the
/// thin column between them is missing from the scan: one object of the room becomes two or
/// more ground-truth instances, which a human annotator (and a network trained on ScanNet)
/// would not separate.
struct PartJoinConfig {
  /// Side of the square cells (in x and y; the mesh's z axis points up, as ScanNet's does)
  /// that make an instance's footprint, metres.
  float cell_m = 0.05f;
  /// A smaller instance joins the larger one of its class whose footprint covers this share
  /// of its own footprint cells, or more (the largest share wins).
  double min_share = 0.25;
  /// Throws Error naming the bad field.
  void check() const;
};

/// One instance folded into another by joinStackedParts.
struct PartJoin {
  int32_t part = 0;  ///< instance id that disappeared
  int32_t into = 0;  ///< instance id its vertices carry now (the root of the chain)
  int32_t class_id = 0;
  double share = 0.0;  ///< share of the part's footprint under the instance it joined directly
};

/// Joins the thing instances of a labelled mesh that are parts of one object stacked above
/// each other (same class, overlapping floor footprints): each instance joins the one of its
/// class with the most cells (ties: more vertices, then the lower id) whose footprint covers at
/// least `min_share` of its own, and chains resolve to their root. A small piece between two
/// chairs joins one of them; the chairs join each other only if one covers the other so. Stuff
/// (wall, floor, ceiling) and class-0 vertices are left alone. Meant for derived annotations only:
/// in a human annotation a pile of books is several instances on purpose. Deterministic; returns
/// the joins in ascending part id. Throws Error when the mesh lacks labels, an instance holds
/// two classes, or the config is invalid.
std::vector<PartJoin> joinStackedParts(LabelledMesh* mesh, const PartJoinConfig& config);

}  // namespace panmap
