#pragma once

#include <cstdint>
#include <map>

#include "panmap/graph/superpoint_graph.h"

namespace panmap {

/// Parameters of the final optimisation (paper III-C energy, III-D refinement).
struct OptimiserConfig {
  bool regularise = true;  ///< III-C semantic regularisation (off: argmax of the scores)
  bool refine = true;      ///< III-D instance refinement (off: initial instances)
  /// III-C, after the swap: super-points the network showed as one object take one class,
  /// the one with the most evidence over them (internal/class_consensus.h; not in the paper).
  bool class_consensus = true;
  /// Class consensus: a super-point takes its group's class only if its own score for that
  /// class is at least this share of its score for its own (its views left it in doubt).
  double consensus_min_ratio = 0.5;
  double K_C = 60.0;   ///< pairwise weight per voxel (Eq. 9, weighting; docs/TUNING.md)
  double theta = 0.5;  ///< pairwise bandwidth (Eq. 9)
  /// Discount Eq. 9's co-observation sum_C P_eps^C by P_eps / (P_eps + P_apart): how often the
  /// two super-points were under one mask rather than two (not in the paper).
  bool discount_apart = true;
  int max_sweeps = 10;  ///< alpha-beta swap sweeps over all class pairs at most
  /// How much each term of Eq. 7 counts. kSurface (not in the paper): a vertex's unary counts
  /// once per voxel it holds, an edge's pairwise once per voxel of the smaller of its two
  /// vertices, so E sums over surface as a voxel CRF would. kNone: once per vertex and edge
  /// (the paper); then a super-point of one voxel outweighs a whole chair part, and a chair
  /// bordered by dozens of one-voxel floor fragments is relabelled floor (docs/MAPPING.md).
  /// kShared: unaries as kSurface; each vertex shares its voxels over its edges in proportion
  /// to their normalised confidence, and an edge weighs the smaller of its two shares, so the
  /// pairwise terms around a vertex never outweigh its own surface however many small
  /// neighbours it has (opt-in: not yet through the tuning suite).
  enum class Weighting : int8_t { kNone = 0, kSurface = 1, kShared = 2 };
  Weighting weighting = Weighting::kSurface;
  /// What Eq. 9's co-observation sum_C P_eps^C is divided by to make it scale-free. kSmaller:
  /// the smaller of the two vertices' score sums, so a fragment observed once under a chair's
  /// mask is as strongly linked to the chair as a part seen under it in every frame. kGeometric:
  /// their geometric mean (the cosine of the two super-points' observations), so a link is
  /// strong only when the co-observation is a large share of both vertices' observations
  /// (docs/MAPPING.md: two chairs, 41 small super-points, turned floor through 920 links to
  /// barely observed fragments around them).
  enum class LinkScale : int8_t { kSmaller = 0, kGeometric = 1 };
  LinkScale link_scale = LinkScale::kSmaller;
  /// How much a link is trusted, by how often its less observed end was seen: the normalised
  /// co-observation is multiplied by n / (n + link_half_observations), n the smaller of the
  /// two vertices' score sums per voxel (confidence-weighted observations per voxel). A
  /// fragment seen once or twice then pulls on its neighbours weakly, a surface seen in many
  /// frames as before. 0: every link fully trusted (docs/MAPPING.md).
  double link_half_observations = 1.0;
  /// A super-point that no mask of a known class covered in more than this share of the
  /// frames that showed it (GraphVertex::void_share) is left unlabelled: class 0, no instance,
  /// outside III-C's labelling. Its class scores are then the bleed of its neighbours' mask
  /// outlines, and labelling it by them grows those objects by surface the network never
  /// called theirs (docs/MAPPING.md). 1: off. 0.8 was chosen by
  /// scripts/bench/tune_refinement.py (docs/TUNING.md; 0.6-0.8 tied).
  double max_void_share = 0.8;
  /// Floor of the normalised score P_nu^C / sum_C' P_nu^C' in the unary (Eq. 8): a class
  /// without score costs -log(score_floor) (13.8 for 1e-6) instead of infinity.
  double score_floor = 1e-6;
  /// Instance refinement passes (split + re-examination) per class at most; it stops
  /// earlier when a pass leaves the partition unchanged.
  int max_refine_iterations = 10;
  /// Per-class refinement thresholds theta_D, theta_O, theta_L (III-D); classes not listed
  /// use the defaults below. Each is a fraction in [0, 1]. The defaults were chosen by
  /// scripts/bench/tune_refinement.py on rooms kept out of docs/RESULTS.md (docs/TUNING.md):
  /// weak-link splits (theta_D > 0) only lost accuracy there, so they are off by default.
  struct Thresholds {
    double theta_D = 0.0;   ///< weak link: below theta_D * P_O(own instance)
    double theta_O = 0.05;  ///< join: link above theta_O * P_O(neighbour instance)
    double theta_L = 0.3;   ///< join: link above theta_L * P_L (strongest link of the unit)
  };
  Thresholds default_thresholds;
  std::map<int32_t, Thresholds> class_thresholds;
  /// How III-D refines instances: clustering by the network's one-mask / two-mask verdicts
  /// (internal/instance_clustering.h), or the paper's rules with the thresholds above.
  enum class Refinement : int8_t { kClustering = 0, kPaperRules = 1 };
  Refinement refinement = Refinement::kClustering;
  /// Clustering: clusters join when P_eps / (P_eps + P_sep) between them reaches this
  /// (chosen with min_coverage and K_C by scripts/bench/tune_refinement.py, docs/TUNING.md).
  double join_affinity = 0.6;
  /// Clustering: and P_eps between them reaches this share of the smaller one's P_nu.
  double min_coverage = 0.05;
  /// What is reported as an object (after III-D): fragments are folded into the instance of
  /// their class they are most strongly linked to, or left out and counted; every object gets
  /// a calibrated confidence.
  struct Objects {
    bool consolidate = true;  ///< false: every instance is an object (no folding)
    /// Instances covering less surface than this (num_voxels * voxel_size_m^2) are fragments.
    double min_area_m2 = 0.04;
    /// Confidence = 1 / (1 + exp(-(bias + area * log10(area_m2) + support * log2(support) +
    /// share * class_share))), InstanceEvidence's support and class share; a logistic model
    /// fitted by scripts/bench/calibrate_confidence.py on the tuning scenes
    /// (docs/CALIBRATION.md) so that about a share c of the objects reported with confidence
    /// c match a real object. The class share did not help on scene kinds left out of the
    /// fit: held at 0.
    double bias = 0.2772;
    double area = 2.5930;
    double support = 0.9467;
    double share = 0.0;
  };
  Objects objects;
  /// Throws Error naming the bad field.
  void check() const;
  /// The thresholds of a class (class_thresholds entry, else default_thresholds).
  const Thresholds& thresholds(int32_t class_id) const;
};

/// Runs the final optimisation: alpha-beta swap over the semantic energy, then per-class
/// instance refinement. Deterministic. Used by panmap-optimizer and in-process.
/// Throws Error naming the field when the config or the graph is invalid (vertices not
/// sorted by id, edges not sorted by (a, b) with a < b or naming unknown vertices, negative
/// or non-finite scores/confidences, no classes for a non-empty graph).
GraphLabels optimise(const SuperpointGraph& graph, const OptimiserConfig& config);

/// E(C) of Eq. 7 for a labelling (super-point id -> class), for tests and reports.
/// Throws Error when a vertex has no label or the graph/config is invalid.
double semanticEnergy(const SuperpointGraph& graph, const std::map<int32_t, int32_t>& labels,
                      const OptimiserConfig& config);

}  // namespace panmap
