#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include <absl/container/flat_hash_map.h>
#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/core/thread_pool.h"
#include "panmap/graph/internal/edge_table.h"
#include "panmap/graph/internal/mask_hits.h"
#include "panmap/graph/superpoint_graph.h"
#include "panmap/graph/surface_adjacency.h"
#include "panmap/graph/surface_scan.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/map/voxel_label_sampler.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {

/// Parameters of the per-frame graph update (III-C).
struct GraphConfig {
  /// P_s = 1 / (1 + d / spatial_scale_m), d the distance between the centroids of the two
  /// super-points' voxels seen through the same mask in the frame (the paper: "based on the
  /// inverse distance"; this form is 1 for touching parts and halves at spatial_scale_m).
  double spatial_scale_m = 0.5;
  int sample_stride_px = 2;  ///< pixels between ray samples (1 = every pixel)
  /// Separation evidence (P_sep^C, not in the paper) is kept for pairs of super-points under
  /// two masks of one thing class in a frame whose voxels' centroids are at most this far
  /// apart: farther pairs are never candidates for one instance anyway.
  double separation_radius_m = 1.5;
  /// Keep the graph bounded by the surface instead of by the history of masks (issue 23): an
  /// edge survives only between super-points that own observed surface (SurfaceAdjacency) and
  /// that touch there, or whose evidence is strong (below). Eq. 6 otherwise keeps a pair for
  /// every two super-points ever seen under one wall or floor mask, and most of them are
  /// super-points that lost every voxel to a newer one. Applied to the table every
  /// Mapper::kForgetEveryFrames frames and to every graph() handed to the optimiser.
  bool prune_edges = true;
  /// A pair that does not touch keeps its edge when its strongest P_eps^C or P_sep^C reaches
  /// this share of the smaller super-point's sum_C P_nu^C: the smaller one was seen with the
  /// other under one mask (or as two objects) in at least about this share of its sightings.
  double edge_min_share = 0.1;
  /// Half-width of the surface band, voxels: observed voxels with |sdf| at most this count as
  /// surface (as objects and meshes do: mapper/objects.h kObjectSurfaceBandVoxels).
  float surface_band_voxels = 2.0f;
  /// Eq. 6 and the separation evidence count only voxels reached by pixels at least this many
  /// pixels (Chebyshev) inside their mask's outline; Eq. 5 counts every pixel. A network's
  /// outline errors put a band of each mask on its neighbours: counted as co-observation,
  /// they tie every small piece at an object's rim to the floor or wall around it as strongly
  /// as if one mask had covered both (not in the paper; 0 = every pixel, as the paper).
  int pair_interior_px = 2;
  /// Throws Error naming the bad field.
  void check() const;
};

/// Accumulates the super-point graph frame by frame: vertex scores P_nu^C (Eq. 5), edge
/// confidences P_eps^C (Eq. 6), and their counterpart P_sep^C: the evidence that two
/// super-points seen in one frame under two different masks of one thing class belong to
/// different objects (Eq. 6 with the two masks' smaller confidence). Keyed by live super-points;
/// merges fold scores and edges together, so the cost of an update does not grow with the number of
/// frames seen.
class GraphAccumulator {
 public:
  /// Throws Error when the config is invalid.
  /// @param pool threads for sampling the frame's rays (not owned; null: the caller's thread)
  explicit GraphAccumulator(const GraphConfig& config, ThreadPool* pool = nullptr);

  /// Adds one frame: for each panoptic mask o (confidence P_o from Eq. 1), the voxels its
  /// pixels' rays reach are grouped by super-point (N^S_o, unique voxels), then Eq. 5 and
  /// Eq. 6 are applied. Call after the frame was integrated. Also folds in the tracker's merges
  /// made since the last call.
  void update(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C, const PanopticFrame& panoptic,
              const TsdfMap& map, const SuperpointTracker& tracker, float stuff_confidence = 0.5f);

  /// Splits the evidence of super-points as the tracker split them this frame (call before
  /// update() with FrameAssociation::splits). The new super-point takes its share of the old
  /// one's scores P_nu^C, and the two get P_eps^C = P_s min(share, 1 - share) P_nu^C (Eq. 6
  /// with P_s from the split's distance_m; a split without one is left without): until this
  /// frame every mask that saw the old super-point saw both parts under one mask, and that
  /// history stays evidence for III-D (a fridge the network split in two for a few frames at
  /// the end of a sequence is one object by its earlier frames).
  void applySplits(const std::vector<SuperpointSplit>& splits, const SuperpointTracker& tracker);

  /// Drops the scores and edges of super-points no voxel votes for any more (see
  /// SuperpointTracker::forgetUnvoted; has_votes is indexed by root label).
  void forgetUnvoted(const std::vector<uint8_t>& has_votes, const LabelRegistry& registry);

  /// Drops the edges GraphConfig::prune_edges says the graph does without: an end owns no
  /// surface, or the two neither touch nor have strong evidence (keepEdge). No-op when pruning
  /// is off. Labels are resolved through `registry`.
  /// @return the number of edges dropped
  size_t pruneEdges(const SurfaceAdjacency& surface, const LabelRegistry& registry);

  /// Whether the edge (a, b) of live super-points stays under GraphConfig::prune_edges (true
  /// for every edge when pruning is off); `strongest` is its largest P_eps^C or P_sep^C.
  bool keepEdge(int32_t a, int32_t b, double strongest, const SurfaceAdjacency& surface) const;

  /// The graph of the live super-points: scores and confidences, centroids and voxel counts
  /// from the map, initial labels from the tracker's frame counts. With prune_edges, only the
  /// super-points owning surface and the edges keepEdge() keeps: the rest cannot change an
  /// output (meshes and objects are made of surface voxels) and would only slow the solver.
  SuperpointGraph graph(const TsdfMap& map, const SuperpointTracker& tracker) const;

  /// The map's surface owners, touching pairs, owner totals and voted labels, brought up to
  /// date by reading only the blocks that changed since the last call (SurfaceScan). Kept
  /// here, beside the graph it serves; like update(), call from one thread at a time.
  const SurfaceScan& surfaceScan(const TsdfMap& map, const LabelRegistry& registry) const;

  /// P_nu^C of a super-point (merges resolved by the caller), empty if never seen.
  const std::map<int32_t, double>& scores(int32_t label) const;
  /// P_eps^C of a pair (either order), empty if never co-observed.
  std::map<int32_t, double> confidences(int32_t a, int32_t b) const;
  /// P_sep^C of a pair (either order), empty if never seen apart.
  std::map<int32_t, double> separations(int32_t a, int32_t b) const;
  /// P_apart of a pair (either order): seen under two different masks of any classes.
  double apart(int32_t a, int32_t b) const;
  /// Number of edges.
  size_t numEdges() const { return edges_.size(); }
  /// Estimated heap bytes of the scores (std::map nodes), the edge table, the surface scan's
  /// per-block results and the scratch.
  size_t memoryBytes() const;

  /// Follows SuperpointTracker::renumberSuperpoints(): call first, with the tracker as it is
  /// before it. Folds in the tracker's merges not yet applied, then keys the scores and edges
  /// by the new ids, to[label] for every label the tracker knows (merged away or not; an entry
  /// whose label has none, 0, is dropped: no live super-point); the surface scan reads the
  /// whole map again at its next refresh.
  void renumberSuperpoints(const SuperpointTracker& tracker, const std::vector<int32_t>& to);

  /// Full state for saving and restoring a map.
  struct Snapshot {
    std::map<int32_t, std::map<int32_t, double>> scores;
    EdgeTable::OrderedEdges edges;
    uint64_t merges_applied = 0;
  };
  /// Copies the state out.
  Snapshot snapshot() const { return Snapshot{scores_, edges_.toOrdered(), merges_applied_}; }
  /// Moves the scores and edges of super-points merged since the last call to the survivors
  /// (every update does it first; call it after merges made outside association).
  void applyMerges(const SuperpointTracker& tracker);
  /// Replaces the state.
  void restore(const Snapshot& s) {
    scores_ = s.scores;
    edges_.assign(s.edges);
    merges_applied_ = static_cast<size_t>(s.merges_applied);
  }

 private:
  /// Sum of a super-point's P_nu^C over its classes (0 if never seen).
  double scoreTotal(int32_t label) const;
  /// Per label below `size`: scoreTotal(label), for the many lookups of a whole-table pass.
  std::vector<double> scoreTotals(size_t size) const;
  /// keepEdge() with the ends' score totals from `total(label)`.
  template <typename Total>
  bool keepEdgeWith(int32_t a, int32_t b, double strongest, const SurfaceAdjacency& surface,
                    const Total& total) const;

  mutable SurfaceScan surface_scan_;

  using Hit = internal::MaskHit;

  /// Per-thread scratch of the sampling pass.
  struct ThreadScratch {
    std::vector<Hit> hits;
    std::vector<Hit> sort_scratch;
    std::vector<RowSample> samples;  // one row's
    std::vector<int32_t> masks, labels;
    std::vector<Eigen::Vector3i> voxels;
  };

  /// The voxels one mask reaches of one super-point: N^S_o and their centroid.
  struct Group {
    int32_t label;
    int count;
    int interior;  ///< of count, the voxels reached by a pixel inside the mask's outline
    Eigen::Vector3d sum;
    Eigen::Vector3d centroid;
  };

  GraphConfig config_;
  ThreadPool* pool_ = nullptr;
  std::vector<ThreadScratch> thread_scratch_;  // one per thread
  std::vector<Hit> hits_;                      // scratch
  std::vector<Hit> merged_;                    // scratch
  std::vector<Group> groups_;                  // one mask's, scratch
  /// Groups of every mask of the frame, for the evidence of two segments.
  struct MaskGroups {
    int32_t cls;
    float p_o;
    bool thing;  ///< a thing mask of a class with two or more things in the frame
    std::vector<Group> groups;
  };
  std::vector<MaskGroups> mask_groups_;  // scratch
  Image<uint8_t> interior_;              // per pixel: inside its mask by pair_interior_px, scratch
  absl::flat_hash_map<int32_t, size_t> group_index_;     // label -> groups_ index, scratch
  std::map<int32_t, std::map<int32_t, double>> scores_;  // label -> class -> P_nu
  EdgeTable edges_;  // (a<b) -> class C -> P_eps^C, -C -> P_sep^C, 0 -> P_apart
  size_t merges_applied_ = 0;
};

}  // namespace panmap
