#include "panmap/graph/object_confidence.h"

#include <algorithm>
#include <cmath>

namespace panmap {

float objectConfidence(const InstanceEvidence& e, double voxel_size_m,
                       const OptimiserConfig::Objects& model) {
  // Floors keep the logarithms finite for an instance without area or observations.
  const double area = std::max(static_cast<double>(e.voxels) * voxel_size_m * voxel_size_m, 1e-4);
  const double support = std::max(e.support(), 1e-2);
  const double z = model.bias + model.area * std::log10(area) + model.support * std::log2(support) +
                   model.share * e.classShare();
  return static_cast<float>(1.0 / (1.0 + std::exp(-z)));
}

ObjectEvidence objectEvidence(const InstanceEvidence& e, double voxel_size_m) {
  ObjectEvidence ev;
  ev.area_m2 = static_cast<float>(static_cast<double>(e.voxels) * voxel_size_m * voxel_size_m);
  ev.support = static_cast<float>(e.support());
  ev.class_share = static_cast<float>(e.classShare());
  return ev;
}

}  // namespace panmap
