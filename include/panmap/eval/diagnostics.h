#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "panmap/core/labelled_mesh.h"
#include "panmap/eval/label_transfer.h"

namespace panmap {

/// What explains a score: how pure the super-points are, how the largest one is made up,
/// how many objects came out per ground-truth object, the stuff classes' IoU, and how well
/// instance confidences predict a match. All counts are over ground-truth vertices after the
/// label transfer; unannotated GT vertices (class 0) are left out of every share.
struct SceneDiagnostics {
  /// Vertex-weighted share of each super-point's majority GT identity (a thing instance, or a
  /// stuff class: walls split into pieces by the annotation are one identity), over the
  /// annotated GT vertices that carry a super-point. 1 = no super-point spans two objects.
  double superpoint_purity = 0.0;
  /// Vertex-weighted share of each super-point's majority GT class (the same, by class).
  double superpoint_class_purity = 0.0;
  int64_t num_superpoints = 0;  ///< super-points on at least one annotated GT vertex

  /// Super-points where two GT classes each hold more than `bridge_share` of its annotated
  /// vertices (only super-points of at least `min_superpoint_vertices` such vertices), counting
  /// only GT vertices farther than `boundary_band_m` from an annotated vertex of another class.
  /// A voxel map cannot place a class boundary more exactly: the first ring of wall vertices
  /// around a picture is a 10-20 % share of a small picture's super-point, and is resolution,
  /// not a super-point that chains classes.
  int num_bridging_superpoints = 0;
  /// The same count with every annotated vertex, boundary bands included.
  int num_bridging_superpoints_with_boundaries = 0;
  double bridge_share = 0.1;
  int64_t min_superpoint_vertices = 100;
  double boundary_band_m = 0.0;  ///< as given to diagnose()
  /// Largest share of a second GT class in any such super-point (boundary bands left out).
  double worst_second_class_share = 0.0;
  /// One super-point that spans two classes: its id, annotated vertices and class mix
  /// (NYU40 id, share), largest first.
  struct Bridge {
    int32_t superpoint = 0;
    int64_t vertices = 0;
    std::vector<std::pair<int32_t, double>> class_mix;
    /// How far it reaches past the boundary of its two largest classes, metres: for each of
    /// the two, the largest distance from one of its vertices here (boundary bands left out)
    /// to the nearest GT vertex of the other class; the smaller of the two. A super-point that
    /// chains classes reaches far into both (the floor-and-wall super-point of issue 19:
    /// metres); one that takes a few centimetres of a neighbour's surface at their boundary
    /// reaches that far into it, whatever the share those centimetres make of a small object.
    double reach_m = 0.0;
    /// The GT objects those vertices belong to, the most vertices first, at most
    /// kBridgeInstances: what to trace frame by frame (scripts/bench/trace_object.py
    /// --instance); a stuff class counts as one object, instance 0.
    struct Part {
      int32_t class_id = 0;  ///< NYU40 class
      int32_t instance = 0;  ///< GT instance id (0: a stuff class as a whole)
      int64_t vertices = 0;  ///< its GT vertices here, beyond the boundary band
    };
    std::vector<Part> parts;  ///< most vertices first, at most kBridgeInstances
    /// Median distance from its vertices of each of its two largest classes (boundary bands
    /// left out) to the nearest vertex of the map, metres; NaN when the label transfer kept no
    /// distances. Vertices on surface the map observed lie within about half a voxel of it;
    /// a class whose vertices lie farther is surface the map never resolved (the side of a
    /// bathtub behind an object standing against it), which the label transfer labels from the
    /// nearest mapped surface, whatever super-point that is.
    std::array<double, 2> map_distance_m = {std::numeric_limits<double>::quiet_NaN(),
                                            std::numeric_limits<double>::quiet_NaN()};
  };
  static constexpr size_t kBridgeInstances = 4;  ///< GT objects listed per bridge, at most
  std::vector<Bridge> bridges;                   ///< the bridging super-points, largest first

  /// The super-point on the most GT vertices (annotated or not).
  int32_t largest_superpoint = 0;
  int64_t largest_vertices = 0;              ///< all GT vertices it carries
  int64_t largest_unannotated_vertices = 0;  ///< of those, on unannotated GT
  /// Its annotated vertices by GT class, largest first: (NYU40 id, share).
  std::vector<std::pair<int32_t, double>> largest_class_mix;
  int largest_gt_instances = 0;  ///< GT identities it holds at least 1 % of

  /// Per-vertex IoU of the stuff classes, over annotated GT vertices (NaN without GT vertex of
  /// the class).
  double wall_iou = 0.0, floor_iou = 0.0, ceiling_iou = 0.0;
  /// Share of each stuff class's annotated GT vertices the map reached at all (NaN without GT
  /// vertex of the class): an IoU far below it is a labelling error, an IoU near it a surface
  /// the trajectory never looked at (the ceiling of a survey at head height).
  double wall_observed = 0.0, floor_observed = 0.0, ceiling_observed = 0.0;

  /// One predicted object (an instance id on the predicted mesh or in the object list).
  struct ObjectMatch {
    int32_t id = 0;
    int32_t class_id = 0;       ///< majority predicted class of its vertices
    double confidence = 1.0;    ///< from the object list; 1 when absent
    int64_t vertices = 0;       ///< GT vertices carrying it
    int64_t void_vertices = 0;  ///< of those, on unannotated GT
    double best_iou = 0.0;      ///< best IoU with a GT thing instance of the same class
    int32_t best_gt = -1;       ///< index into gt_things, -1 when none overlaps
    bool matched = false;       ///< best_iou > 0.5
    /// Most of it on unannotated GT: nothing to check it against, left out of calibration.
    bool unverifiable = false;
  };
  std::vector<ObjectMatch> objects;
  /// Why a GT thing is not matched at IoU 0.5, in the order tested; each cause bounds what
  /// can fix it. kUnobserved: at most half of it found a predicted vertex in range, so no
  /// labelling can reach IoU 0.5 (the trajectory did not see it). kPartlyObserved: more than
  /// half of it was seen, and the best object of its class would match had the rest been
  /// seen and mapped as the part seen was (its IoU over the share observed is above 0.5): the
  /// survey's coverage, not the labelling, is what it lacks. At most half of it carries
  /// its class, and more of the rest carries another class (kWrongClass: semantics, III-C's
  /// domain) or no class at all (kUnlabelled). kMerged: one object of its class covers more
  /// than half of it but is too large (it spans neighbours or background). kSplit: its class
  /// covers most of it, but no single object more than half (fragments).
  enum class MissCause : int8_t {
    kMatched = 0,
    kUnobserved,
    kWrongClass,
    kUnlabelled,
    kMerged,
    kSplit,
    kPartlyObserved  // tested second: after kUnobserved, before kWrongClass
  };

  /// GT thing instances of at least ScanNet's minimum region size: (class, instance id,
  /// vertices) and what became of them.
  struct GtThing {
    int32_t class_id = 0;
    int32_t instance_id = 0;
    int64_t vertices = 0;
    int32_t best_object = 0;             ///< the object overlapping it with the best IoU, any class
    int32_t best_object_class = 0;       ///< that object's class
    double best_iou = 0.0;               ///< its IoU (0 when no object overlaps)
    double observed_share = 0.0;         ///< share of its vertices that found a predicted vertex
    double class_share = 0.0;            ///< share of its vertices predicted with its class
    double other_class_share = 0.0;      ///< share predicted with another class (not 0)
    double best_same_class_iou = 0.0;    ///< best IoU with an object of its class
    double best_same_class_cover = 0.0;  ///< largest share of it one object of its class holds
    MissCause cause = MissCause::kMatched;
  };
  std::vector<GtThing> gt_things;
  int num_objects = 0;  ///< predicted objects (object list entries, else mesh instances)
  /// num_objects / gt_things.size() (NaN without GT things).
  double objects_per_gt_instance = 0.0;
  /// Objects that are not unverifiable: the ones a count against the annotated GT things can
  /// judge. Where a quarter of a scene is unannotated and the network labels it, the objects
  /// found there are the scene's real objects, not fragments of annotated ones.
  int num_checkable_objects = 0;
  /// num_checkable_objects / gt_things.size() (NaN without GT things).
  double checkable_objects_per_gt_instance = 0.0;

  /// Reliability of the confidences: objects (verifiable ones) binned by confidence.
  struct ReliabilityBin {
    double low = 0.0, high = 0.0;  ///< [low, high), the last bin includes 1
    int count = 0;
    int matched = 0;
    double mean_confidence = 0.0;
  };
  std::vector<ReliabilityBin> reliability;
  /// Objects with confidence >= 0.5 (verifiable), and the share of them that match.
  int confident_objects = 0;
  double confident_precision = 0.0;  ///< NaN without confident objects
  /// Share of GT thing instances matched by an object with confidence >= 0.5.
  double confident_recall = 0.0;
};

/// Computes the diagnostics of transferred labels against a GT mesh.
/// @param gt ground-truth mesh with semantic and instance labels (throws Error without them)
/// @param pred predicted labels per GT vertex (transferLabels; superpoint may be all 0)
/// @param objects instance id -> confidence of the object list; empty = every predicted
///     instance on the mesh with confidence 1. Ids in the list that no GT vertex carries are
///     objects too (unmatched).
/// @param num_bins reliability bins over [0, 1]
/// @param boundary_band_m GT vertices this close to another class are left out of the bridging
///        count (0: none left out). 1.5 voxels: the voxel a boundary crosses can take either
///        class, and the nearest-vertex transfer moves labels by up to half a voxel more.
SceneDiagnostics diagnose(const LabelledMesh& gt, const TransferredLabels& pred,
                          const std::map<int32_t, double>& objects, int num_bins = 5,
                          double boundary_band_m = 0.03);

/// "matched", "unobserved", "wrong class", "unlabelled", "merged" or "split".
const char* missCauseName(SceneDiagnostics::MissCause cause);

/// A few lines of text: purity, the largest super-point, objects, stuff IoU, reliability.
std::string formatDiagnostics(const SceneDiagnostics& d);

}  // namespace panmap
