#pragma once

#include <cstdint>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/map/voxel_label_sampler.h"
#include "panmap/segmentation/panoptic_geometric.h"
#include "panmap/superpoint/label_registry.h"

namespace panmap {

/// Parameters of super-point segmentation (paper III-B) and frame-count instance association.
struct SuperpointConfig {
  /// A surface joins the super-point holding at least this share of its sampled points
  /// (Pi_s(L_S, s_i) / |s_i|); otherwise it starts a new one.
  float association_min_overlap = 0.2f;
  /// Super-points holding at least this share of a surface are its L_N(s_i) (Eq. 3).
  float significant_overlap = 0.2f;
  /// theta_merge: super-points merge once co-observed in more than this many surfaces (with
  /// semantic_consistency: frames, each counting once however many of its surfaces show them).
  int merge_threshold = 3;
  /// Merge only semantically consistent super-points: the same labelled class
  /// (SuperpointState::labelledClass), unlabelled ones only with unlabelled ones. false:
  /// spatial-only merging as in Voxblox++ (ablation "w/o III-B").
  bool semantic_consistency = true;
  /// Only the network's verdicts on their own class decide (with semantic_consistency;
  /// docs/MAPPING.md): a co-observation counts towards a merge only in a surface of the two
  /// super-points' class or without a mask (a floor mask spilling over two cabinets says
  /// nothing about them),
  /// and a surface that loses its super-point to a surface of another mask of its class
  /// splits from it (the super-point was formed under a mask that merged two objects).
  bool mask_verdicts = true;
  /// With semantic_consistency: two super-points merge only when they were co-observed in
  /// more than apart_weight times as many frames as the network showed them as two objects
  /// (two masks of one class). A merge cannot be undone, while III-D can still group pieces
  /// left apart, so a merge needs clearly more evidence than a split: 1.5 is the geometric
  /// mean of the one-to-two odds of a network's errors on two touching objects (merged into
  /// one mask 20 % of the time: 0.25) and on one long object (split 10 %: 9), docs/MAPPING.md.
  float apart_weight = 1.5f;
  /// With semantic_consistency: the void share (SuperpointState::voidShare) above which the
  /// final labelling leaves a super-point unlabelled (OptimiserConfig::max_void_share; the
  /// config file sets both from that key). A merge whose result would be left unlabelled is
  /// refused unless both parts already are: a mostly unmasked super-point that the network
  /// labelled a few times must not bury a labelled piece of an object (issue 19: half of a
  /// chair went unlabelled in a wall-and-clutter super-point). 1 turns the rule off.
  double unlabelled_void_share = 0.8;
  /// Opt-in (docs/MAPPING.md, step 3: on the accuracy suite a box room lost a match at IoU 0.50).
  /// With semantic_consistency: a surface whose super-point another surface of the same mask
  /// took this frame joins it too, when the super-point is of the mask's class. One mask is one
  /// verdict, and a depth edge that cuts it says nothing the super-point does not already hold.
  /// false: a new super-point, as Voxblox++'s one surface per super-point per frame; its one
  /// vote a voxel lost to the next frame's, it lasted a frame and took the surface's frame
  /// counts with it (issue 19: a quarter of a ScanNet-like room's new super-points).
  bool join_mask_pieces = false;
  /// With semantic_consistency: a labelled surface that would start a super-point (none free
  /// among its voxels' leading labels) first takes a free one of its class that any vote slot
  /// of at least association_min_overlap of its samples holds: the one it started on an
  /// earlier visit, not yet its voxels' leader (a picture on a wall, a cabinet front under a
  /// super-point that another surface took). false: every visit starts another, and the
  /// object's frame and apart counts are spread over super-points gone a few frames later.
  bool revisit_votes = false;
  /// Pixels between overlap samples (1 = every pixel).
  int sample_stride_px = 2;
  /// A 2D instance joins the global instance covering at least this share of its pixels.
  float instance_min_overlap = 0.1f;
  /// Throws Error naming the bad field.
  void check() const;
};

/// What the tracker knows about one live super-point.
struct SuperpointState {
  std::map<int32_t, double> class_counts;  ///< frames that saw it as each class (0 = background)
  std::map<int32_t, int> instance_counts;  ///< frames that assigned it to each global instance
  /// C(L_S) from frame counting: the most frequent class (0 = background / none).
  int32_t semanticClass() const;
  /// The most frequent class other than background (0 when no surface of it was labelled):
  /// what the network said the super-point is, whenever it said anything.
  int32_t labelledClass() const;
  /// Share of its frame counts that are class 0 (no mask of a known class); 0 when never seen.
  double voidShare() const;
  /// Its frame counts of class 0 (first) and of every class (second): voidShare's terms.
  std::pair<double, double> voidFrames() const;
  /// Its global instance from frame counting (0 = none).
  int32_t instance() const;
};

/// A surface that split from a super-point: the network showed the super-point's surface as
/// two objects of one class (two masks), and another surface took the super-point, so this
/// one's voxels move to a new one (applySplits()).
struct SuperpointSplit {
  int32_t surface_id = 0;  ///< the surface (pixel value in FrameSegmentation::surfaces)
  int32_t from = 0;        ///< the super-point it split from (a root label at association)
  int32_t to = 0;          ///< its new super-point
  /// The surface's share of the samples of `from` in the frame: how much of it splits off.
  double share = 0.0;
  /// Distance between the centroids of the surface's points and of the points of the surface
  /// that kept `from`, metres (applySplits() fills it in; -1 until then).
  double distance_m = -1.0;
};

/// The result of associating one frame's surfaces with super-points.
struct FrameAssociation {
  LabelImage pixel_labels;                 ///< super-point label per pixel, 0 = none
  std::vector<int32_t> surface_labels;     ///< per surface (index = id - 1)
  std::vector<int32_t> surface_instances;  ///< global instance per surface, 0 = none
  std::vector<SuperpointSplit> splits;     ///< to apply before integrating (applySplits())
  int new_labels = 0;
  int merges = 0;
};

/// A merge of two super-points, for the record (ids stay resolvable through LabelRegistry).
struct SuperpointMerge {
  int32_t kept = 0;
  int32_t removed = 0;
  int64_t frame = 0;
};

/// Semantically consistent super-point segmentation (III-B) with frame-count semantic and
/// instance labelling (as Voxblox++ / Han et al.), the initial labelling the graph refines.
class SuperpointTracker {
 public:
  /// Throws Error when the config is invalid.
  explicit SuperpointTracker(const SuperpointConfig& config);

  /// Associates the surfaces of a frame seen from T_W_C with the map's super-points, creates
  /// new ones, counts co-observations and merges (Eq. 2-3), updates class and instance frame
  /// counts. Call before integrating the frame with the returned pixel labels.
  FrameAssociation associate(const FrameSegmentation& segmentation, const RgbdFrame& frame,
                             const Eigen::Isometry3d& T_W_C, const TsdfMap& map);

  /// Like associate() above, into `out`, whose buffers are reused (a mapper calls this every
  /// frame: no per-frame allocation of the pixel label image).
  void associate(const FrameSegmentation& segmentation, const RgbdFrame& frame,
                 const Eigen::Isometry3d& T_W_C, const TsdfMap& map, FrameAssociation* out);

  /// Forgets super-points that no voxel votes for any more (their votes were all evicted by
  /// stronger labels): their frame counts and co-observations. They can never be associated
  /// again, and on long runs they would outnumber the live ones many times over.
  /// @param has_votes flag per root label (index = label), non-zero when some voxel votes for it
  /// @return the number of super-points forgotten
  size_t forgetUnvoted(const std::vector<uint8_t>& has_votes);

  /// Label registry (creation and merges).
  const LabelRegistry& labels() const { return labels_; }
  /// State of a live super-point (resolves merged labels); null if unknown.
  const SuperpointState* state(int32_t label) const;
  /// All live super-points.
  const std::map<int32_t, SuperpointState>& states() const { return states_; }
  /// Every merge so far, in order.
  const std::vector<SuperpointMerge>& merges() const { return merge_log_; }
  /// Global instances created so far.
  int32_t numInstances() const { return next_instance_ - 1; }
  /// Gives the global instances new ids (a repair keeps the ids the map had before it:
  /// carriedInstanceIds()); ids not in `ids` keep theirs. Instances created afterwards start at
  /// `next_instance`. Throws Error, changing nothing, when two instances would share an id or
  /// an id would not be below `next_instance`.
  void renumberInstances(const std::map<int32_t, int32_t>& ids, int32_t next_instance);
  /// Gives the live super-points new ids (a repair keeps the ids the map had before it:
  /// carriedIds()): root label r becomes ids.at(r), every other label up to `size` is retired
  /// (LabelRegistry::renumber), and super-points created afterwards start at size + 1. States,
  /// co-observations and the apart counts follow; the merges logged so far keep their frame and
  /// name the survivor by its new id and the merged-away label as 0 (it no longer exists).
  /// Throws Error, changing nothing, when a super-point with a state has no new id, two would
  /// share one, or one would fall outside 1..size.
  void renumberSuperpoints(const std::map<int32_t, int32_t>& ids, int32_t size);
  /// Throws Error, as renumberSuperpoints() would, when the ids do not fit: a key that is not a
  /// live label, two keys with one id, an id outside 1..size, a super-point with a state and
  /// no id.
  void checkSuperpointIds(const std::map<int32_t, int32_t>& ids, int32_t size) const;
  /// Joins two super-points whose surfaces a repair laid over one another
  /// (rejoinCoincidingSuperpoints(), mapper/superpoint_rejoin.h) where III-B's merge rule
  /// allows it: semantically consistent, and not shown as two objects by the network in as
  /// many frames as together. Where they coincide, each frame that saw the one seen in fewer
  /// frames saw the other's surface too, so those frames times `share` (the part of it that
  /// coincides) count as frames together, besides the co-observations. Returns whether they
  /// merged (false also when they already are one).
  bool rejoin(int32_t a, int32_t b, double share);
  /// Co-observation counts M(L1, L2) of live super-points (L1 < L2).
  const std::map<std::pair<int32_t, int32_t>, int>& coObservations() const { return co_observed_; }
  /// Frames that showed two live super-points (L1 < L2) as two objects: each significant in a
  /// surface of a different thing mask of one class.
  const std::map<std::pair<int32_t, int32_t>, int>& apartCounts() const { return apart_; }
  /// The config in use.
  const SuperpointConfig& config() const { return config_; }
  /// Estimated heap bytes of the super-point bookkeeping (states, co-observations, merge log,
  /// label registry).
  size_t memoryBytes() const;

  /// Full state for saving and restoring a map.
  struct Snapshot {
    std::vector<int32_t> parents;
    std::map<int32_t, SuperpointState> states;
    std::map<std::pair<int32_t, int32_t>, int> co_observed;
    std::map<std::pair<int32_t, int32_t>, int> apart;
    std::vector<SuperpointMerge> merges;
    int32_t next_instance = 1;
    int64_t frames = 0;
  };
  /// Copies the state out.
  Snapshot snapshot() const;
  /// Replaces the state (throws Error when inconsistent).
  void restore(const Snapshot& snapshot);

 private:
  /// SuperpointState::labelledClass() of a live super-point, 0 when it has no state.
  int32_t labelledClassOf(int32_t label) const;
  bool consistent(int32_t a, int32_t b) const;
  /// Whether a surface in which both super-points are significant may join them: it has no
  /// mask, or a mask of their own class (with mask_verdicts).
  bool showsAsOne(const Surface& surface, int32_t a, int32_t b) const;
  /// Whether surface s, which lost a super-point to surface t this frame, splits from it:
  /// both are thing surfaces of one class under two different masks.
  bool splitsFrom(const Surface& s, const Surface& t) const;
  /// The network showed the pair (a < b) as two objects in at least as many frames as it
  /// co-observed them in one surface (m): no merge (semantic consistency only).
  bool seenApart(const std::pair<int32_t, int32_t>& key, int m) const;
  void mergeLabels(int32_t a, int32_t b, FrameAssociation* out);  // out: null or counts it
  /// join_mask_pieces: surfaces without a label take the super-point a surface of their mask
  /// took. pairs: (-samples, surface, label), best first; holder: label -> surface taking it.
  void joinMaskPieces(const std::vector<Surface>& surfaces,
                      const std::vector<std::tuple<int, size_t, int32_t>>& pairs,
                      const std::vector<int>& samples, const std::vector<int32_t>& lost,
                      const std::map<int32_t, size_t>& holder, FrameAssociation* out) const;
  /// revisit_votes: labelled surfaces without a label (and not splitting) take a free
  /// super-point of their class from their voxels' vote slots; holder gains them.
  void revisitVotes(const FrameSegmentation& segmentation, const RgbdFrame& frame,
                    const Eigen::Isometry3d& T_W_C, const TsdfMap& map,
                    const std::vector<int>& samples, const std::vector<int32_t>& lost,
                    std::map<int32_t, size_t>* holder, FrameAssociation* out);
  void associateInstances(const FrameSegmentation& segmentation, FrameAssociation* out);

  SuperpointConfig config_;
  LabelRegistry labels_;
  std::map<int32_t, SuperpointState> states_;               // by root label
  std::map<std::pair<int32_t, int32_t>, int> co_observed_;  // M, by root labels (a < b)
  std::map<std::pair<int32_t, int32_t>, int> apart_;        // frames seen as two objects
  std::vector<SuperpointMerge> merge_log_;
  std::vector<RowSample> row_samples_;  // scratch of associate(): one row's samples,
  std::vector<int32_t> row_surfaces_;   // their surfaces
  std::vector<int32_t> row_labels_;     // and their voxels' labels
  int32_t next_instance_ = 1;
  int64_t frames_ = 0;
};

}  // namespace panmap
