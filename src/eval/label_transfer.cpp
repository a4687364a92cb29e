#include "panmap/eval/label_transfer.h"

#include <cmath>
#include <limits>

#include "panmap/core/error.h"
#include "panmap/core/nearest_point.h"

namespace panmap {
namespace {

int32_t labelOr0(const std::vector<int32_t>& labels, size_t i) {
  return labels.empty() ? 0 : labels[i];
}

}  // namespace

TransferredLabels transferLabels(const LabelledMesh& predicted,
                                 const std::vector<Eigen::Vector3f>& gt_vertices,
                                 double max_distance_m) {
  if (!(max_distance_m >= 0.0)) {
    throw Error("transferLabels: max_distance_m must be >= 0, got " +
                std::to_string(max_distance_m));
  }
  const std::string problem = predicted.check();
  if (!problem.empty()) throw Error("transferLabels: predicted mesh: " + problem);

  TransferredLabels out;
  out.semantic.assign(gt_vertices.size(), 0);
  out.instance.assign(gt_vertices.size(), 0);
  out.superpoint.assign(gt_vertices.size(), 0);
  out.reached.assign(gt_vertices.size(), 0);
  out.distance_m.assign(gt_vertices.size(), std::numeric_limits<float>::infinity());
  if (predicted.vertices.empty() || gt_vertices.empty()) return out;

  const NearestPointIndex tree(&predicted.vertices);
  for (size_t g = 0; g < gt_vertices.size(); ++g) {
    const int64_t found = tree.nearest(gt_vertices[g]);
    if (found < 0) continue;
    const auto index = static_cast<size_t>(found);
    // The radius test in double on the original coordinates, so 4.9 cm / 5.1 cm are exact.
    const double d =
        (predicted.vertices[index].cast<double>() - gt_vertices[g].cast<double>()).norm();
    out.distance_m[g] = static_cast<float>(d);
    if (d > max_distance_m) continue;
    out.semantic[g] = labelOr0(predicted.semantic, index);
    out.instance[g] = labelOr0(predicted.instance, index);
    out.superpoint[g] = labelOr0(predicted.superpoint, index);
    out.reached[g] = 1;
    ++out.num_transferred;
  }
  return out;
}

}  // namespace panmap
