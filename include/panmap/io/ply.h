#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// PLY encodings panmap writes.
enum class PlyFormat { kBinaryLittleEndian, kAscii };

/// Reads a PLY mesh (ascii, binary_little_endian or binary_big_endian). Vertex properties
/// x y z (float or double) are required; red green blue (uchar, or any integer type holding
/// 0..255; alpha is ignored), semantic, instance and superpoint (any integer type, values
/// must fit int32) are read when present, other properties and elements are skipped. Faces: a list
/// property named vertex_indices or vertex_index; polygons with more than three corners are
/// fan-triangulated. Throws Error naming the file on bad input. A vertex property `label` is
/// ignored: in ScanNet's labels.ply it is a ScanNet label id, not an NYU40 id (see
/// readPlyVertexIntProperty and ScanNetLabelTable).
LabelledMesh readPly(const std::string& path);

/// Reads one integer vertex property (any name but x y z), e.g. `label` of ScanNet's
/// *_vh_clean_2.labels.ply, which readPly ignores. One value per vertex. Throws Error naming
/// the file when the property is missing, not of an integer type, or the file is bad.
std::vector<int32_t> readPlyVertexIntProperty(const std::string& path, const std::string& name);

/// Writes a mesh as PLY with x y z (float), red green blue (uchar) when colours are present,
/// and int properties semantic, instance, superpoint for each label array present, then an
/// element face (possibly empty) with `list uchar int vertex_indices`. Floats in ascii files
/// are written with the fewest digits that read back to the same float, so round trips are
/// exact in both formats. Throws Error naming the file when it cannot be written or the mesh is
/// inconsistent.
void writePly(const std::string& path, const LabelledMesh& mesh,
              PlyFormat format = PlyFormat::kBinaryLittleEndian);

/// A mesh's arrays as writePly(PlyColumns) takes them (not owned), so that several files can
/// share one mesh with other colours or labels without a copy each. A null column is not
/// written; a label column pointing to an empty vector is written as zeros.
struct PlyColumns {
  const std::vector<Eigen::Vector3f>* vertices = nullptr;  ///< required
  const std::vector<Eigen::Vector3i>* faces = nullptr;     ///< null: an empty face element
  const std::vector<Rgb8>* colors = nullptr;
  const std::vector<int32_t>* semantic = nullptr;
  const std::vector<int32_t>* instance = nullptr;
  const std::vector<int32_t>* superpoint = nullptr;
};

/// writePly() of the given columns, in the same layout; streamed in chunks of about 1 MiB,
/// never held whole in memory, to PATH.partial, renamed over PATH when complete (a reader of
/// PATH sees the old mesh or the whole new one). Throws Error naming the file when it cannot be
/// written, a column's length differs from the vertices', or a face index is out of range.
void writePly(const std::string& path, const PlyColumns& columns,
              PlyFormat format = PlyFormat::kBinaryLittleEndian);

}  // namespace panmap
