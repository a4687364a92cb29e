#pragma once

#include <cstdint>
#include <string>

#include "panmap/core/image.h"
#include "panmap/core/labelled_mesh.h"
#include "panmap/io/ply.h"

namespace panmap {

/// Colour of an NYU40 class in ScanNet's benchmark palette (0 and ids outside 1..40: black,
/// so unlabelled surfaces stand out).
Rgb8 semanticColor(int32_t class_id);

/// A deterministic colour per id (instances, super-points): a hash of the id, bright enough
/// to tell apart on a dark background; 0 (none) is black.
Rgb8 idColor(int32_t id);

/// File names of the three exports (DESIGN 4).
inline constexpr const char* kSemanticMeshFile = "mesh_semantic.ply";
inline constexpr const char* kInstanceMeshFile = "mesh_instance.ply";
inline constexpr const char* kSuperpointMeshFile = "mesh_superpoint.ply";

/// Writes mesh_semantic.ply, mesh_instance.ply and mesh_superpoint.ply into `dir` (created
/// when missing): the same geometry coloured by semanticColor / idColor, each with the integer
/// vertex properties semantic, instance and superpoint (zeros where the mesh has no such
/// array). Throws Error naming the folder or file that could not be written.
void writeLabelledMeshes(const std::string& dir, const LabelledMesh& mesh,
                         PlyFormat format = PlyFormat::kBinaryLittleEndian);

}  // namespace panmap
