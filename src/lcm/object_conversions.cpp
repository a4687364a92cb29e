#include "panmap/lcm/object_conversions.h"

#include <cmath>
#include <string>

#include "panmap/core/error.h"

namespace panmap {
namespace {

void put3(const Eigen::Vector3d& v, double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = v[k];
}

Eigen::Vector3d get3(const double in[3]) { return Eigen::Vector3d(in[0], in[1], in[2]); }

}  // namespace

object_list_t toMessage(const std::vector<MappedObject>& objects, int64_t utime) {
  object_list_t msg;
  msg.utime = utime;
  msg.num_objects = static_cast<int32_t>(objects.size());
  msg.objects.reserve(objects.size());
  for (const MappedObject& o : objects) {
    object_t m;
    m.id = o.id;
    m.category = o.class_id;
    m.confidence = o.confidence;
    m.area_m2 = o.evidence.area_m2;
    m.support = o.evidence.support;
    m.class_share = o.evidence.class_share;
    m.num_voxels = o.num_voxels;
    put3(o.centroid_W, m.centroid);
    put3(o.aabb_min_W, m.aabb_min);
    put3(o.aabb_max_W, m.aabb_max);
    put3(o.obb_center_W, m.obb_center);
    m.obb_orientation[0] = o.q_W_B.w();
    m.obb_orientation[1] = o.q_W_B.x();
    m.obb_orientation[2] = o.q_W_B.y();
    m.obb_orientation[3] = o.q_W_B.z();
    put3(o.obb_extent_m, m.obb_extent);
    m.num_superpoints = static_cast<int32_t>(o.superpoints.size());
    m.superpoints = o.superpoints;
    msg.objects.push_back(std::move(m));
  }
  return msg;
}

std::vector<MappedObject> fromMessage(const object_list_t& msg) {
  if (msg.num_objects < 0 || msg.objects.size() != static_cast<size_t>(msg.num_objects)) {
    throw Error("objects message: num_objects disagrees with the array");
  }
  std::vector<MappedObject> objects;
  objects.reserve(msg.objects.size());
  for (const object_t& m : msg.objects) {
    const std::string where = "objects message: object " + std::to_string(m.id);
    if (m.id <= 0) throw Error(where + ": id must be positive");
    if (m.num_superpoints < 0 || m.superpoints.size() != static_cast<size_t>(m.num_superpoints)) {
      throw Error(where + ": num_superpoints disagrees with the array");
    }
    MappedObject o;
    o.id = m.id;
    o.class_id = m.category;
    o.confidence = m.confidence;
    o.evidence = {m.area_m2, m.support, m.class_share};
    o.num_voxels = m.num_voxels;
    o.centroid_W = get3(m.centroid);
    o.aabb_min_W = get3(m.aabb_min);
    o.aabb_max_W = get3(m.aabb_max);
    o.obb_center_W = get3(m.obb_center);
    o.q_W_B = Eigen::Quaterniond(m.obb_orientation[0], m.obb_orientation[1], m.obb_orientation[2],
                                 m.obb_orientation[3]);
    if (!o.q_W_B.coeffs().allFinite() || std::abs(o.q_W_B.norm() - 1.0) > 1e-6) {
      throw Error(where + ": obb_orientation is not a unit quaternion");
    }
    o.obb_extent_m = get3(m.obb_extent);
    o.superpoints = m.superpoints;
    objects.push_back(std::move(o));
  }
  return objects;
}

}  // namespace panmap
