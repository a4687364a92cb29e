// clusterByAffinity on hand-made link lists: joins add the links of the two clusters, so a third
// vertex that neither reached alone can join their union, and links to it follow the join.
#include <algorithm>
#include <random>
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

/// Average linkage the plain way: every pair of clusters re-evaluated after every join, the best
/// join taken first (highest affinity, then larger same, then smaller first and second member).
std::vector<int> referenceClusters(int n,
                                   const std::vector<std::tuple<int, int, double, double>>& rows,
                                   std::vector<double> observed, double join_affinity,
                                   double min_coverage) {
  std::vector<int> root(n);
  for (int i = 0; i < n; ++i) root[i] = i;
  while (true) {
    // Evidence between clusters, summed over their members' links.
    std::vector<std::vector<LinkEvidence>> sum(n, std::vector<LinkEvidence>(n));
    for (const auto& [a, b, same, apart] : rows) {
      const int x = std::min(root[a], root[b]), y = std::max(root[a], root[b]);
      if (x == y) continue;
      sum[x][y].same += same;
      sum[x][y].apart += apart;
    }
    bool found = false;
    std::tuple<double, double, int, int> best;
    for (int x = 0; x < n; ++x) {
      for (int y = x + 1; y < n; ++y) {
        const LinkEvidence& link = sum[x][y];
        if (!(link.same > 0.0)) continue;
        const double affinity = link.same / (link.same + link.apart);
        if (affinity < join_affinity) continue;
        if (link.same < min_coverage * std::min(observed[x], observed[y])) continue;
        const auto key = std::make_tuple(affinity, link.same, -x, -y);
        if (!found || key > std::make_tuple(std::get<0>(best), std::get<1>(best),
                                            -std::get<2>(best), -std::get<3>(best))) {
          best = std::make_tuple(affinity, link.same, x, y);
          found = true;
        }
      }
    }
    if (!found) return root;
    const int x = std::get<2>(best), y = std::get<3>(best);
    observed[x] += observed[y];
    for (int& r : root) {
      if (r == y) r = x;
    }
  }
}

TEST(AffinityClustering, JoinsInTheOrderOfThePlainAlgorithm) {
  // Random graphs with values on a coarse grid, so that equal affinities and ties are common.
  std::mt19937 rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 3 + static_cast<int>(rng() % 14);
    std::vector<std::tuple<int, int, double, double>> rows;
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) {
        if (rng() % 3 != 0) continue;
        rows.emplace_back(a, b, static_cast<double>(rng() % 4), static_cast<double>(rng() % 3));
      }
    }
    std::vector<double> observed(n);
    for (double& o : observed) o = static_cast<double>(1 + rng() % 6);
    EXPECT_EQ(clusterByAffinity(linksOf(n, rows), observed, 0.5, 0.3),
              referenceClusters(n, rows, observed, 0.5, 0.3))
        << "trial " << trial;
  }
}

TEST(AffinityClustering, LinksOfPairsListsBothDirectionsInOrder) {
  const std::vector<Links> links = internal::linksOf(
      4, std::vector<LinkPair>{{0, 2, {1.0, 0.5}}, {0, 3, {2.0, 0.0}}, {1, 2, {3.0, 1.0}}});
  ASSERT_EQ(links.size(), 4u);
  EXPECT_EQ(links[0].size(), 2u);
  EXPECT_EQ(links[1].size(), 1u);
  EXPECT_EQ(links[2].size(), 2u);
  EXPECT_EQ(links[3].size(), 1u);
  EXPECT_EQ(links[2].begin()->first, 0);  // ascending: 0, then 1
  EXPECT_EQ(links[2].at(1).same, 3.0);
  EXPECT_EQ(links[3].at(0).same, 2.0);
  EXPECT_EQ(links[0].at(2).apart, 0.5);
}

TEST(AffinityClustering, NoLinksLeaveEveryVertexAlone) {
  const std::vector<int> root = clusterByAffinity(std::vector<Links>(3), {1.0, 1.0, 1.0}, 0.5, 0.5);
  EXPECT_EQ(root, (std::vector<int>{0, 1, 2}));
}

}  // namespace
}  // namespace internal
}  // namespace panmap
