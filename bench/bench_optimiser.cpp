// The final optimisation (alpha-beta swap + instance refinement) on random super-point graphs
// of room scale: 5,000 super-points, 20 classes, 50,000 edges (mostly between spatially near
// super-points), 1-3 classes' scores per super-point, 1-2 classes per edge.
//
// Super-points belong to 400 random objects (the nearest object centre in a 20 x 20 x 3 m room);
// an edge inside an object has a high confidence for the object's class, an edge between
// objects a low one. Two noise levels of the scores:
//  - typical: the object's class dominates; 0-2 confusion classes (half of them the class of a
//    neighbouring object) at 5-50% of it; 8% of the super-points are mislabelled (a confusion
//    exceeds the true class); 5% of the edges join random super-points.
//  - noisy: 15% of the super-points have no score for their object's class, and 0-2 random
//    classes score 0.5-20 against 5-50 for the true class (about a fifth of the argmax labels
//    are wrong); 10% random edges. Much more work for the swap (hundreds of accepted moves).
#include <algorithm>
#include <set>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "panmap/core/random.h"
#include "panmap/graph/optimiser.h"

namespace {

constexpr int kVertices = 5000;
constexpr int kClasses = 20;
constexpr int kEdges = 50000;
constexpr int kObjects = 400;
constexpr int kNeighbours = 24;

panmap::SuperpointGraph makeGraph(bool noisy) {
  panmap::Rng rng(2024);
  panmap::SuperpointGraph graph;
  for (int c = 1; c <= kClasses; ++c) graph.classes.push_back(c);
  graph.background = {1, 2, 3};  // wall, floor, ceiling-like stuff

  // Objects: a centre and a class; each super-point belongs to the nearest object.
  std::vector<Eigen::Vector3d> centres(kObjects);
  std::vector<int32_t> object_class(kObjects);
  for (int o = 0; o < kObjects; ++o) {
    centres[o] = {rng.uniform(0, 20), rng.uniform(0, 20), rng.uniform(0, 3)};
    object_class[o] = 1 + static_cast<int32_t>(rng.below(kClasses));
  }
  std::vector<int> object(kVertices);
  for (int i = 0; i < kVertices; ++i) {
    panmap::GraphVertex v;
    v.id = i + 1;
    v.num_voxels = 50 + static_cast<int32_t>(rng.below(500));
    v.centroid = {rng.uniform(0, 20), rng.uniform(0, 20), rng.uniform(0, 3)};
    int best = 0;
    for (int o = 1; o < kObjects; ++o) {
      if ((centres[o] - v.centroid).squaredNorm() < (centres[best] - v.centroid).squaredNorm()) {
        best = o;
      }
    }
    object[i] = best;
    v.semantic = object_class[best];
    v.instance = rng.bernoulli(0.9) ? best + 1 : 0;
    graph.vertices.push_back(v);
  }

  // Nearest neighbours (brute force, once).
  std::vector<std::vector<int>> nearest(kVertices);
  std::vector<std::pair<double, int>> dist(kVertices);
  for (int i = 0; i < kVertices; ++i) {
    for (int j = 0; j < kVertices; ++j) {
      dist[j] = {(graph.vertices[i].centroid - graph.vertices[j].centroid).squaredNorm(), j};
    }
    std::partial_sort(dist.begin(), dist.begin() + kNeighbours + 1, dist.end());
    for (int k = 1; k <= kNeighbours; ++k) nearest[i].push_back(dist[k].second);
  }

  // Scores.
  for (int i = 0; i < kVertices; ++i) {
    panmap::GraphVertex& v = graph.vertices[i];
    const int32_t c = v.semantic;
    const int confusions = static_cast<int>(rng.below(3));
    if (noisy) {
      if (rng.bernoulli(0.85)) v.scores[c] = rng.uniform(5.0, 50.0);
      for (int k = 0; k < confusions || v.scores.empty(); ++k) {
        v.scores[1 + static_cast<int32_t>(rng.below(kClasses))] += rng.uniform(0.5, 20.0);
      }
      continue;
    }
    const double main = rng.uniform(10.0, 50.0);
    v.scores[c] = main;
    const bool mislabelled = rng.bernoulli(0.08);
    for (int k = 0; k < std::max(confusions, mislabelled ? 1 : 0); ++k) {
      const int32_t other = rng.bernoulli(0.5)
                                ? graph.vertices[nearest[i][rng.below(kNeighbours)]].semantic
                                : 1 + static_cast<int32_t>(rng.below(kClasses));
      if (other == c) continue;
      v.scores[other] =
          main * (mislabelled && k == 0 ? rng.uniform(1.05, 2.0) : rng.uniform(0.05, 0.5));
    }
  }

  // Edges: round robin over each super-point's nearest neighbours, then random pairs.
  const int near_edges = noisy ? kEdges * 9 / 10 : kEdges * 19 / 20;
  std::set<std::pair<int, int>> pairs;
  for (int r = 0; r < kNeighbours && static_cast<int>(pairs.size()) < near_edges; ++r) {
    for (int i = 0; i < kVertices && static_cast<int>(pairs.size()) < near_edges; ++i) {
      const int j = nearest[i][r];
      pairs.insert({std::min(i, j), std::max(i, j)});
    }
  }
  while (static_cast<int>(pairs.size()) < kEdges) {
    const int i = static_cast<int>(rng.below(kVertices));
    const int j = static_cast<int>(rng.below(kVertices));
    if (i != j) pairs.insert({std::min(i, j), std::max(i, j)});
  }
  for (const auto& [i, j] : pairs) {
    panmap::GraphEdge e;
    e.a = i + 1;
    e.b = j + 1;
    const bool same = object[i] == object[j];
    const int32_t c = graph.vertices[rng.bernoulli(0.5) ? i : j].semantic;
    e.confidences[c] = same ? rng.uniform(1.0, 20.0) : rng.uniform(0.1, 3.0);
    if (rng.bernoulli(0.3)) {
      e.confidences[1 + static_cast<int32_t>(rng.below(kClasses))] += rng.uniform(0.1, 3.0);
    }
    graph.edges.push_back(e);
  }
  return graph;
}

void BM_Optimise(benchmark::State& state, bool noisy, bool regularise, bool refine) {
  const panmap::SuperpointGraph graph = makeGraph(noisy);
  panmap::OptimiserConfig config;
  config.regularise = regularise;
  config.refine = refine;
  int64_t relabelled = 0;
  for (auto _ : state) {
    const panmap::GraphLabels labels = panmap::optimise(graph, config);
    relabelled = 0;
    for (const panmap::GraphVertex& v : graph.vertices) {
      relabelled += labels.semantic.at(v.id) != v.semantic;
    }
    benchmark::DoNotOptimize(labels);
  }
  // Super-points whose final class differs from their object's class.
  state.counters["wrong_class"] = static_cast<double>(relabelled);
}

#define PANMAP_OPTIMISE_BENCHMARK(name, ...)        \
  BENCHMARK_CAPTURE(BM_Optimise, name, __VA_ARGS__) \
      ->Unit(benchmark::kMillisecond)               \
      ->Repetitions(9)                              \
      ->ReportAggregatesOnly(true)

PANMAP_OPTIMISE_BENCHMARK(typical, false, true, true);
PANMAP_OPTIMISE_BENCHMARK(typical_argmax_refine, false, false, true);
PANMAP_OPTIMISE_BENCHMARK(noisy, true, true, true);

}  // namespace

BENCHMARK_MAIN();
