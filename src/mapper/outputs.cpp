#include "panmap/mapper/outputs.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/objects.h"
#include "panmap/mesh/mesh_export.h"
#include "panmap/sim/overview.h"

namespace panmap {

namespace {

LabelledMesh recoloured(const LabelledMesh& mesh, Rgb8 (*colour)(int32_t),
                        const std::vector<int32_t>& ids) {
  LabelledMesh out = mesh;
  out.colors.resize(mesh.vertices.size());
  for (size_t i = 0; i < ids.size(); ++i) out.colors[i] = colour(ids[i]);
  return out;
}

void writePng(const std::string& dir, const std::string& name, const LabelledMesh& mesh,
              OutputSummary* summary) {
  writeFileBytes(dir + "/" + name, encodePng(renderOverview(mesh)));
  summary->files.push_back(name);
}

}  // namespace

OutputSummary writeOutputs(const std::string& dir, Mapper* mapper, const GraphLabels* labels,
                           const OptimiserConfig& optimiser, const OutputOptions& options) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw Error("cannot create output folder " + dir + ": " + error.message());
  OutputSummary summary;
  auto last = std::chrono::steady_clock::now();
  auto step = [&](const char* name) {
    const auto now = std::chrono::steady_clock::now();
    summary.step_seconds.emplace_back(name, std::chrono::duration<double>(now - last).count());
    last = now;
  };
  const LabelledMesh mesh = mapper->extractMesh(labels);
  summary.mesh_vertices = mesh.numVertices();
  summary.mesh_faces = mesh.numFaces();
  summary.mesh_area_m2 = mesh.surfaceArea();
  std::set<int32_t> instances;
  for (int32_t id : mesh.instance) {
    if (id > 0) instances.insert(id);
  }
  summary.instances_in_mesh = instances.size();
  step("mesh extraction");

  writeLabelledMeshes(dir, mesh);
  summary.files.insert(summary.files.end(),
                       {kSemanticMeshFile, kInstanceMeshFile, kSuperpointMeshFile});
  step("meshes");
  const std::vector<MappedObject> objects = computeObjects(*mapper, labels);
  writeObjectsJson(dir + "/objects.json", objects, options.utime);
  summary.objects = objects.size();
  summary.files.push_back("objects.json");
  step("objects.json");
  if (mapper->occupancy()) {
    mapper->occupancy()->writeBt(dir + "/occupancy.bt");
    summary.files.push_back("occupancy.bt");
    step("occupancy.bt");
  }
  writeTumTrajectory(dir + "/trajectory.txt", mapper->trajectory());
  summary.files.push_back("trajectory.txt");
  step("trajectory.txt");
  mapper->save(dir + "/map.panmap");
  summary.files.push_back("map.panmap");
  step("map.panmap");
  // The exact parameters the outputs were made with (a loaded map brings its own).
  {
    std::ofstream out(dir + "/config.yaml");
    out << configToYaml(PanmapConfig{mapper->config(), optimiser});
    if (!out) throw Error("cannot write " + dir + "/config.yaml");
    summary.files.push_back("config.yaml");
  }
  step("config.yaml");
  if (options.snapshots && !mesh.faces.empty()) {
    writePng(dir, "snapshot_semantic.png", recoloured(mesh, &semanticColor, mesh.semantic),
             &summary);
    writePng(dir, "snapshot_instance.png", recoloured(mesh, &idColor, mesh.instance), &summary);
    writePng(dir, "snapshot_superpoint.png", recoloured(mesh, &idColor, mesh.superpoint), &summary);
    writePng(dir, "snapshot_color.png", mesh, &summary);
    step("snapshots");
  }
  return summary;
}

}  // namespace panmap
