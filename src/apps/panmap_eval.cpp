// panmap-eval: ScanNet-style instance evaluation (AP, N_TP, PQ), super-point IoU_LS and
// semantic mIoU of a predicted mesh against a ground-truth mesh (DESIGN 8).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/eval/evaluation.h"
#include "panmap/io/ply.h"
#include "panmap/io/scannet_ground_truth.h"

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
    out[o[key].get<int32_t>()] = o["confidence"].get<double>();
  }
  return out;
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
                       {"semantic_iou", number(c.semantic_iou)}});
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
          {"classes", classes}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Evaluate a predicted panmap mesh against a ground-truth mesh: ScanNet "
      "evaluate_semantic_instance AP (0.5:0.95, 0.5, 0.75, 0.25), N_TP, PQ/SQ/RQ, super-point "
      "IoU_LS and semantic mIoU after a nearest-vertex label transfer."};
  std::string pred_path, gt_path, gt_instances_path, confidences_path, json_path;
  panmap::EvalConfig config;
  app.add_option("--pred", pred_path,
                 "predicted mesh (mesh_instance.ply: semantic, instance, "
                 "superpoint vertex properties)")
      ->required();
  app.add_option("--gt", gt_path, "ground-truth mesh PLY (semantic, instance)")->required();
  app.add_option("--gt-instances", gt_instances_path,
                 "ScanNet benchmark GT file (class*1000+k per vertex); overrides the GT mesh's "
                 "instances");
  app.add_option("--confidences", confidences_path,
                 "objects.json with id and confidence per instance (default: confidence 1)");
  app.add_option("--json", json_path, "write the results as JSON to this file");
  app.add_option("--max-distance", config.max_distance_m, "label transfer radius, metres")
      ->capture_default_str();
  app.add_flag("--paper-compatible", config.paper_compatible,
               "score matched predictions at confidence 1 (the released scripts' quirk)");
  CLI11_PARSE(app, argc, argv);

  try {
    const panmap::LabelledMesh pred = panmap::readPly(pred_path);
    panmap::LabelledMesh gt = panmap::readPly(gt_path);
    if (!gt_instances_path.empty()) {
      const std::vector<int32_t> ids = panmap::readScanNetInstanceFile(gt_instances_path);
      if (ids.size() != gt.numVertices()) {
        throw panmap::Error(gt_instances_path + ": " + std::to_string(ids.size()) + " lines but " +
                            gt_path + " has " + std::to_string(gt.numVertices()) + " vertices");
      }
      if (gt.semantic.size() != gt.numVertices()) gt.semantic.assign(gt.numVertices(), 0);
      gt.instance.assign(gt.numVertices(), 0);
      for (size_t v = 0; v < ids.size(); ++v) {
        if (ids[v] <= 0) continue;
        gt.semantic[v] = ids[v] / 1000;
        gt.instance[v] = ids[v];
      }
    }
    if (gt.semantic.size() != gt.numVertices() || gt.instance.size() != gt.numVertices()) {
      throw panmap::Error(gt_path +
                          ": needs semantic and instance vertex properties (or "
                          "--gt-instances)");
    }
    std::map<int32_t, double> confidences;
    if (!confidences_path.empty()) confidences = readConfidences(confidences_path);
    const panmap::EvalResult result = panmap::evaluate(gt, pred, confidences, config);
    std::printf("%s", panmap::formatEvalTable(result).c_str());
    if (!json_path.empty()) {
      std::ofstream out(json_path);
      out << toJson(result).dump(2) << "\n";
      if (!out) throw panmap::Error(json_path + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-eval: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
