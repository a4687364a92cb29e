#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <nanoflann.hpp>

namespace panmap {

/// Nearest-neighbour queries over a fixed set of 3D points (a k-d tree from nanoflann, a
/// header-only library). The points must outlive the index.
class NearestPointIndex {
 public:
  /// Builds the tree over `points`.
  explicit NearestPointIndex(const std::vector<Eigen::Vector3f>* points)
      : cloud_{points}, tree_(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    tree_.buildIndex();
  }

  /// Index of the point nearest to `query`, or -1 when the set is empty.
  int64_t nearest(const Eigen::Vector3f& query) const {
    if (cloud_.points->empty()) return -1;
    uint32_t index = 0;
    float dist2 = 0.0f;
    if (tree_.knnSearch(query.data(), 1, &index, &dist2) == 0) return -1;
    return index;
  }

 private:
  struct Cloud {
    const std::vector<Eigen::Vector3f>* points;
    size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i][static_cast<int>(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>,
                                                   Cloud, 3, uint32_t>;
  Cloud cloud_;
  Tree tree_;
};

}  // namespace panmap
