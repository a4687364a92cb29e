#include "panmap/mesh/mesh_welder.h"

#include "panmap/mesh/internal/vertex_labeller.h"

namespace panmap {

namespace {

constexpr int kGrid = kBlockSide + 1;

// Every cache line of a vector's elements.
template <typename T>
void prefetchAll(const std::vector<T>& v) {
  const char* p = reinterpret_cast<const char*>(v.data());
  const size_t bytes = v.size() * sizeof(T);
  for (size_t offset = 0; offset < bytes; offset += 64) __builtin_prefetch(p + offset);
}

}  // namespace

void MeshWelder::prefetch(const BlockMesh& mesh) const {
  prefetchAll(mesh.vertices);
  prefetchAll(mesh.colors);
  prefetchAll(mesh.edges);
  prefetchAll(mesh.sources);
  prefetchAll(mesh.faces);
}

MeshWelder::MeshWelder(const TsdfMap& map, const MeshLabeller& labeller, LabelledMesh* out)
    : out_(out),
      label_vertex_(labeller.superpoint ? std::make_unique<internal::VertexLabeller>(map, labeller)
                                        : nullptr) {}

MeshWelder::~MeshWelder() = default;

int32_t MeshWelder::emit(const BlockMesh& mesh, size_t i) {
  const int32_t index = static_cast<int32_t>(out_->vertices.size());
  out_->vertices.push_back(mesh.vertices[i]);
  out_->colors.push_back(mesh.colors[i]);
  if (label_vertex_) {
    const internal::VertexLabels labels = (*label_vertex_)(mesh.sources[i]);
    out_->superpoint.push_back(labels.superpoint);
    out_->semantic.push_back(labels.semantic);
    out_->instance.push_back(labels.instance);
  }
  return index;
}

void MeshWelder::add(const BlockMesh& mesh) {
  if (mesh.vertices.empty()) return;
  if (label_vertex_) {
    label_vertex_->setBlock(mesh.index);
    // A vertex's labels wait on two loads the marching cubes never made (its voxel's vote
    // slot, then its vote set): started for the whole block first, they overlap.
    for (uint16_t source : mesh.sources) label_vertex_->prefetchSlot(source);
    for (uint16_t source : mesh.sources) label_vertex_->prefetchVotes(source);
  }
  const uint64_t own_key = TsdfMap::key(mesh.index);
  local_.resize(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const uint16_t edge = mesh.edges[i];
    const int cell = edge / 3;
    const int x = cell % kGrid, y = (cell / kGrid) % kGrid, z = cell / (kGrid * kGrid);
    const bool on_lower_face = x == 0 || y == 0 || z == 0;
    const bool on_upper_face = x == kBlockSide || y == kBlockSide || z == kBlockSide;
    if (!on_lower_face && !on_upper_face) {
      local_[i] = emit(mesh, i);  // inside the block: no other block has this edge
    } else if (!on_upper_face) {
      // The block's own edge on a lower face: a lower neighbour (added before) may have made
      // it, and no block after this one can, so it leaves the seam.
      const auto it = seam_.find(EdgeKey(own_key, edge));
      if (it == seam_.end()) {
        local_[i] = emit(mesh, i);
      } else {
        local_[i] = it->second;
        seam_.erase(it);
      }
    } else {
      // An upper neighbour's edge: shared with that neighbour and the other blocks below it,
      // all of which come later or made it already.
      const BlockIndex owner = mesh.index + BlockIndex(x >> 3, y >> 3, z >> 3);
      const EdgeKey key(TsdfMap::key(owner), blockEdgeId(x & 7, y & 7, z & 7, edge % 3));
      const auto [it, inserted] = seam_.try_emplace(key, -1);
      if (inserted) it->second = emit(mesh, i);
      local_[i] = it->second;
    }
  }
  for (const Eigen::Vector3i& f : mesh.faces) {
    out_->faces.emplace_back(local_[f[0]], local_[f[1]], local_[f[2]]);
  }
}

}  // namespace panmap
