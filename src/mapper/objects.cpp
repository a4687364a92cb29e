#include "panmap/mapper/objects.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/graph/object_confidence.h"
#include "panmap/io/atomic_file.h"
#include "panmap/mapper/final_labels.h"
#include "panmap/mapper/mapper.h"

namespace panmap {
namespace {

using nlohmann::json;

// Everything gathered about one instance in the voxel pass.
struct InstanceVoxels {
  std::vector<Eigen::Vector3d> centres_W;
  std::map<int32_t, int64_t> voxels_per_superpoint;
  std::map<int32_t, int64_t> voxels_per_class;
};

// n_best / (n + 1) of one super-point's frame-count instance assignments.
double frameCountStability(const SuperpointState* state) {
  if (!state) return 0.0;
  int64_t n = 0, best = 0;
  for (const auto& [id, count] : state->instance_counts) {
    n += count;
    best = std::max<int64_t>(best, count);
  }
  return static_cast<double>(best) / static_cast<double>(n + 1);
}

double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Convex hull (Andrew's monotone chain), counter-clockwise, collinear points dropped.
std::vector<Eigen::Vector2d> convexHull(std::vector<Eigen::Vector2d> points) {
  auto less = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  };
  std::sort(points.begin(), points.end(), less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross2(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Axis of the minimum-area rectangle around a footprint (an edge of the optimal rectangle lies
// on a hull edge, so trying every hull edge direction is exhaustive). First minimum wins.
Eigen::Vector2d minimumAreaAxis(const std::vector<Eigen::Vector2d>& footprint) {
  const std::vector<Eigen::Vector2d> hull = convexHull(footprint);
  if (hull.size() < 2) return Eigen::Vector2d::UnitX();
  if (hull.size() == 2) return (hull[1] - hull[0]).normalized();
  double best_area = std::numeric_limits<double>::infinity();
  Eigen::Vector2d best = Eigen::Vector2d::UnitX();
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d u = (hull[(i + 1) % hull.size()] - hull[i]).normalized();
    const Eigen::Vector2d v(-u.y(), u.x());
    double lo_u = std::numeric_limits<double>::infinity(), hi_u = -lo_u, lo_v = lo_u, hi_v = hi_u;
    for (const Eigen::Vector2d& p : hull) {
      lo_u = std::min(lo_u, u.dot(p));
      hi_u = std::max(hi_u, u.dot(p));
      lo_v = std::min(lo_v, v.dot(p));
      hi_v = std::max(hi_v, v.dot(p));
    }
    const double area = (hi_u - lo_u) * (hi_v - lo_v);
    if (area < best_area) {
      best_area = area;
      best = u;
    }
  }
  return best;
}

// The sign of an axis direction with yaw in (-pi/2, pi/2]. Axes stay vectors (not angles) so
// that axis-aligned boxes come out exact.
Eigen::Vector2d canonicalAxis(const Eigen::Vector2d& u) {
  return u.x() > 0.0 || (u.x() == 0.0 && u.y() > 0.0) ? u : Eigen::Vector2d(-u);
}

// Extent of the voxel cells along a horizontal unit axis: centres +- a cell's half width
// along that axis.
std::pair<double, double> cellRange(const std::vector<Eigen::Vector3d>& centres_W,
                                    const Eigen::Vector2d& u, double voxel_m) {
  const double half = 0.5 * voxel_m * (std::abs(u.x()) + std::abs(u.y()));
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Eigen::Vector3d& c : centres_W) {
    const double p = u.x() * c.x() + u.y() * c.y();
    lo = std::min(lo, p);
    hi = std::max(hi, p);
  }
  return {lo - half, hi + half};
}

// Fills the boxes and centroid of an object from its voxel centres.
void fitBoxes(const std::vector<Eigen::Vector3d>& centres_W, double voxel_m, MappedObject* o) {
  const double half = 0.5 * voxel_m;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo, sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector2d> footprint;
  footprint.reserve(centres_W.size());
  for (const Eigen::Vector3d& c : centres_W) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
    sum += c;
    footprint.push_back(c.head<2>());
  }
  o->centroid_W = sum / static_cast<double>(centres_W.size());
  o->aabb_min_W = lo.array() - half;
  o->aabb_max_W = hi.array() + half;

  Eigen::Vector2d u = canonicalAxis(minimumAreaAxis(footprint));
  Eigen::Vector2d v = canonicalAxis(Eigen::Vector2d(-u.y(), u.x()));
  auto [lo_u, hi_u] = cellRange(centres_W, u, voxel_m);
  auto [lo_v, hi_v] = cellRange(centres_W, v, voxel_m);
  // Canonical form: x along the longer side; a square takes the axis nearer world x (on a
  // tie, the positive yaw).
  const double len_u = hi_u - lo_u, len_v = hi_v - lo_v;
  const double tie = 1e-9 * std::max(len_u, len_v);
  const bool square = std::abs(len_u - len_v) <= tie;
  if ((!square && len_v > len_u) ||
      (square && (v.x() > u.x() || (v.x() == u.x() && v.y() > u.y())))) {
    std::swap(u, v);
    std::swap(lo_u, lo_v);
    std::swap(hi_u, hi_v);
  }
  // B's y axis completes a right-handed frame with x = u and z up.
  const Eigen::Vector2d y_B(-u.y(), u.x());
  const double mid_v = 0.5 * (lo_v + hi_v) * (y_B.dot(v) > 0.0 ? 1.0 : -1.0);
  const Eigen::Vector2d centre_xy = 0.5 * (lo_u + hi_u) * u + mid_v * y_B;
  o->obb_center_W = Eigen::Vector3d(centre_xy.x(), centre_xy.y(), 0.5 * (lo.z() + hi.z()));
  const double yaw = std::atan2(u.y(), u.x());
  o->q_W_B = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  o->obb_extent_m = Eigen::Vector3d(hi_u - lo_u, hi_v - lo_v, hi.z() - lo.z() + voxel_m);
}

json vec3(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

Eigen::Vector3d readVec3(const json& o, const char* key, const std::string& where) {
  if (!o.contains(key) || !o[key].is_array() || o[key].size() != 3) {
    throw Error(where + ": '" + key + "' must be an array of 3 numbers");
  }
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!o[key][k].is_number()) throw Error(where + ": '" + key + "' must hold numbers");
    v[k] = o[key][k].get<double>();
  }
  return v;
}

template <typename T>
T readNumber(const json& o, const char* key, const std::string& where) {
  if (!o.contains(key) || !o[key].is_number()) throw Error(where + ": '" + key + "' missing");
  return o[key].get<T>();
}

}  // namespace

std::vector<MappedObject> computeObjects(const TsdfMap& map, const SuperpointTracker& tracker,
                                         const GraphLabels* labels, const ObjectScoring* scoring) {
  const float band_m = kObjectSurfaceBandVoxels * map.voxelSize();
  auto resolve = [&tracker](int32_t l) { return tracker.labels().resolve(l); };
  std::map<int32_t, SuperpointLabels> cache;  // super-point -> labels, looked up once each
  std::map<int32_t, InstanceVoxels> instances;
  for (const auto& block : map.blocks()) {
    for (int z = 0; z < kBlockSide; ++z) {
      for (int y = 0; y < kBlockSide; ++y) {
        for (int x = 0; x < kBlockSide; ++x) {
          const Voxel& voxel = block->at(x, y, z);
          if (voxel.weight <= 0.0f || std::abs(voxel.sdf_m) > band_m) continue;
          const int32_t superpoint = argmaxLabel(block->votes(Block::linear(x, y, z)), resolve);
          if (superpoint <= 0) continue;
          auto it = cache.find(superpoint);
          if (it == cache.end()) {
            it = cache.emplace(superpoint, finalLabels(superpoint, tracker, labels)).first;
          }
          if (it->second.instance <= 0) continue;
          InstanceVoxels& inst = instances[it->second.instance];
          inst.centres_W.push_back(map.voxelCentre(block->index, x, y, z).cast<double>());
          ++inst.voxels_per_superpoint[superpoint];
          ++inst.voxels_per_class[it->second.semantic];
        }
      }
    }
  }

  std::vector<MappedObject> objects;
  objects.reserve(instances.size());
  for (const auto& [id, inst] : instances) {
    MappedObject o;
    o.id = id;
    o.num_voxels = static_cast<int32_t>(inst.centres_W.size());
    int64_t best = 0;
    for (const auto& [cls, count] : inst.voxels_per_class) {
      if (count > best) o.class_id = cls, best = count;  // ascending: ties keep the smaller id
    }
    for (const auto& entry : inst.voxels_per_superpoint) o.superpoints.push_back(entry.first);
    const auto optimised =
        labels ? labels->instance_confidence.find(id) : std::map<int32_t, float>::const_iterator();
    if (labels && optimised != labels->instance_confidence.end()) {
      o.confidence = optimised->second;
      const auto e = labels->instance_evidence.find(id);
      if (e != labels->instance_evidence.end()) o.evidence = e->second;
    } else if (scoring && scoring->graph) {
      // The evidence InstanceEvidence would give this instance in the optimiser's graph.
      InstanceEvidence e;
      e.instance = id;
      e.class_id = o.class_id;
      e.voxels = o.num_voxels;
      for (const auto& entry : inst.voxels_per_superpoint) {
        ++e.superpoints;
        const int32_t own_class = cache.at(entry.first).semantic;
        for (const auto& [cls, value] : scoring->graph->scores(entry.first)) {
          e.score_all += value;
          if (cls == own_class) e.score += value;
        }
      }
      o.confidence = objectConfidence(e, map.voxelSize(), scoring->model);
      o.evidence = objectEvidence(e, map.voxelSize());
    } else {
      double weighted = 0.0;
      for (const auto& [superpoint, count] : inst.voxels_per_superpoint) {
        weighted += static_cast<double>(count) * frameCountStability(tracker.state(superpoint));
      }
      o.confidence = static_cast<float>(weighted / o.num_voxels);
    }
    fitBoxes(inst.centres_W, map.voxelSize(), &o);
    objects.push_back(std::move(o));
  }
  return objects;
}

std::vector<MappedObject> computeObjects(const Mapper& mapper, const GraphLabels* labels,
                                         const OptimiserConfig::Objects& model) {
  const ObjectScoring scoring{&mapper.graphAccumulator(), model};
  return computeObjects(mapper.map(), mapper.superpoints(), labels, &scoring);
}

void writeObjectsJson(const std::string& path, const std::vector<MappedObject>& objects,
                      int64_t utime) {
  json list = json::array();
  for (const MappedObject& o : objects) {
    const Eigen::Quaterniond& q = o.q_W_B;
    list.push_back({{"id", o.id},
                    {"class", o.class_id},
                    {"class_name", nyu40Name(o.class_id)},
                    {"confidence", static_cast<double>(o.confidence)},
                    {"num_voxels", o.num_voxels},
                    {"centroid", vec3(o.centroid_W)},
                    {"aabb_min", vec3(o.aabb_min_W)},
                    {"aabb_max", vec3(o.aabb_max_W)},
                    {"obb_center", vec3(o.obb_center_W)},
                    {"obb_orientation_wxyz", json::array({q.w(), q.x(), q.y(), q.z()})},
                    {"obb_extent", vec3(o.obb_extent_m)},
                    {"superpoints", o.superpoints},
                    {"evidence",
                     {{"area_m2", o.evidence.area_m2},
                      {"support", o.evidence.support},
                      {"class_share", o.evidence.class_share}}}});
  }
  const json root = {{"utime", utime}, {"objects", list}};
  writeFileAtomically(path, root.dump(2) + "\n");
}

std::vector<MappedObject> readObjectsJson(const std::string& path, int64_t* utime) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  json root;
  try {
    in >> root;
  } catch (const std::exception& e) {
    throw Error(path + ": bad JSON: " + e.what());
  }
  if (!root.is_object() || !root.contains("objects") || !root["objects"].is_array()) {
    throw Error(path + ": expected {\"objects\": [...]}");
  }
  if (utime) *utime = root.contains("utime") ? readNumber<int64_t>(root, "utime", path) : 0;
  std::vector<MappedObject> objects;
  for (const json& j : root["objects"]) {
    const std::string where = path + ": object " + std::to_string(objects.size());
    if (!j.is_object()) throw Error(where + ": not an object");
    MappedObject o;
    o.id = readNumber<int32_t>(j, "id", where);
    o.class_id = readNumber<int32_t>(j, "class", where);
    o.confidence = static_cast<float>(readNumber<double>(j, "confidence", where));
    o.num_voxels = readNumber<int32_t>(j, "num_voxels", where);
    o.centroid_W = readVec3(j, "centroid", where);
    o.aabb_min_W = readVec3(j, "aabb_min", where);
    o.aabb_max_W = readVec3(j, "aabb_max", where);
    o.obb_center_W = readVec3(j, "obb_center", where);
    const json& q = j.contains("obb_orientation_wxyz") ? j["obb_orientation_wxyz"] : json();
    if (!q.is_array() || q.size() != 4 || !q[0].is_number() || !q[1].is_number() ||
        !q[2].is_number() || !q[3].is_number()) {
      throw Error(where + ": 'obb_orientation_wxyz' must be an array of 4 numbers");
    }
    o.q_W_B = Eigen::Quaterniond(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(),
                                 q[3].get<double>());
    o.obb_extent_m = readVec3(j, "obb_extent", where);
    if (!j.contains("superpoints") || !j["superpoints"].is_array()) {
      throw Error(where + ": 'superpoints' must be an array");
    }
    if (j.contains("evidence")) {
      const json& e = j["evidence"];
      const std::string at = where + ": evidence";
      o.evidence.area_m2 = static_cast<float>(readNumber<double>(e, "area_m2", at));
      o.evidence.support = static_cast<float>(readNumber<double>(e, "support", at));
      o.evidence.class_share = static_cast<float>(readNumber<double>(e, "class_share", at));
    }
    for (const json& s : j["superpoints"]) {
      if (!s.is_number_integer()) throw Error(where + ": 'superpoints' must hold integers");
      o.superpoints.push_back(s.get<int32_t>());
    }
    objects.push_back(std::move(o));
  }
  return objects;
}

size_t keepObjectsOnMesh(const std::vector<int32_t>& mesh_instance,
                         std::vector<MappedObject>* objects) {
  const std::set<int32_t> on_mesh(mesh_instance.begin(), mesh_instance.end());
  const size_t before = objects->size();
  objects->erase(std::remove_if(objects->begin(), objects->end(),
                                [&](const MappedObject& o) { return !on_mesh.count(o.id); }),
                 objects->end());
  return before - objects->size();
}

}  // namespace panmap
