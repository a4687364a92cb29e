// VertexIndex: super-point id -> position in the graph's vertex list, through its table (dense
// ids) and through its search (ids spread far apart, as after a long run forgot most of them).
#include <vector>

#include <gtest/gtest.h>

#include "panmap/graph/internal/graph_check.h"

namespace panmap {
namespace internal {
namespace {

SuperpointGraph graphWithIds(const std::vector<int32_t>& ids) {
  SuperpointGraph graph;
  graph.classes = {1};
  for (int32_t id : ids) {
    GraphVertex v;
    v.id = id;
    graph.vertices.push_back(v);
  }
  return graph;
}

void expectFinds(const std::vector<int32_t>& ids, const std::vector<int32_t>& absent) {
  const SuperpointGraph graph = graphWithIds(ids);
  const VertexIndex index(graph);
  for (size_t i = 0; i < ids.size(); ++i) EXPECT_EQ(index(ids[i]), static_cast<int>(i)) << ids[i];
  for (int32_t id : absent) EXPECT_EQ(index(id), -1) << id;
}

TEST(VertexIndex, DenseIdsAreFoundThroughTheTable) {
  expectFinds({1, 2, 3, 7, 40}, {0, 4, 39, 41, -1, 1 << 30});
}

TEST(VertexIndex, SparseIdsAreFoundThroughTheSearch) {
  // Three vertices, ids up to 2^30: far past 32 slots per vertex.
  expectFinds({5, 100000, 1 << 30}, {0, 4, 6, 99999, 100001, (1 << 30) - 1, -7, INT32_MAX});
}

TEST(VertexIndex, IdsSpreadEvery32AreFound) {
  // 100 vertices, ids every 32 (3,169 < 32 x 100 + 1024: the table side of the line; the
  // answers cannot show which side was taken, only that they are right).
  std::vector<int32_t> ids;
  for (int k = 0; k < 100; ++k) ids.push_back(1 + 32 * k);
  expectFinds(ids, {0, 2, 34, 3170, 3200, 1 << 20});
}

TEST(VertexIndex, AnEmptyGraphFindsNothing) { expectFinds({}, {0, 1, -1}); }

}  // namespace
}  // namespace internal
}  // namespace panmap
