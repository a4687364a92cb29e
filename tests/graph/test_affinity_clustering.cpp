// clusterByAffinity on hand-made link lists: joins add the links of the two clusters, so a third
// vertex that neither reached alone can join their union, and links to it follow the join.
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/graph/internal/affinity_clustering.h"

namespace panmap {
namespace internal {
namespace {

/// Symmetric link lists for n vertices from (a, b, same, apart) rows.
std::vector<Links> linksOf(int n, const std::vector<std::tuple<int, int, double, double>>& rows) {
  std::vector<Links> links(n);
  for (const auto& [a, b, same, apart] : rows) {
    links[a][b] = LinkEvidence{same, apart};
    links[b][a] = LinkEvidence{same, apart};
  }
  return links;
}

TEST(AffinityClustering, AJoinAddsTheLinksBothClustersHadToAThird) {
  // 0-1 join first (same 10, observed 10 each). Vertex 2 (observed 4) has same 1.5 to each:
  // below min_coverage 0.5 * 4 = 2 alone, 3.0 >= 2 once the links add up.
  const auto links = linksOf(3, {{0, 1, 10.0, 0.0}, {0, 2, 1.5, 0.0}, {1, 2, 1.5, 0.0}});
  const std::vector<int> root = clusterByAffinity(links, {10.0, 10.0, 4.0}, 0.6, 0.5);
  EXPECT_EQ(root, (std::vector<int>{0, 0, 0}));
}

TEST(AffinityClustering, ApartEvidenceAddsUpToo) {
  // 2's links: same 1.5 / apart 0 to vertex 0 and same 1.5 / apart 3 to vertex 1. Summed,
  // affinity 3 / 6 = 0.5, under join_affinity 0.6, so 2 stays apart from the union of 0 and 1.
  const auto links = linksOf(3, {{0, 1, 10.0, 0.0}, {0, 2, 1.5, 0.0}, {1, 2, 1.5, 3.0}});
  const std::vector<int> root = clusterByAffinity(links, {10.0, 10.0, 2.0}, 0.6, 0.5);
  EXPECT_EQ(root, (std::vector<int>{0, 0, 2}));
}

TEST(AffinityClustering, LinksFollowAJoinToTheClustersFirstMember) {
  // 1-2 join (the best link), then 0 joins their cluster through its link to 2 alone, which
  // after the join is the cluster's link (named by vertex 1); 3 has no link and stays alone.
  const auto links = linksOf(4, {{1, 2, 9.0, 0.0}, {0, 2, 3.0, 1.0}});
  const std::vector<int> root = clusterByAffinity(links, {3.0, 9.0, 9.0, 1.0}, 0.6, 0.5);
  EXPECT_EQ(root, (std::vector<int>{0, 0, 0, 3}));
}

TEST(AffinityClustering, NoLinksLeaveEveryVertexAlone) {
  const std::vector<int> root = clusterByAffinity(std::vector<Links>(3), {1.0, 1.0, 1.0}, 0.5, 0.5);
  EXPECT_EQ(root, (std::vector<int>{0, 1, 2}));
}

}  // namespace
}  // namespace internal
}  // namespace panmap
