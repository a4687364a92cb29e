// panmap-eval: ScanNet-style instance evaluation (AP, N_TP, PQ), super-point IoU_LS and
// semantic mIoU of a predicted mesh against a ground-truth mesh (ours, or a ScanNet scene's
// vh_clean_2 mesh with its aggregation and segments, or a benchmark GT file with its mesh)
// (DESIGN 8), and ATE / RPE of a camera trajectory against ground truth (TUM files).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include <nlohmann/json.hpp>
#include "cli_checks.h"

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/core/nearest_point.h"
#include "panmap/eval/diagnostics.h"
#include "panmap/eval/evaluation.h"
#include "panmap/eval/ground_truth_input.h"
#include "panmap/eval/trajectory_error.h"
#include "panmap/io/ply.h"
#include "panmap/io/scannet_ground_truth.h"
#include "panmap/io/tum_trajectory.h"

namespace {

using nlohmann::json;

/// Instance confidences from objects.json: an array, or {"objects": [...]}, of entries with
/// "id" (or "instance") and "confidence".
std::map<int32_t, double> readConfidences(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw panmap::Error(path + ": cannot open");
  json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw panmap::Error(path + ": bad JSON: " + e.what());
  }
  const json& list = j.is_object() && j.contains("objects") ? j["objects"] : j;
  if (!list.is_array()) throw panmap::Error(path + ": expected an array of objects");
  std::map<int32_t, double> out;
  for (const json& o : list) {
    const char* key = o.contains("id") ? "id" : "instance";
    if (!o.contains(key) || !o.contains("confidence")) {
      throw panmap::Error(path + ": an object lacks id or confidence");
    }
    const json& id = o[key];
    if (!id.is_number_integer()) {
      throw panmap::Error(path + ": an object's " + key + " is " + id.dump() +
                          ", not an integer instance id");
    }
    if (!o["confidence"].is_number()) {
      throw panmap::Error(path + ": object " + id.dump() + "'s confidence is " +
                          o["confidence"].dump() + ", not a number");
    }
    out[id.get<int32_t>()] = o["confidence"].get<double>();
  }
  return out;
}

/// Share of the predicted vertices with a ground-truth vertex within `max_distance_m`: near 1
/// for a map of the ground truth's scene, in its frame and units.
double shareNearGroundTruth(const panmap::LabelledMesh& pred,
                            const std::vector<Eigen::Vector3f>& gt_vertices,
                            double max_distance_m) {
  if (pred.vertices.empty() || gt_vertices.empty()) return 0.0;
  const panmap::NearestPointIndex tree(&gt_vertices);
  size_t near = 0;
  for (const Eigen::Vector3f& p : pred.vertices) {
    const int64_t g = tree.nearest(p);
    if (g >= 0 && (gt_vertices[g].cast<double>() - p.cast<double>()).norm() <= max_distance_m) {
      ++near;
    }
  }
  return static_cast<double>(near) / pred.vertices.size();
}

/// Instances of the mesh scored by the evaluation (at least `min_vertices`) that `confidences`
/// lacks: each would be scored at confidence 1. Smaller ones are left out of the evaluation
/// (and the mapper leaves such fragments out of objects.json).
size_t instancesWithoutConfidence(const panmap::LabelledMesh& pred,
                                  const std::map<int32_t, double>& confidences,
                                  int64_t min_vertices, size_t* instances) {
  std::map<int32_t, int64_t> vertices;
  for (const int32_t id : pred.instance) {
    if (id != 0) ++vertices[id];
  }
  *instances = 0;
  size_t missing = 0;
  for (const auto& [id, count] : vertices) {
    if (count < min_vertices) continue;
    ++*instances;
    missing += confidences.count(id) == 0;
  }
  return missing;
}

/// NaN as JSON null.
json number(double v) { return std::isnan(v) ? json(nullptr) : json(v); }

json toJson(const panmap::EvalResult& r) {
  json classes = json::array();
  for (const panmap::ClassMetrics& c : r.classes) {
    classes.push_back({{"class_id", c.class_id},
                       {"name", panmap::nyu40Name(c.class_id)},
                       {"num_gt", c.num_gt},
                       {"num_pred", c.num_pred},
                       {"ap", number(c.ap)},
                       {"ap25", number(c.ap25)},
                       {"ap50", number(c.ap50)},
                       {"ap75", number(c.ap75)},
                       {"tp50", c.tp50},
                       {"tp75", c.tp75},
                       {"pq50", number(c.pq50)},
                       {"sq50", number(c.sq50)},
                       {"rq50", number(c.rq50)},
                       {"pq75", number(c.pq75)},
                       {"sq75", number(c.sq75)},
                       {"rq75", number(c.rq75)},
                       {"iou_ls", number(c.iou_ls)},
                       {"iou_ls_best", number(c.iou_ls_best)},
                       {"semantic_iou", number(c.semantic_iou)},
                       {"semantic_gt_vertices", c.semantic_gt_vertices},
                       {"semantic_false_vertices", c.semantic_false_vertices}});
  }
  return {{"protocol", r.paper_compatible ? "paper-compatible (matched predictions scored at "
                                            "confidence 1)"
                                          : "scannet evaluate_semantic_instance"},
          {"paper_compatible", r.paper_compatible},
          {"num_gt_vertices", r.num_gt_vertices},
          {"num_transferred", r.num_transferred},
          {"map", number(r.map)},
          {"map25", number(r.map25)},
          {"map50", number(r.map50)},
          {"map75", number(r.map75)},
          {"ntp50", r.ntp50},
          {"ntp75", r.ntp75},
          {"pq50", number(r.pq50)},
          {"sq50", number(r.sq50)},
          {"rq50", number(r.rq50)},
          {"pq75", number(r.pq75)},
          {"sq75", number(r.sq75)},
          {"rq75", number(r.rq75)},
          {"iou_ls", number(r.iou_ls)},
          {"iou_ls_instances", number(r.iou_ls_instances)},
          {"iou_ls_best", number(r.iou_ls_best)},
          {"miou", number(r.miou)},
          {"miou_gt_classes", number(r.miou_gt_classes)},
          {"spurious_classes", r.spurious_classes},
          {"spurious_vertices", r.spurious_vertices},
          {"classes", classes}};
}

json toJson(const panmap::SceneDiagnostics& d) {
  json mix = json::array();
  for (const auto& [cls, share] : d.largest_class_mix) {
    mix.push_back({{"class_id", cls}, {"name", panmap::nyu40Name(cls)}, {"share", share}});
  }
  json objects = json::array();
  for (const auto& o : d.objects) {
    objects.push_back({{"id", o.id},
                       {"class_id", o.class_id},
                       {"confidence", o.confidence},
                       {"vertices", o.vertices},
                       {"void_vertices", o.void_vertices},
                       {"best_iou", o.best_iou},
                       {"matched", o.matched},
                       {"unverifiable", o.unverifiable}});
  }
  json bridges = json::array();
  for (const auto& b : d.bridges) {
    json classes = json::array();
    for (const auto& [cls, share] : b.class_mix) {
      classes.push_back({{"class_id", cls}, {"name", panmap::nyu40Name(cls)}, {"share", share}});
    }
    json parts = json::array();
    for (const auto& p : b.parts) {
      parts.push_back(
          {{"class_id", p.class_id}, {"instance", p.instance}, {"vertices", p.vertices}});
    }
    bridges.push_back({{"superpoint", b.superpoint},
                       {"vertices", b.vertices},
                       {"classes", classes},
                       {"gt_instances", parts},
                       {"reach_m", b.reach_m},
                       {"map_distance_m",
                        json::array({number(b.map_distance_m[0]), number(b.map_distance_m[1])})}});
  }
  json things = json::array();
  for (const auto& t : d.gt_things) {
    things.push_back({{"class_id", t.class_id},
                      {"instance_id", t.instance_id},
                      {"vertices", t.vertices},
                      {"best_object", t.best_object},
                      {"best_object_class", t.best_object_class},
                      {"best_iou", t.best_iou},
                      {"observed_share", t.observed_share},
                      {"class_share", t.class_share},
                      {"other_class_share", t.other_class_share},
                      {"best_same_class_iou", t.best_same_class_iou},
                      {"best_same_class_cover", t.best_same_class_cover},
                      {"cause", panmap::missCauseName(t.cause)}});
  }
  json bins = json::array();
  for (const auto& b : d.reliability) {
    bins.push_back({{"low", b.low},
                    {"high", b.high},
                    {"count", b.count},
                    {"matched", b.matched},
                    {"mean_confidence", b.mean_confidence}});
  }
  return {{"superpoint_purity", number(d.superpoint_purity)},
          {"superpoint_class_purity", number(d.superpoint_class_purity)},
          {"num_superpoints", d.num_superpoints},
          {"num_bridging_superpoints", d.num_bridging_superpoints},
          {"num_bridging_superpoints_with_boundaries", d.num_bridging_superpoints_with_boundaries},
          {"boundary_band_m", d.boundary_band_m},
          {"bridge_share", d.bridge_share},
          {"worst_second_class_share", d.worst_second_class_share},
          {"bridges", bridges},
          {"largest_superpoint",
           {{"id", d.largest_superpoint},
            {"vertices", d.largest_vertices},
            {"unannotated_vertices", d.largest_unannotated_vertices},
            {"gt_objects", d.largest_gt_instances},
            {"class_mix", mix}}},
          {"wall_iou", number(d.wall_iou)},
          {"floor_iou", number(d.floor_iou)},
          {"ceiling_iou", number(d.ceiling_iou)},
          {"wall_observed", number(d.wall_observed)},
          {"floor_observed", number(d.floor_observed)},
          {"ceiling_observed", number(d.ceiling_observed)},
          {"num_objects", d.num_objects},
          {"num_gt_things", d.gt_things.size()},
          {"objects_per_gt_instance", number(d.objects_per_gt_instance)},
          {"num_checkable_objects", d.num_checkable_objects},
          {"checkable_objects_per_gt_instance", number(d.checkable_objects_per_gt_instance)},
          {"confident_objects", d.confident_objects},
          {"confident_precision", number(d.confident_precision)},
          {"confident_recall", number(d.confident_recall)},
          {"reliability", bins},
          {"gt_things", things},
          {"objects", objects}};
}

/// Error statistics; null values when there were no errors to summarise.
json toJson(const panmap::ErrorStats& s) {
  const auto value = [&s](double v) { return s.count ? json(v) : json(nullptr); };
  return {{"count", s.count},
          {"rmse", value(s.rmse)},
          {"mean", value(s.mean)},
          {"median", value(s.median)},
          {"max", value(s.max)}};
}

json toJson(const panmap::TrajectoryError& e, const panmap::TrajectoryErrorConfig& config) {
  json T = json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) T.push_back(e.T_gt_est.matrix()(r, c));
  }
  return {
      {"num_estimated", e.num_estimated},
      {"num_ground_truth", e.num_ground_truth},
      {"num_associated", e.num_associated},
      {"max_time_difference_s", config.max_time_difference_s},
      {"rpe_delta_s", e.rpe_delta_s},
      {"ate_m", toJson(e.ate_m)},
      {"rpe_translation_m", toJson(e.rpe_m)},
      {"rpe_rotation_deg", toJson(e.rpe_deg)},
      {"T_gt_est_row_major", T},
      {"scale", e.scale},
      {"camera_offset_m", {e.camera_offset_m.x(), e.camera_offset_m.y(), e.camera_offset_m.z()}}};
}

/// The ground-truth mesh from --gt or --gt-scannet, with --gt-instances applied.
panmap::LabelledMesh loadGroundTruth(const std::string& gt_path, const std::string& scannet_dir,
                                     const std::string& scannet_labels,
                                     const std::string& gt_instances_path) {
  panmap::LabelledMesh gt;
  std::string source = gt_path;
  if (!scannet_dir.empty()) {
    const panmap::ScanNetSceneFiles files = panmap::findScanNetSceneFiles(scannet_dir);
    const std::string table_path =
        scannet_labels.empty() ? panmap::findScanNetLabelTable(scannet_dir) : scannet_labels;
    if (table_path.empty()) {
      throw panmap::Error("--gt-scannet " + scannet_dir +
                          ": no scannetv2-labels.combined.tsv in it, its parent or its "
                          "grandparent; give it with --scannet-labels");
    }
    const panmap::ScanNetLabelTable table = panmap::ScanNetLabelTable::load(table_path);
    panmap::ScanNetGroundTruth scene = panmap::loadScanNetGroundTruth(
        files.mesh_ply, files.aggregation_json, files.segs_json, table);
    if (!scene.unknown_labels.empty()) {
      std::string names;
      for (size_t i = 0; i < scene.unknown_labels.size() && i < 5; ++i) {
        names += (i ? ", '" : "'") + scene.unknown_labels[i] + "'";
      }
      std::fprintf(stderr, "panmap-eval: %zu raw labels of %s match no NYU40 class (%s%s)\n",
                   scene.unknown_labels.size(), files.scene.c_str(), names.c_str(),
                   scene.unknown_labels.size() > 5 ? ", ..." : "");
    }
    gt = std::move(scene.mesh);
    source = files.mesh_ply;
  } else {
    gt = panmap::readPly(gt_path);
  }
  if (!gt_instances_path.empty()) {
    panmap::applyScanNetInstanceIds(panmap::readScanNetInstanceFile(gt_instances_path),
                                    gt_instances_path, source, &gt);
  }
  if (gt.semantic.size() != gt.numVertices() || gt.instance.size() != gt.numVertices()) {
    throw panmap::Error(source +
                        ": needs semantic and instance vertex properties (or "
                        "--gt-instances)");
  }
  return gt;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Evaluate a predicted panmap mesh against ground truth: ScanNet evaluate_semantic_instance "
      "AP (0.5:0.95, 0.5, 0.75, 0.25), N_TP, PQ/SQ/RQ, super-point IoU_LS and semantic mIoU "
      "after a nearest-vertex label transfer; and/or a TUM trajectory against ground truth: "
      "ATE (RMSE after rigid alignment) and RPE."};
  std::string pred_path, gt_path, gt_instances_path, confidences_path, json_path;
  std::string scannet_dir, scannet_labels, classes_text, traj_path, gt_traj_path;
  panmap::EvalConfig config;
  panmap::TrajectoryErrorConfig traj_config;
  app.add_option("--pred", pred_path,
                 "predicted mesh (mesh_instance.ply: semantic, instance, "
                 "superpoint vertex properties)");
  auto* gt_option =
      app.add_option("--gt", gt_path, "ground-truth mesh PLY (semantic, instance properties)");
  auto* scannet_option = app.add_option(
      "--gt-scannet", scannet_dir,
      "ScanNet scene folder with <scene>_vh_clean_2.ply, <scene>.aggregation.json and "
      "<scene>_vh_clean_2.0.010000.segs.json (instance = objectId + 1)");
  auto* labels_option = app.add_option(
      "--scannet-labels", scannet_labels,
      "ScanNet's scannetv2-labels.combined.tsv (raw category -> NYU40), for --gt-scannet "
      "(default: the one in the scene folder, its parent or its grandparent)");
  scannet_option->excludes(gt_option);
  labels_option->needs(scannet_option);
  app.add_option("--gt-instances", gt_instances_path,
                 "ScanNet benchmark GT file (class*1000+k per vertex) of the GT mesh; overrides "
                 "its labels");
  app.add_option("--confidences", confidences_path,
                 "objects.json with id and confidence per instance (default: confidence 1)");
  app.add_option("--classes", classes_text,
                 "evaluated classes, NYU40 ids or names, comma-separated (default: ScanNet's 18)");
  app.add_option("--min-region-size", config.min_region_size,
                 "ignore GT and predicted instances with fewer vertices (ScanNet: 100)")
      ->capture_default_str()
      ->check(panmap::cli::nonNegative());
  app.add_option("--json", json_path, "write the results as JSON to this file");
  app.add_option("--max-distance", config.max_distance_m, "label transfer radius, metres")
      ->capture_default_str();
  double boundary_band_m = 0.03;
  app.add_option("--boundary-band", boundary_band_m,
                 "diagnostics: GT vertices this close to another class are left out of the "
                 "count of super-points that span two classes (1.5 voxels of the map), metres")
      ->capture_default_str()
      ->check(panmap::cli::nonNegative());
  app.add_flag("--paper-compatible", config.paper_compatible,
               "score matched predictions at confidence 1 (the released scripts' quirk)");
  auto* traj_option = app.add_option("--traj", traj_path,
                                     "estimated trajectory, TUM format (t tx ty tz qx qy qz qw)");
  auto* gt_traj_option =
      app.add_option("--gt-traj", gt_traj_path, "ground-truth trajectory, TUM format");
  traj_option->needs(gt_traj_option);
  gt_traj_option->needs(traj_option);
  bool align_pred = false;
  app.add_flag("--align-pred", align_pred,
               "move the predicted mesh by the trajectory's alignment (the ATE's T_gt_est, and "
               "its scale with --fit-scale) before the label transfer: a map built from "
               "estimated poses lives in the estimate's world frame, which differs from the "
               "ground truth's by a rigid transform no mapper can observe")
      ->needs(traj_option);
  app.add_option("--max-time-difference", traj_config.max_time_difference_s,
                 "largest stamp difference of associated poses, seconds")
      ->capture_default_str();
  app.add_flag("--fit-camera-offset", traj_config.fit_camera_offset,
               "ATE: also fit a constant offset of the camera centre in the estimate's camera "
               "frame, for trajectories of two cameras on one rig (depth tracking against "
               "colour-camera poses)")
      ->needs(traj_option);
  app.add_flag("--fit-scale", traj_config.fit_scale,
               "ATE: align by a similarity (with scale), for trajectories without metric scale")
      ->needs(traj_option);
  app.add_option("--rpe-delta", traj_config.rpe_delta_s,
                 "time between the poses of a relative pose error, seconds")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  try {
    const bool mesh_eval = !pred_path.empty();
    if (mesh_eval && gt_path.empty() && scannet_dir.empty()) {
      throw panmap::Error("--pred needs ground truth: --gt MESH or --gt-scannet SCENE_DIR");
    }
    if (!mesh_eval && (!gt_path.empty() || !scannet_dir.empty() || !gt_instances_path.empty() ||
                       !confidences_path.empty() || !classes_text.empty())) {
      throw panmap::Error("mesh ground truth, --confidences and --classes need --pred");
    }
    if (!mesh_eval && traj_path.empty()) {
      throw panmap::Error(
          "nothing to evaluate: give --pred with --gt or --gt-scannet, and/or --traj with "
          "--gt-traj");
    }
    if (align_pred && !mesh_eval) throw panmap::Error("--align-pred needs --pred");
    json out;
    panmap::TrajectoryError trajectory_error;
    if (!traj_path.empty()) {
      trajectory_error =
          panmap::evaluateTrajectory(panmap::readTumTrajectory(traj_path),
                                     panmap::readTumTrajectory(gt_traj_path), traj_config);
    }
    if (mesh_eval) {
      if (!classes_text.empty()) config.classes = panmap::parseClassList(classes_text);
      panmap::LabelledMesh pred = panmap::readPly(pred_path);
      // Without them every vertex would read as unlabelled and score 0 without a word.
      if (pred.semantic.size() != pred.numVertices() ||
          pred.instance.size() != pred.numVertices()) {
        throw panmap::Error(pred_path +
                            ": needs semantic and instance vertex properties (a panmap "
                            "mesh_instance.ply)");
      }
      if (align_pred) {
        const Eigen::Isometry3f T_gt_est = trajectory_error.T_gt_est.cast<float>();
        const float scale = static_cast<float>(trajectory_error.scale);
        for (Eigen::Vector3f& p : pred.vertices) p = T_gt_est * (scale * p);
      }
      const panmap::LabelledMesh gt =
          loadGroundTruth(gt_path, scannet_dir, scannet_labels, gt_instances_path);
      std::map<int32_t, double> confidences;
      if (!confidences_path.empty()) confidences = readConfidences(confidences_path);
      const panmap::TransferredLabels transferred =
          panmap::transferLabels(pred, gt.vertices, config.max_distance_m);
      const double near_share = shareNearGroundTruth(pred, gt.vertices, config.max_distance_m);
      if (transferred.num_transferred == 0 && pred.numVertices() > 0) {
        char radius[32];
        std::snprintf(radius, sizeof(radius), "%g", config.max_distance_m);
        throw panmap::Error("no ground-truth vertex has a predicted vertex within " +
                            std::string(radius) +
                            " m: the meshes do not overlap (another scene, other units, or a "
                            "map in another frame: --align-pred)");
      }
      if (near_share < 0.5 && pred.numVertices() > 0) {
        std::fprintf(stderr,
                     "panmap-eval: warning: only %.1f %% of the predicted vertices lie within "
                     "%g m of the ground truth: the same scene, in the same frame and units?\n",
                     100.0 * near_share, config.max_distance_m);
      }
      if (!confidences_path.empty()) {
        size_t instances = 0;
        const size_t missing =
            instancesWithoutConfidence(pred, confidences, config.min_region_size, &instances);
        if (missing > 0) {
          std::fprintf(stderr,
                       "panmap-eval: warning: %zu of the %zu scored instances of %s have no "
                       "confidence in %s (scored at 1): the objects.json of another map?\n",
                       missing, instances, pred_path.c_str(), confidences_path.c_str());
        }
      }
      const panmap::EvalResult result =
          panmap::evaluateTransferred(gt, transferred, confidences, config);
      std::printf("%s", panmap::formatEvalTable(result).c_str());
      std::printf("predicted vertices within %g m of the ground truth: %.1f %%\n",
                  config.max_distance_m, 100.0 * near_share);
      out = toJson(result);
      out["pred_near_gt_share"] = near_share;
      const panmap::SceneDiagnostics diagnostics =
          panmap::diagnose(gt, transferred, confidences, 5, boundary_band_m);
      std::printf("%s", panmap::formatDiagnostics(diagnostics).c_str());
      out["diagnostics"] = toJson(diagnostics);
    }
    if (!traj_path.empty()) {
      std::printf("%s", panmap::formatTrajectoryError(trajectory_error).c_str());
      out["trajectory"] = toJson(trajectory_error, traj_config);
      if (align_pred) out["pred_aligned_by_trajectory"] = true;
    }
    if (!json_path.empty()) {
      std::ofstream file(json_path);
      file << out.dump(2) << "\n";
      file.close();
      if (!file) throw panmap::Error(json_path + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-eval: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
