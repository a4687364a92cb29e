// The final optimisation of a saved map, as panmap-mapper runs it at the end of a session:
// the super-point graph of the live super-points (Mapper::graph), then the solve (optimise).
// Prints each run, the median of each over --repeats runs, and a digest of the labels (a
// fingerprint of every super-point's id, class and instance) so that a faster build can be checked
// for equal output. With --mesh, also the whole labelled mesh from the block meshes a live
// session keeps (Mapper::extractMesh after a first call: welding and labelling, one thread).
// Also the size of the PANMAP_GRAPH message the live mapper sends for each optimisation.
//   panmap-bench-final MAP.panmap [--repeats 5] [--mesh]

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "panmap/core/fingerprint.h"
#include "panmap/core/memory_policy.h"
#include "panmap/core/process_memory.h"
#include "panmap/graph/optimiser.h"
#include "panmap/lcm/graph_conversions.h"
#include "panmap/mapper/mapper.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// Fingerprint of the labels, in id order.
uint64_t labelsDigest(const panmap::GraphLabels& labels) {
  panmap::Fingerprint f;
  for (const auto& [id, cls] : labels.semantic) {
    const auto it = labels.instance.find(id);
    const int64_t values[3] = {id, cls, it == labels.instance.end() ? -1 : it->second};
    f.add(values, sizeof(values));
  }
  return f.value();
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Time the final optimisation (graph, then solve) of a saved map."};
  std::string path;
  int repeats = 5;
  app.add_option("map", path, "map.panmap written by panmap-mapper")->required();
  app.add_option("--repeats", repeats, "runs to take the median of")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  bool mesh = false;
  app.add_flag("--mesh", mesh,
               "also time the whole labelled mesh from the kept block meshes (welding and "
               "labelling on one thread)");
  CLI11_PARSE(app, argc, argv);
  // As panmap-mapper: the heap on huge pages where the kernel gives them on request, and buffers
  // of 4 MiB and more fresh pages every time, which the final optimisation's timing includes.
  panmap::applyMemoryPolicy(argv);
  try {
    const auto mapper = panmap::Mapper::load(path);
    std::vector<double> graph_ms, solve_ms;
    size_t vertices = 0, edges = 0;
    uint64_t digest = 0;
    for (int r = 0; r < repeats; ++r) {
      const long faults_before = panmap::minorPageFaults();
      auto start = std::chrono::steady_clock::now();
      const panmap::SuperpointGraph graph = mapper->graph();
      graph_ms.push_back(msSince(start));
      const long faults_graph = panmap::minorPageFaults();
      start = std::chrono::steady_clock::now();
      const panmap::GraphLabels labels = panmap::optimise(graph, panmap::OptimiserConfig());
      solve_ms.push_back(msSince(start));
      const long faults_solve = panmap::minorPageFaults();
      digest = labelsDigest(labels);
      vertices = graph.vertices.size();
      edges = graph.edges.size();
      std::fprintf(stderr,
                   "  run %d/%d: graph %.1f ms, solve %.1f ms; pages touched first: graph %ld, "
                   "solve %ld\n",
                   r + 1, repeats, graph_ms.back(), solve_ms.back(), faults_graph - faults_before,
                   faults_solve - faults_graph);
    }
    std::printf(
        "%s: %zu blocks, %zu vertices, %zu edges; median of %d: graph %.1f ms, solve %.1f ms, "
        "total %.1f ms; labels %016llx\n",
        path.c_str(), mapper->map().numBlocks(), vertices, edges, repeats, median(graph_ms),
        median(solve_ms), median(graph_ms) + median(solve_ms),
        static_cast<unsigned long long>(digest));
    // What the live mapper publishes on PANMAP_GRAPH for each optimisation request.
    const size_t message_bytes =
        static_cast<size_t>(panmap::toMessage(mapper->graph(), 0, 0).getEncodedSize());
    std::printf("%s: PANMAP_GRAPH message %zu bytes (%.2f MB)\n", path.c_str(), message_bytes,
                static_cast<double>(message_bytes) / 1e6);
    if (mesh) {
      size_t mesh_vertices = mapper->extractMesh().numVertices();  // meshes every block once
      std::vector<double> mesh_ms;
      for (int r = 0; r < repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        mesh_vertices = mapper->extractMesh().numVertices();
        mesh_ms.push_back(msSince(start));
      }
      std::printf("%s: whole mesh from the kept block meshes, %zu vertices: median of %d %.1f ms\n",
                  path.c_str(), mesh_vertices, repeats, median(mesh_ms));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-final: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
