#include "panmap/mapper/outputs.h"

#include <chrono>
#include <filesystem>
#include <functional>
#include <iterator>
#include <set>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/objects.h"
#include "panmap/mesh/mesh_export.h"
#include "panmap/render/overview.h"

namespace panmap {

namespace {

// The vertex colours of `ids` under `colour`; a mesh without those labels keeps its colours
// (black without colours either).
OverviewColouring byLabel(const LabelledMesh& mesh, Rgb8 (*colour)(int32_t),
                          const std::vector<int32_t>& ids) {
  if (!ids.empty()) return [colour, &ids](size_t v) { return colour(ids[v]); };
  if (!mesh.colors.empty()) return [&mesh](size_t v) { return mesh.colors[v]; };
  return [](size_t) { return Rgb8{0, 0, 0}; };
}

constexpr const char* kSnapshotFiles[] = {"snapshot_semantic.png", "snapshot_instance.png",
                                          "snapshot_superpoint.png", "snapshot_color.png"};

// The four overview pictures, rasterised once (a building's mesh is 14 M faces).
void writeSnapshots(const std::string& dir, const LabelledMesh& mesh, OutputSummary* summary) {
  const std::vector<std::string> names(std::begin(kSnapshotFiles), std::end(kSnapshotFiles));
  const std::vector<ColorImage> pictures = renderOverviews(
      mesh, {byLabel(mesh, &semanticColor, mesh.semantic), byLabel(mesh, &idColor, mesh.instance),
             byLabel(mesh, &idColor, mesh.superpoint), vertexColours(mesh)});
  for (size_t i = 0; i < names.size(); ++i) {
    const std::vector<uint8_t> png = encodePng(pictures[i]);
    writeFileAtomically(dir + "/" + names[i], png.data(), png.size());
    summary->files.push_back(names[i]);
  }
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
  // The map first: it is what hours of mapping made, and every other output can be made again
  // from it (--load MAP --export-only). A later output that cannot be written (a full disk, a
  // folder in its place) is named at the end, after the others are written.
  mapper->save(dir + "/map.panmap");
  summary.files.push_back("map.panmap");
  step("map.panmap");
  // A failed output's files are removed: a PLY cut off by a full disk still claims all its
  // vertices in its header, and an empty occupancy.bt reads as "not an OctoMap file".
  auto attempt = [&](std::initializer_list<const char*> names, const std::function<void()>& write) {
    try {
      write();
    } catch (const std::exception& e) {
      summary.failed.push_back(e.what());
      for (const char* name : names) {
        const std::string path = dir + "/" + name;
        std::error_code ignored;
        if (std::filesystem::is_regular_file(path, ignored)) std::filesystem::remove(path, ignored);
      }
    }
  };
  std::vector<int32_t> mesh_instances;  // of mesh_instance.ply: objects.json lists these only
  {
    // The welded mesh lives only while the meshes and snapshots are written: the later steps
    // (the occupancy tree, the map file) would otherwise hold it on top of theirs (issue 23:
    // the 2 cm building's export peaked during the occupancy tree, 0.4 GB of it this mesh).
    const LabelledMesh mesh =
        options.final_export ? mapper->extractFinalMesh(labels) : mapper->extractMesh(labels);
    summary.mesh_vertices = mesh.numVertices();
    summary.mesh_faces = mesh.numFaces();
    summary.mesh_area_m2 = mesh.surfaceArea();
    std::set<int32_t> instances;
    for (int32_t id : mesh.instance) {
      if (id > 0) instances.insert(id);
    }
    mesh_instances.assign(instances.begin(), instances.end());
    summary.instances_in_mesh = instances.size();
    step("mesh extraction");

    attempt({kSemanticMeshFile, kInstanceMeshFile, kSuperpointMeshFile}, [&] {
      writeLabelledMeshes(dir, mesh);
      summary.files.insert(summary.files.end(),
                           {kSemanticMeshFile, kInstanceMeshFile, kSuperpointMeshFile});
    });
    step("meshes");
    if (options.snapshots && !mesh.faces.empty()) {
      attempt({kSnapshotFiles[0], kSnapshotFiles[1], kSnapshotFiles[2], kSnapshotFiles[3]},
              [&] { writeSnapshots(dir, mesh, &summary); });
      step("snapshots");
    } else {
      // Pictures of an earlier run in the same folder would pass for this map's.
      for (const char* name : kSnapshotFiles) {
        std::error_code ignored;
        std::filesystem::remove(dir + "/" + name, ignored);
      }
    }
  }
  attempt({"objects.json"}, [&] {
    std::vector<MappedObject> objects = computeObjects(*mapper, labels, optimiser.objects);
    summary.objects_off_mesh = keepObjectsOnMesh(mesh_instances, &objects);
    writeObjectsJson(dir + "/objects.json", objects, options.utime);
    summary.objects = objects.size();
    summary.object_list = objects;
    summary.files.push_back("objects.json");
  });
  step("objects.json");
  if (mapper->occupancy()) {
    attempt({"occupancy.bt"}, [&] {
      mapper->occupancy()->writeBt(dir + "/occupancy.bt");
      summary.files.push_back("occupancy.bt");
    });
    step("occupancy.bt");
  }
  attempt({"trajectory.txt"}, [&] {
    writeTumTrajectory(dir + "/trajectory.txt", mapper->trajectory());
    summary.files.push_back("trajectory.txt");
  });
  step("trajectory.txt");
  // The exact parameters the outputs were made with (a loaded map brings its own).
  attempt({"config.yaml"}, [&] {
    writeFileAtomically(dir + "/config.yaml",
                        configToYaml(PanmapConfig{mapper->config(), optimiser, options.sync}));
    summary.files.push_back("config.yaml");
  });
  step("config.yaml");
  return summary;
}

void requireAllWritten(const OutputSummary& summary, const std::string& dir) {
  const std::vector<std::string>& failed = summary.failed;
  if (failed.empty()) return;
  throw Error(failed.front() +
              (failed.size() > 1 ? " (and " + std::to_string(failed.size() - 1) + " more)"
                                 : std::string()) +
              "; " + dir + "/map.panmap and the other outputs were written");
}

}  // namespace panmap
