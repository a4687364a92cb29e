// Renderer timing: one 640x480 frame of a ~200k-triangle room on one core (issue target
// <= 30 ms). A tessellated 9 x 7 x 3 m box room with furniture-sized boxes, 5 cm triangles.
#include <benchmark/benchmark.h>

#include "panmap/render/renderer.h"
#include "panmap/sim/procedural_room.h"

namespace {

using panmap::LabelledMesh;

// Axis-aligned box surface split into a grid of cells no larger than edge_m.
void addTessellatedBox(LabelledMesh* mesh, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                       float edge_m, int32_t instance) {
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    const int n1 = std::max(1, static_cast<int>(std::ceil((hi[a1] - lo[a1]) / edge_m)));
    const int n2 = std::max(1, static_cast<int>(std::ceil((hi[a2] - lo[a2]) / edge_m)));
    for (int side = 0; side < 2; ++side) {
      const int base = static_cast<int>(mesh->vertices.size());
      for (int i = 0; i <= n1; ++i) {
        for (int j = 0; j <= n2; ++j) {
          Eigen::Vector3f p;
          p[axis] = side ? hi[axis] : lo[axis];
          p[a1] = lo[a1] + (hi[a1] - lo[a1]) * i / n1;
          p[a2] = lo[a2] + (hi[a2] - lo[a2]) * j / n2;
          mesh->vertices.push_back(p);
          mesh->instance.push_back(instance);
          mesh->semantic.push_back(instance % 40 + 1);
          mesh->colors.push_back(panmap::Rgb8{static_cast<uint8_t>(50 * instance), 120, 200});
        }
      }
      for (int i = 0; i < n1; ++i) {
        for (int j = 0; j < n2; ++j) {
          const int v00 = base + i * (n2 + 1) + j;
          mesh->faces.emplace_back(v00, v00 + n2 + 1, v00 + n2 + 2);
          mesh->faces.emplace_back(v00, v00 + n2 + 2, v00 + 1);
        }
      }
    }
  }
}

LabelledMesh makeRoom() {
  LabelledMesh mesh;
  addTessellatedBox(&mesh, {0, 0, 0}, {9, 7, 3}, 0.05f, 1);
  for (int k = 0; k < 12; ++k) {
    const float x = 0.5f + 0.65f * k;
    addTessellatedBox(&mesh, {x, 0.3f, 0.0f}, {x + 0.5f, 0.9f, 0.4f + 0.1f * k}, 0.05f, k + 2);
  }
  return mesh;
}

void BM_RenderRoom(benchmark::State& state) {
  const LabelledMesh mesh = makeRoom();
  const panmap::MeshRenderer renderer(mesh);
  const panmap::PinholeCamera camera{525.0, 525.0, 319.5, 239.5, 640, 480};
  panmap::RenderedView view;
  int frame = 0;
  for (auto _ : state) {
    // Walk around the room centre looking outwards: every frame sees a different part.
    const double yaw = 0.1 * frame++;
    Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d z(std::cos(yaw), std::sin(yaw), -0.2);
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
    T_W_C.linear().col(0) = x;
    T_W_C.linear().col(2) = z.normalized();
    T_W_C.linear().col(1) = z.normalized().cross(x);
    T_W_C.translation() = Eigen::Vector3d(4.5, 3.5, 1.5);
    renderer.render(camera, T_W_C, &view);
    benchmark::DoNotOptimize(view.depth_m.data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.faces.size());
}
BENCHMARK(BM_RenderRoom)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly();

// The same walk through procedural rooms: seed 4 (216k triangles) and seed 1 (454k).
void BM_RenderProceduralRoom(benchmark::State& state) {
  const panmap::ProceduralRoom room = panmap::generateRoom(static_cast<uint64_t>(state.range(0)));
  const panmap::MeshRenderer renderer(room.mesh);
  const panmap::PinholeCamera camera{525.0, 525.0, 319.5, 239.5, 640, 480};
  const Eigen::AlignedBox3f box = [&] {
    Eigen::AlignedBox3f b;
    for (const auto& v : room.mesh.vertices) b.extend(v);
    return b;
  }();
  panmap::RenderedView view;
  int frame = 0;
  for (auto _ : state) {
    const double yaw = 0.1 * frame++;
    Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d z = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), -0.3).normalized();
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
    T_W_C.linear().col(0) = x;
    T_W_C.linear().col(1) = z.cross(x);
    T_W_C.linear().col(2) = z;
    T_W_C.translation() = box.center().cast<double>();
    T_W_C.translation().z() = 1.5;
    renderer.render(camera, T_W_C, &view);
    benchmark::DoNotOptimize(view.depth_m.data());
  }
  state.counters["triangles"] = static_cast<double>(room.mesh.faces.size());
}
BENCHMARK(BM_RenderProceduralRoom)
    ->Arg(4)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly();

}  // namespace

BENCHMARK_MAIN();
