// compareOccupancy: cell-by-cell agreement of two trees, pruned leaves counted cell by cell.
#include <gtest/gtest.h>

#include <octomap/OcTree.h>

#include "panmap/core/error.h"
#include "panmap/occupancy/occupancy_query.h"

namespace panmap {
namespace {

// Marks every cell of an n x n x n cube from `origin` free, then `occupied` cells occupied.
void fill(octomap::OcTree* tree, int n, const std::vector<octomap::point3d>& occupied) {
  const double r = tree->getResolution();
  for (int x = 0; x < n; ++x) {
    for (int y = 0; y < n; ++y) {
      for (int z = 0; z < n; ++z) {
        tree->updateNode(octomap::point3d((x + 0.5) * r, (y + 0.5) * r, (z + 0.5) * r), false);
      }
    }
  }
  for (const octomap::point3d& p : occupied) tree->updateNode(p, true);
  tree->updateInnerOccupancy();
  tree->prune();  // free cubes collapse into coarser leaves: still counted per cell
}

TEST(CompareOccupancy, CountsCellsKnownInBothAndTheirAgreement) {
  octomap::OcTree a(0.1), b(0.1);
  fill(&a, 8, {octomap::point3d(0.05f, 0.05f, 0.05f)});
  // b: one more occupied cell, and one more row of known cells beyond a's cube.
  fill(&b, 8, {octomap::point3d(0.05f, 0.05f, 0.05f), octomap::point3d(0.35f, 0.45f, 0.55f)});
  for (int y = 0; y < 8; ++y) b.updateNode(octomap::point3d(0.85f, 0.1f * y + 0.05f, 0.05f), false);
  b.prune();
  const OccupancyAgreement agreement = compareOccupancy(a, b);
  EXPECT_EQ(agreement.known_in_both, 512u);
  EXPECT_EQ(agreement.agree, 511u);
  EXPECT_EQ(agreement.only_in_a, 0u);
  EXPECT_EQ(agreement.only_in_b, 8u);
  EXPECT_DOUBLE_EQ(agreement.agreement(), 511.0 / 512.0);
  const OccupancyAgreement same = compareOccupancy(a, a);
  EXPECT_EQ(same.known_in_both, 512u);
  EXPECT_EQ(same.agree, 512u);

  octomap::OcTree coarse(0.2);
  EXPECT_THROW(compareOccupancy(a, coarse), Error);
}

}  // namespace
}  // namespace panmap
