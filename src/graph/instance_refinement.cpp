// III-D instance refinement over the super-point graph, per semantic class C.
//
// Reading of the paper's rules (all confidences are P_eps^C of the class C being refined; an
// edge with P_eps^C = 0 is no link):
//  - Instances O are the initial instances (vertex.instance) of the super-points labelled C;
//    a super-point of a thing class with instance 0 starts as an instance of its own.
//  - Eq. 10: P_O(O) = max P_eps^C over the edges between members of O (0 without such edges).
//  - Weak links: a member whose strongest link to the rest of O is below theta_D * P_O(O) is
//    re-examined. We apply this to connected groups, not only single super-points: O is split
//    into the connected components of its strong links (P_eps^C >= theta_D * P_O(O)). A member
//    without a strong link is a component of one, which is exactly the paper's single
//    super-point test; larger components catch an instance made of two strongly linked parts
//    joined only by weak edges. The component with the most voxels (then the most
//    super-points, then the smallest id) keeps O; the others are the units re-examined.
//    Instances of a single super-point are re-examined too (they have no link inside).
//  - Re-examination of a unit U (a super-point or a split-off component): for every
//    neighbouring instance O_neigh of class C, P_U(O_neigh) = max P_eps^C over the edges from
//    U to members of O_neigh; the best O_neigh (largest link, then the smaller id) is joined if
//    P_U(O_neigh) > theta_O * P_O(O_neigh) and P_U(O_neigh) > theta_L * P_L(U), where P_L(U)
//    is the strongest link of U of any kind: max P_eps^C over all edges leaving U, whatever
//    the neighbour's class or instance. Otherwise U keeps its own (new) instance. A unit never
//    rejoins an instance it was split from (else the split and the join could alternate).
//  - Passes (split, then re-examine the units in order of their smallest super-point id,
//    updating membership and P_O as units join) repeat until a pass leaves the partition
//    unchanged, at most max_refine_iterations times.
//  - Output ids: an initial instance id is kept by the final instance holding it (when regroup-
//    ing or relabelling left the id in several instances, by the one with the most voxels,
//    then the most super-points, then the smaller class); every other instance gets a new id
//    above the largest initial id, in order of (class, smallest super-point id). Stuff classes
//    (graph.background) get instance 0.
//  - instance_confidence: P_O of each final instance divided by the largest P_O of all
//    instances (all 0 when no instance has an inner link), so the best-supported instance has
//    1 and an instance of a single super-point has 0.
#include "panmap/graph/internal/instance_refinement.h"

#include <algorithm>
#include <tuple>

#include "panmap/graph/internal/graph_check.h"

namespace panmap {
namespace internal {
namespace {

/// A neighbour and the confidence P_eps^C of the edge for the owner's class C (> 0).
struct Link {
  int vertex;
  double confidence;
};

/// A final instance: class, working id, members (vertex indices, ascending).
struct Cluster {
  int32_t class_id;
  int32_t id;
  std::vector<int> members;
};

/// The refinement of one graph: per-vertex links with the confidence of the vertex's class,
/// working instance ids, and the passes over each thing class.
class Refiner {
 public:
  Refiner(const SuperpointGraph& graph, const std::vector<int32_t>& classes)
      : graph_(graph), classes_(classes), n_(static_cast<int>(graph.vertices.size())) {
    // Per-vertex links with the confidence of the vertex's own class.
    std::vector<int> degree(n_ + 1, 0);
    std::vector<std::tuple<int, int, double>> directed;
    const VertexIndex index(graph);
    for (const GraphEdge& e : graph.edges) {
      const int a = index(e.a);
      const int b = index(e.b);
      const auto confidence = [&](int32_t c) {
        const auto it = e.confidences.find(c);
        return it == e.confidences.end() ? 0.0 : it->second;
      };
      const double ca = confidence(classes[a]);
      const double cb = confidence(classes[b]);
      if (ca > 0.0) directed.emplace_back(a, b, ca);
      if (cb > 0.0) directed.emplace_back(b, a, cb);
    }
    for (const auto& [from, to, c] : directed) ++degree[from + 1];
    for (int i = 0; i < n_; ++i) degree[i + 1] += degree[i];
    offset_ = degree;
    links_.resize(directed.size());
    std::vector<int> fill(degree.begin(), degree.end() - 1);
    for (const auto& [from, to, c] : directed) links_[fill[from]++] = {to, c};
    mark_.assign(n_, 0);
  }

  /// Eq. 10, instance confidence: P_O(O) = max P_eps^C(L_S1, L_S2) over the edges between
  /// members of O (class C, working id `id`, in `instance`); 0 without such an edge.
  double instanceConfidence(const std::vector<int>& members, int32_t class_id, int32_t id,
                            const std::vector<int32_t>& instance) const {
    double best = 0.0;
    for (int v : members) {
      for (int e = offset_[v]; e < offset_[v + 1]; ++e) {
        const int q = links_[e].vertex;
        if (classes_[q] == class_id && instance[q] == id) {
          best = std::max(best, links_[e].confidence);
        }
      }
    }
    return best;
  }

  /// Refines all thing classes; returns the output instances and confidences.
  InstanceLabels run(const OptimiserConfig& config) {
    const ClassSet background = backgroundSet();
    max_initial_ = 0;
    for (const GraphVertex& v : graph_.vertices) max_initial_ = std::max(max_initial_, v.instance);
    next_id_ = max_initial_ + 1;
    instance_.assign(n_, 0);
    banned_.assign(n_, {});
    std::map<int32_t, std::vector<int>> by_class;
    for (int i = 0; i < n_; ++i) {
      if (background.contains(classes_[i])) continue;
      const int32_t initial = graph_.vertices[i].instance;
      instance_[i] = initial > 0 ? initial : next_id_++;
      by_class[classes_[i]].push_back(i);
    }
    std::vector<Cluster> clusters;
    for (const auto& [class_id, verts] : by_class) {
      std::map<int32_t, std::vector<int>> members;
      for (int v : verts) members[instance_[v]].push_back(v);
      const OptimiserConfig::Thresholds& th = config.thresholds(class_id);
      for (int pass = 0; pass < config.max_refine_iterations; ++pass) {
        if (!refinePass(class_id, th, verts, members)) break;
      }
      for (auto& [id, m] : members) clusters.push_back({class_id, id, m});
    }
    return output(clusters);
  }

  /// Initial instances (no refinement): vertex.instance for things, 0 for stuff.
  InstanceLabels initial() {
    const ClassSet background = backgroundSet();
    instance_.assign(n_, 0);
    std::map<std::pair<int32_t, int32_t>, std::vector<int>> groups;
    for (int i = 0; i < n_; ++i) {
      if (background.contains(classes_[i]) || graph_.vertices[i].instance <= 0) continue;
      instance_[i] = graph_.vertices[i].instance;
      groups[{classes_[i], instance_[i]}].push_back(i);
    }
    std::map<int32_t, double> confidence;
    double max_confidence = 0.0;
    for (const auto& [key, members] : groups) {
      const double p = instanceConfidence(members, key.first, key.second, instance_);
      confidence[key.second] = std::max(confidence[key.second], p);
      max_confidence = std::max(max_confidence, p);
    }
    InstanceLabels out;
    out.instance = instance_;
    for (const auto& [id, p] : confidence) out.confidence[id] = normalise(p, max_confidence);
    return out;
  }

 private:
  ClassSet backgroundSet() const { return noInstanceClasses(graph_); }

  static float normalise(double p, double max_p) {
    return max_p > 0.0 ? static_cast<float>(p / max_p) : 0.0f;
  }

  /// Connected components of the members of instance `id` over links >= threshold, each
  /// ascending, in order of their smallest member.
  std::vector<std::vector<int>> strongComponents(const std::vector<int>& members, int32_t class_id,
                                                 int32_t id, double threshold) {
    std::vector<std::vector<int>> components;
    for (int start : members) {
      if (mark_[start]) continue;
      std::vector<int> component{start};
      mark_[start] = 1;
      for (size_t k = 0; k < component.size(); ++k) {
        const int v = component[k];
        for (int e = offset_[v]; e < offset_[v + 1]; ++e) {
          const int q = links_[e].vertex;
          if (mark_[q] || classes_[q] != class_id || instance_[q] != id) continue;
          if (links_[e].confidence < threshold) continue;
          mark_[q] = 1;
          component.push_back(q);
        }
      }
      std::sort(component.begin(), component.end());
      components.push_back(std::move(component));
    }
    for (int v : members) mark_[v] = 0;
    return components;
  }

  int64_t voxels(const std::vector<int>& members) const {
    int64_t sum = 0;
    for (int v : members) sum += graph_.vertices[v].num_voxels;
    return sum;
  }

  /// One pass for class C: split every instance into its strong components, then re-examine
  /// the units. Returns true when the partition changed.
  bool refinePass(int32_t class_id, const OptimiserConfig::Thresholds& th,
                  const std::vector<int>& verts, std::map<int32_t, std::vector<int>>& members) {
    const std::vector<int> before = canonical(verts, members);

    // Split.
    std::vector<std::vector<int>> units;
    std::vector<int32_t> ids;
    for (const auto& entry : members) ids.push_back(entry.first);
    for (int32_t id : ids) {
      const std::vector<int> current = members[id];
      if (current.size() == 1) {
        units.push_back(current);
        continue;
      }
      const double p_o = instanceConfidence(current, class_id, id, instance_);
      std::vector<std::vector<int>> components =
          strongComponents(current, class_id, id, th.theta_D * p_o);
      if (components.size() == 1) continue;
      size_t main = 0;
      for (size_t c = 1; c < components.size(); ++c) {
        const auto key = [&](size_t i) {
          return std::make_pair(voxels(components[i]), components[i].size());
        };
        if (key(c) > key(main)) main = c;
      }
      for (size_t c = 0; c < components.size(); ++c) {
        if (c == main) continue;
        const int32_t new_id = next_id_++;
        for (int v : components[c]) {
          instance_[v] = new_id;
          banned_[v].push_back(id);
        }
        members[new_id] = components[c];
        units.push_back(components[c]);
      }
      members[id] = components[main];
    }

    // Re-examine.
    std::sort(units.begin(), units.end(),
              [](const std::vector<int>& a, const std::vector<int>& b) { return a[0] < b[0]; });
    std::map<int32_t, double> p_o;
    for (const auto& [id, m] : members) p_o[id] = instanceConfidence(m, class_id, id, instance_);
    for (const std::vector<int>& unit : units) {
      const int32_t own = instance_[unit[0]];
      if (members[own].size() != unit.size()) continue;  // others joined it: no longer a unit
      double p_l = 0.0;
      std::map<int32_t, double> link;
      for (int v : unit) {
        for (int e = offset_[v]; e < offset_[v + 1]; ++e) {
          const int q = links_[e].vertex;
          const bool same_class = classes_[q] == class_id;
          if (same_class && instance_[q] == own) continue;
          p_l = std::max(p_l, links_[e].confidence);
          if (same_class) link[instance_[q]] = std::max(link[instance_[q]], links_[e].confidence);
        }
      }
      int32_t best = 0;
      double best_link = 0.0;
      for (const auto& [id, value] : link) {
        if (value > best_link && !bannedFor(unit, id)) {
          best = id;
          best_link = value;
        }
      }
      if (best_link <= 0.0 || best_link <= th.theta_O * p_o[best] ||
          best_link <= th.theta_L * p_l) {
        continue;
      }
      std::vector<int>& target = members[best];
      for (int v : unit) instance_[v] = best;
      target.insert(target.end(), unit.begin(), unit.end());
      std::sort(target.begin(), target.end());
      p_o[best] = std::max({p_o[best], p_o[own], best_link});
      members.erase(own);
      p_o.erase(own);
    }
    return canonical(verts, members) != before;
  }

  bool bannedFor(const std::vector<int>& unit, int32_t id) const {
    for (int v : unit) {
      if (std::find(banned_[v].begin(), banned_[v].end(), id) != banned_[v].end()) return true;
    }
    return false;
  }

  /// The partition as the smallest member of each vertex's instance.
  std::vector<int> canonical(const std::vector<int>& verts,
                             const std::map<int32_t, std::vector<int>>& members) const {
    std::vector<int> out;
    out.reserve(verts.size());
    for (int v : verts) out.push_back(members.at(instance_[v]).front());
    return out;
  }

  /// Output ids (initial ids kept where possible) and normalised confidences.
  InstanceLabels output(std::vector<Cluster>& clusters) {
    std::vector<double> p_o(clusters.size());
    double max_p = 0.0;
    for (size_t c = 0; c < clusters.size(); ++c) {
      p_o[c] =
          instanceConfidence(clusters[c].members, clusters[c].class_id, clusters[c].id, instance_);
      max_p = std::max(max_p, p_o[c]);
    }
    // Which cluster keeps each initial id.
    std::map<int32_t, size_t> keeper;
    const auto rank = [&](size_t c) {
      return std::make_tuple(voxels(clusters[c].members), clusters[c].members.size(),
                             -static_cast<int64_t>(clusters[c].class_id));
    };
    for (size_t c = 0; c < clusters.size(); ++c) {
      const int32_t id = clusters[c].id;
      if (id > max_initial_) continue;
      const auto it = keeper.find(id);
      if (it == keeper.end() || rank(c) > rank(it->second)) keeper[id] = c;
    }
    std::vector<int32_t> out_id(clusters.size(), 0);
    std::vector<size_t> fresh;
    for (size_t c = 0; c < clusters.size(); ++c) {
      const auto it = keeper.find(clusters[c].id);
      if (it != keeper.end() && it->second == c) {
        out_id[c] = clusters[c].id;
      } else {
        fresh.push_back(c);
      }
    }
    std::sort(fresh.begin(), fresh.end(), [&](size_t a, size_t b) {
      return std::make_pair(clusters[a].class_id, clusters[a].members.front()) <
             std::make_pair(clusters[b].class_id, clusters[b].members.front());
    });
    int32_t next = max_initial_ + 1;
    for (size_t c : fresh) out_id[c] = next++;

    InstanceLabels out;
    out.instance.assign(n_, 0);
    for (size_t c = 0; c < clusters.size(); ++c) {
      for (int v : clusters[c].members) out.instance[v] = out_id[c];
      out.confidence[out_id[c]] = normalise(p_o[c], max_p);
    }
    return out;
  }

  const SuperpointGraph& graph_;
  const std::vector<int32_t>& classes_;
  const int n_;
  std::vector<int> offset_;
  std::vector<Link> links_;
  std::vector<char> mark_;
  std::vector<int32_t> instance_;             ///< working instance ids
  std::vector<std::vector<int32_t>> banned_;  ///< instances a vertex was split from
  int32_t max_initial_ = 0;
  int32_t next_id_ = 1;
};

}  // namespace

InstanceLabels refineInstances(const SuperpointGraph& graph, const std::vector<int32_t>& classes,
                               const OptimiserConfig& config) {
  return Refiner(graph, classes).run(config);
}

InstanceLabels initialInstances(const SuperpointGraph& graph, const std::vector<int32_t>& classes) {
  return Refiner(graph, classes).initial();
}

}  // namespace internal
}  // namespace panmap
