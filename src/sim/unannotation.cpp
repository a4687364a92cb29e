#include "panmap/sim/unannotation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/core/random.h"

namespace panmap {

void UnannotateConfig::check() const {
  if (!(fraction >= 0.0 && fraction < 1.0)) throw Error("unannotate: fraction must be in [0, 1)");
  if (!(object_share >= 0.0 && object_share <= 1.0)) {
    throw Error("unannotate: object_share must be in [0, 1]");
  }
  if (!(patch_radius_min_m > 0.0f && patch_radius_max_m >= patch_radius_min_m &&
        std::isfinite(patch_radius_max_m))) {
    throw Error("unannotate: need 0 < patch_radius_min_m <= patch_radius_max_m");
  }
}

namespace {

// Vertex adjacency of a triangle mesh, compressed rows.
struct Adjacency {
  std::vector<int> offset;
  std::vector<int> next;
  explicit Adjacency(const LabelledMesh& mesh) : offset(mesh.numVertices() + 1, 0) {
    for (const Eigen::Vector3i& f : mesh.faces) {
      for (int k = 0; k < 3; ++k) offset[f[k] + 1] += 2;
    }
    for (size_t v = 0; v < mesh.numVertices(); ++v) offset[v + 1] += offset[v];
    next.resize(offset.back());
    std::vector<int> fill(offset.begin(), offset.end() - 1);
    for (const Eigen::Vector3i& f : mesh.faces) {
      for (int k = 0; k < 3; ++k) {
        next[fill[f[k]]++] = f[(k + 1) % 3];
        next[fill[f[k]]++] = f[(k + 2) % 3];
      }
    }
  }
};

}  // namespace

UnannotatedMesh unannotate(const LabelledMesh& mesh, const UnannotateConfig& config,
                           uint64_t seed) {
  config.check();
  const size_t n = mesh.numVertices();
  if (mesh.semantic.size() != n || mesh.instance.size() != n) {
    throw Error("unannotate: the mesh needs semantic and instance labels per vertex");
  }
  const std::string problem = mesh.check();
  if (!problem.empty()) throw Error("unannotate: " + problem);
  UnannotatedMesh out;
  out.world = mesh;
  out.ground_truth = mesh;
  std::vector<int32_t>& world_sem = out.world.semantic;
  std::vector<int32_t>& world_inst = out.world.instance;
  std::vector<int32_t>& gt_sem = out.ground_truth.semantic;
  std::vector<int32_t>& gt_inst = out.ground_truth.instance;
  const Adjacency adjacency(mesh);
  int32_t next_id = 1;
  for (int32_t id : mesh.instance) next_id = std::max(next_id, id + 1);

  // Class-0 vertices without an instance: each connected region is one clutter instance.
  for (size_t start = 0; start < n; ++start) {
    if (world_sem[start] > 0 || world_inst[start] > 0) continue;
    std::vector<int> stack{static_cast<int>(start)};
    world_inst[start] = next_id;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (int e = adjacency.offset[v]; e < adjacency.offset[v + 1]; ++e) {
        const int q = adjacency.next[e];
        if (world_sem[q] > 0 || world_inst[q] > 0) continue;
        world_inst[q] = next_id;
        stack.push_back(q);
      }
    }
    ++next_id;
  }
  int64_t unannotated = 0;
  for (size_t v = 0; v < n; ++v) {
    if (gt_sem[v] <= 0) gt_sem[v] = 0, gt_inst[v] = 0, ++unannotated;
  }
  const int64_t target = static_cast<int64_t>(std::llround(config.fraction * n)) - unannotated;

  Rng rng(hashSeed(seed, 0x0A77u));
  if (target > 0) {
    // Whole thing instances, in random order, while they fit the objects' share.
    std::map<int32_t, int64_t> size;
    for (size_t v = 0; v < n; ++v) {
      if (gt_sem[v] > 0 && !isStuffClass(gt_sem[v]) && gt_inst[v] > 0) ++size[gt_inst[v]];
    }
    std::vector<int32_t> order;
    for (const auto& [id, count] : size) order.push_back(id);
    for (size_t k = order.size(); k > 1; --k) std::swap(order[k - 1], order[rng.below(k)]);
    const int64_t object_budget = static_cast<int64_t>(config.object_share * target);
    int64_t taken = 0;
    for (int32_t id : order) {
      if (taken + size[id] > object_budget) continue;
      taken += size[id];
      out.stripped_instances.push_back(id);
    }
    std::sort(out.stripped_instances.begin(), out.stripped_instances.end());
    for (size_t v = 0; v < n; ++v) {
      if (gt_inst[v] > 0 && std::binary_search(out.stripped_instances.begin(),
                                               out.stripped_instances.end(), gt_inst[v]) &&
          gt_sem[v] > 0 && !isStuffClass(gt_sem[v])) {
        gt_sem[v] = 0, gt_inst[v] = 0, ++unannotated;
      }
    }

    // Clutter patches until the target is met.
    const int64_t goal = static_cast<int64_t>(std::llround(config.fraction * n));
    std::vector<int> annotated;
    std::vector<uint8_t> seen(n, 0);
    for (int attempts = 0; unannotated < goal && attempts < 100000; ++attempts) {
      annotated.clear();
      for (size_t v = 0; v < n; ++v) {
        if (gt_sem[v] > 0) annotated.push_back(static_cast<int>(v));
      }
      if (annotated.empty()) break;
      const int centre = annotated[rng.below(annotated.size())];
      const double radius = rng.uniform(config.patch_radius_min_m, config.patch_radius_max_m);
      const Eigen::Vector3f c = mesh.vertices[centre];
      std::vector<int> patch{centre}, stack{centre};
      seen[centre] = 1;
      while (!stack.empty()) {
        const int v = stack.back();
        stack.pop_back();
        for (int e = adjacency.offset[v]; e < adjacency.offset[v + 1]; ++e) {
          const int q = adjacency.next[e];
          if (seen[q] || (mesh.vertices[q] - c).norm() > radius) continue;
          seen[q] = 1;
          patch.push_back(q);
          stack.push_back(q);
        }
      }
      int64_t cut = 0;
      for (int v : patch) {
        seen[v] = 0;
        if (gt_sem[v] <= 0) continue;
        gt_sem[v] = 0, gt_inst[v] = 0;
        world_sem[v] = 0, world_inst[v] = next_id;
        ++cut;
      }
      unannotated += cut;
      ++next_id;
      ++out.clutter_patches;
    }
  }
  std::vector<uint8_t> clutter_id(static_cast<size_t>(next_id), 0);
  for (size_t v = 0; v < n; ++v) {
    if (world_sem[v] <= 0 && world_inst[v] > 0) clutter_id[world_inst[v]] = 1;
  }
  out.clutter_instances = static_cast<int>(std::count(clutter_id.begin(), clutter_id.end(), 1));
  out.unannotated_fraction = n ? static_cast<double>(unannotated) / static_cast<double>(n) : 0.0;
  return out;
}

}  // namespace panmap
