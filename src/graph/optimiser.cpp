// The final optimisation: III-C semantic regularisation (alpha-beta swap over Eq. 7), then
// III-D instance refinement.
#include "panmap/graph/optimiser.h"

#include <chrono>
#include <cmath>
#include <string>

#include "panmap/core/error.h"
#include "panmap/graph/internal/alpha_beta_swap.h"
#include "panmap/graph/internal/class_consensus.h"
#include "panmap/graph/internal/graph_check.h"
#include "panmap/graph/internal/instance_clustering.h"
#include "panmap/graph/internal/instance_refinement.h"
#include "panmap/graph/internal/object_consolidation.h"
#include "panmap/graph/internal/semantic_energy.h"

namespace panmap {
namespace {

void checkFraction(double value, const std::string& field) {
  if (!(value >= 0.0 && value <= 1.0)) {
    throw Error(field + ": " + std::to_string(value) + " (must be in [0, 1])");
  }
}

void checkThresholds(const OptimiserConfig::Thresholds& t, const std::string& field) {
  checkFraction(t.theta_D, field + ".theta_D");
  checkFraction(t.theta_O, field + ".theta_O");
  checkFraction(t.theta_L, field + ".theta_L");
}

}  // namespace

void OptimiserConfig::check() const {
  if (!(std::isfinite(link_half_observations) && link_half_observations >= 0.0)) {
    throw Error("OptimiserConfig.link_half_observations: " +
                std::to_string(link_half_observations) + " (must be finite, >= 0)");
  }
  if (!(max_void_share >= 0.0 && max_void_share <= 1.0)) {
    throw Error("OptimiserConfig.max_void_share: " + std::to_string(max_void_share) +
                " (must be in [0, 1])");
  }
  if (!(std::isfinite(consensus_min_ratio) && consensus_min_ratio >= 0.0)) {
    throw Error("OptimiserConfig.consensus_min_ratio: " + std::to_string(consensus_min_ratio) +
                " (must be finite, >= 0)");
  }
  if (!(std::isfinite(K_C) && K_C >= 0.0)) {
    throw Error("OptimiserConfig.K_C: " + std::to_string(K_C) + " (must be finite, >= 0)");
  }
  if (!(std::isfinite(theta) && theta > 0.0)) {
    throw Error("OptimiserConfig.theta: " + std::to_string(theta) + " (must be finite, > 0)");
  }
  if (max_sweeps < 1) {
    throw Error("OptimiserConfig.max_sweeps: " + std::to_string(max_sweeps) +
                " (must be >= 1; set regularise = false to skip)");
  }
  if (!(score_floor > 0.0 && score_floor <= 1.0)) {
    throw Error("OptimiserConfig.score_floor: " + std::to_string(score_floor) +
                " (must be in (0, 1])");
  }
  if (max_refine_iterations < 1) {
    throw Error("OptimiserConfig.max_refine_iterations: " + std::to_string(max_refine_iterations) +
                " (must be >= 1; set refine = false to skip)");
  }
  checkThresholds(default_thresholds, "OptimiserConfig.default_thresholds");
  checkFraction(join_affinity, "OptimiserConfig.join_affinity");
  checkFraction(min_coverage, "OptimiserConfig.min_coverage");
  if (!(std::isfinite(objects.min_area_m2) && objects.min_area_m2 >= 0.0)) {
    throw Error("OptimiserConfig.objects.min_area_m2: " + std::to_string(objects.min_area_m2) +
                " (must be finite, >= 0)");
  }
  for (const double w : {objects.bias, objects.area, objects.support, objects.share}) {
    if (!std::isfinite(w))
      throw Error("OptimiserConfig.objects: confidence weights must be finite");
  }
  for (const auto& [c, t] : class_thresholds) {
    checkThresholds(t, "OptimiserConfig.class_thresholds[" + std::to_string(c) + "]");
  }
}

const OptimiserConfig::Thresholds& OptimiserConfig::thresholds(int32_t class_id) const {
  const auto it = class_thresholds.find(class_id);
  return it == class_thresholds.end() ? default_thresholds : it->second;
}

GraphLabels optimise(const SuperpointGraph& graph, const OptimiserConfig& config) {
  const auto start = std::chrono::steady_clock::now();
  config.check();
  internal::checkGraph(graph);
  GraphLabels out;
  if (graph.vertices.empty()) return out;

  // III-C: argmax labelling, then alpha-beta swap.
  const internal::LabelProblem problem = internal::buildLabelProblem(graph, config);
  std::vector<int> labels = problem.initial;
  if (config.regularise) internal::alphaBetaSwap(problem, labels, config.max_sweeps);
  std::vector<int32_t> classes(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    classes[i] =
        internal::leftUnlabelled(graph.vertices[i], config) ? 0 : problem.labels[labels[i]];
  }
  if (config.regularise && config.class_consensus) {
    internal::ClassConsensusStats consensus;
    classes = internal::classConsensus(graph, classes, config, &consensus);
    out.consensus_groups = consensus.groups;
    out.consensus_superpoints = consensus.superpoints;
  }

  // III-D: instances.
  const internal::InstanceLabels instances =
      !config.refine ? internal::initialInstances(graph, classes)
      : config.refinement == OptimiserConfig::Refinement::kClustering
          ? internal::clusterInstances(graph, classes, config)
          : internal::refineInstances(graph, classes, config);
  // Objects: fragments folded or left out, calibrated confidences.
  const internal::ConsolidatedObjects objects =
      internal::consolidateObjects(graph, classes, instances.instance, config.objects);
  for (size_t i = 0; i < graph.vertices.size(); ++i) {  // ids ascending: append at the end
    out.semantic.emplace_hint(out.semantic.end(), graph.vertices[i].id, classes[i]);
    out.instance.emplace_hint(out.instance.end(), graph.vertices[i].id, objects.instance[i]);
  }
  out.instance_confidence = objects.confidence;
  out.instance_evidence = objects.evidence;
  out.fragments_folded = objects.folded;
  out.fragments_dropped = objects.dropped;
  out.solve_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace panmap
