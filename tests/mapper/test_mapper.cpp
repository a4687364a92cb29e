#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <zlib.h>

#include "box_scene.h"
#include "panmap/core/error.h"
#include "panmap/graph/optimiser.h"
#include "panmap/io/image_codec.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mapper/outputs.h"
#include "panmap/mesh/marching_cubes.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/segmenter_noise.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// Majority super-point of the mesh vertices inside a box, and the share of its vertices.
std::pair<int32_t, double> dominantSuperpoint(const LabelledMesh& mesh,
                                              const Eigen::AlignedBox3f& box) {
  std::map<int32_t, int> counts;
  int n = 0;
  for (size_t v = 0; v < mesh.numVertices(); ++v) {
    if (!box.contains(mesh.vertices[v])) continue;
    ++counts[mesh.superpoint[v]];
    ++n;
  }
  std::pair<int32_t, int> best{0, 0};
  for (const auto& [id, c] : counts) {
    if (c > best.second) best = {id, c};
  }
  return {best.first, n ? static_cast<double>(best.second) / n : 0.0};
}

TEST_F(BoxScene, TouchingBoxesOfDifferentClassesStaySeparate) {
  auto mapper = run(config(), 10);
  const LabelledMesh mesh = mapper->extractMesh();
  // The cameras (1.5 m high) see the cabinet's top and front and the fridge's front.
  const Eigen::AlignedBox3f cabinet_top(Eigen::Vector3f(0.85f, -0.75f, 0.85f),
                                        Eigen::Vector3f(1.35f, -0.1f, 0.95f));
  const Eigen::AlignedBox3f cabinet_front(Eigen::Vector3f(0.75f, -0.7f, 0.1f),
                                          Eigen::Vector3f(0.85f, -0.1f, 0.8f));
  const Eigen::AlignedBox3f fridge_front(Eigen::Vector3f(0.75f, 0.1f, 0.1f),
                                         Eigen::Vector3f(0.85f, 0.6f, 1.5f));
  const auto top = dominantSuperpoint(mesh, cabinet_top);
  const auto front = dominantSuperpoint(mesh, cabinet_front);
  const auto fridge = dominantSuperpoint(mesh, fridge_front);
  ASSERT_GT(top.first, 0);
  ASSERT_GT(front.first, 0);
  ASSERT_GT(fridge.first, 0);
  EXPECT_GT(top.second, 0.8);
  EXPECT_GT(fridge.second, 0.8);
  const SuperpointTracker& sp = mapper->superpoints();
  // Different classes never share a super-point, even where the boxes touch.
  EXPECT_NE(front.first, fridge.first);
  EXPECT_NE(top.first, fridge.first);
  EXPECT_EQ(sp.state(top.first)->semanticClass(), 3);
  EXPECT_EQ(sp.state(front.first)->semanticClass(), 3);
  EXPECT_EQ(sp.state(fridge.first)->semanticClass(), 24);
  // One object, one instance: the cabinet's faces agree, the fridge differs.
  EXPECT_EQ(sp.state(top.first)->instance(), sp.state(front.first)->instance());
  EXPECT_NE(sp.state(top.first)->instance(), sp.state(fridge.first)->instance());
  // The graph (III-C) saw both boxes; the final optimisation keeps their classes and
  // instances apart.
  const SuperpointGraph graph = mapper->graph();
  EXPECT_GE(graph.vertices.size(), 3u);
  EXPECT_GE(graph.edges.size(), 1u);
  const GraphLabels labels = optimise(graph, OptimiserConfig{});
  EXPECT_EQ(labels.semantic.at(top.first), 3);
  EXPECT_EQ(labels.semantic.at(fridge.first), 24);
  EXPECT_EQ(labels.instance.at(top.first), labels.instance.at(front.first));
  EXPECT_NE(labels.instance.at(top.first), labels.instance.at(fridge.first));
  EXPECT_GT(labels.instance.at(fridge.first), 0);
  // Along the shared side no vertex of the fridge's front carries a cabinet super-point.
  for (size_t v = 0; v < mesh.numVertices(); ++v) {
    if (fridge_front.contains(mesh.vertices[v]) && mesh.superpoint[v] > 0) {
      EXPECT_NE(sp.state(mesh.superpoint[v])->semanticClass(), 3) << v;
    }
  }
}

TEST_F(BoxScene, SameInputGivesBitIdenticalOutput) {
  auto a = run(config(), 6);
  auto b = run(config(), 6);
  test::TempDir dir;
  a->save(dir.path("a.panmap"));
  b->save(dir.path("b.panmap"));
  EXPECT_EQ(readFileBytes(dir.path("a.panmap")), readFileBytes(dir.path("b.panmap")));
  const LabelledMesh ma = a->extractMesh(), mb = b->extractMesh();
  EXPECT_EQ(ma.vertices, mb.vertices);
  EXPECT_EQ(ma.superpoint, mb.superpoint);
  EXPECT_EQ(ma.instance, mb.instance);
  // One thread or two: the same map.
  MapperConfig one = config();
  one.num_threads = 1;
  auto c = run(one, 6);
  c->save(dir.path("c.panmap"));
  auto bytes_a = readFileBytes(dir.path("a.panmap")), bytes_c = readFileBytes(dir.path("c.panmap"));
  ASSERT_EQ(bytes_a.size(), bytes_c.size());
  // The files differ only in the stored thread count (and so the checksum).
  size_t differing = 0;
  for (size_t i = 0; i < bytes_a.size(); ++i) differing += bytes_a[i] != bytes_c[i];
  EXPECT_LE(differing, 8u);
}

// The live mapper refreshes the surface scan between frames (LiveOptions::
// idle_scan_every_frames): the final graph must be the one a mapper that never did gives.
TEST_F(BoxScene, SurfaceScanRefreshesBetweenFramesChangeNoResult) {
  auto plain = run(config(), 6);
  auto refreshed = std::make_unique<Mapper>(config());
  for (int k = 0; k < 6; ++k) {
    RgbdFrame frame;
    PanopticFrame panoptic;
    frameAt(k, &frame, &panoptic);
    refreshed->integrate(frame, pose(k), &panoptic);
    const size_t read = refreshed->refreshSurfaceScan();
    if (k == 0) {
      EXPECT_EQ(refreshed->map().numBlocks(), read) << "the first reads every block";
    }
    EXPECT_GT(read, 0u) << "frame " << k << " changed blocks";
    EXPECT_EQ(0u, refreshed->refreshSurfaceScan()) << "nothing changed since";
  }
  const SuperpointGraph a = plain->graph(), b = refreshed->graph();
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_GT(a.edges.size(), 0u);
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) {
    EXPECT_EQ(a.vertices[i].id, b.vertices[i].id);
    EXPECT_EQ(a.vertices[i].num_voxels, b.vertices[i].num_voxels);
    EXPECT_EQ(a.vertices[i].centroid, b.vertices[i].centroid);
    EXPECT_EQ(a.vertices[i].scores, b.vertices[i].scores);
  }
  for (size_t i = 0; i < a.edges.size(); ++i) {
    EXPECT_EQ(std::tie(a.edges[i].a, a.edges[i].b), std::tie(b.edges[i].a, b.edges[i].b));
    EXPECT_EQ(a.edges[i].confidences, b.edges[i].confidences);
  }
  test::TempDir dir;
  plain->save(dir.path("a.panmap"));
  refreshed->save(dir.path("b.panmap"));
  EXPECT_EQ(readFileBytes(dir.path("a.panmap")), readFileBytes(dir.path("b.panmap")));
}

// A final export drops the block meshes kept for live updates: the files are those of an
// ordinary export, the next mesh update meshes every block again (an ordinary export leaves
// nothing to re-mesh), and a mesh extracted afterwards is the same mesh.
TEST_F(BoxScene, AFinalExportWritesTheSameFilesAndLeavesTheMeshIntact) {
  auto mapper = run(config(), 6);
  const GraphLabels labels = optimise(mapper->graph(), OptimiserConfig{});
  const LabelledMesh before = mapper->extractMesh(&labels);
  ASSERT_GT(before.numFaces(), 0u);
  const size_t meshed = mapper->updateMesh(&labels).blocks.size();  // takes every changed block
  ASSERT_GT(meshed, 0u);
  test::TempDir dir;
  OutputOptions ordinary;
  ordinary.snapshots = false;
  const OutputSummary a = writeOutputs(dir.path("a"), mapper.get(), &labels, {}, ordinary);
  EXPECT_EQ(0u, mapper->updateMesh(&labels).blocks.size()) << "the block meshes were kept";
  OutputOptions last = ordinary;
  last.final_export = true;
  const OutputSummary b = writeOutputs(dir.path("b"), mapper.get(), &labels, {}, last);
  EXPECT_EQ(meshed, mapper->updateMesh(&labels).blocks.size()) << "the block meshes were dropped";
  ASSERT_EQ(a.files, b.files);
  for (const std::string& name : a.files) {
    EXPECT_EQ(readFileBytes(dir.path("a/" + name)), readFileBytes(dir.path("b/" + name))) << name;
  }
  const LabelledMesh after = mapper->extractMesh(&labels);
  EXPECT_EQ(before.vertices, after.vertices);
  EXPECT_EQ(before.faces, after.faces);
  EXPECT_EQ(before.semantic, after.semantic);
  EXPECT_EQ(before.instance, after.instance);
  EXPECT_EQ(before.superpoint, after.superpoint);
}

// An output that cannot be written (here a folder in the way of objects.json) costs that
// output alone: the map is written first, the rest after it, and the error names the file.
// Pictures of an earlier run are not left beside a map that made none.
TEST_F(BoxScene, AnOutputThatCannotBeWrittenCostsOnlyThatOutput) {
  auto mapper = run(config(), 3);
  const GraphLabels labels = optimise(mapper->graph(), OptimiserConfig{});
  test::TempDir dir;
  std::filesystem::create_directories(dir.path("out/objects.json"));
  std::ofstream(dir.path("out/snapshot_color.png")) << "an old picture";
  OutputOptions options;
  options.snapshots = false;
  const OutputSummary summary = writeOutputs(dir.path("out"), mapper.get(), &labels, {}, options);
  ASSERT_EQ(summary.failed.size(), 1u);
  EXPECT_EQ(std::count(summary.files.begin(), summary.files.end(), "objects.json"), 0);
  EXPECT_EQ(std::count(summary.files.begin(), summary.files.end(), "config.yaml"), 1);
  test::expectError(
      [&] { requireAllWritten(summary, dir.path("out")); },
      {dir.path("out/objects.json"), "map.panmap and the other outputs were written"});
  for (const char* name : {"map.panmap", "mesh_instance.ply", "trajectory.txt", "config.yaml"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(dir.path("out/") + name)) << name;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path("out/snapshot_color.png")));
  EXPECT_EQ(Mapper::load(dir.path("out/map.panmap"))->framesIntegrated(), 3);

  // A full disk: small files (config.yaml, trajectory.txt, objects.json) were once reported
  // written while they stayed empty. Outputs go to NAME.partial first (renamed over NAME when
  // whole), so that is where the full disk is met.
  if (!std::filesystem::exists("/dev/full")) return;
  std::filesystem::create_directories(dir.path("full"));
  for (const char* name : {"trajectory.txt", "config.yaml"}) {
    std::filesystem::create_symlink("/dev/full", dir.path("full/") + name + ".partial");
  }
  const OutputSummary full = writeOutputs(dir.path("full"), mapper.get(), &labels, {}, options);
  ASSERT_EQ(full.failed.size(), 2u);
  EXPECT_NE(full.failed[0].find("trajectory.txt"), std::string::npos) << full.failed[0];
  EXPECT_NE(full.failed[1].find("config.yaml"), std::string::npos) << full.failed[1];
  EXPECT_EQ(std::count(full.files.begin(), full.files.end(), "trajectory.txt"), 0);
  for (const char* name : {"trajectory.txt", "config.yaml"}) {
    const std::string partial = dir.path("full/") + name + ".partial";
    EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(partial))) << partial;
  }
}

TEST_F(BoxScene, LiveMeshUpdatesAddUpToTheExportedMesh) {
  Mapper mapper(config());
  // A viewer: one mesh per block, replaced when an update names the block.
  std::map<std::array<int, 3>, LabelledMesh> view;
  auto apply = [&view](const MeshUpdate& update) {
    EXPECT_EQ(update.blocks.size(), update.geometry.size());
    EXPECT_EQ(update.blocks.size(), update.labels.size());
    EXPECT_TRUE(std::is_sorted(update.blocks.begin(), update.blocks.end(), blockIndexLess));
    for (size_t i = 0; i < update.blocks.size(); ++i) {
      const BlockIndex& b = update.blocks[i];
      ASSERT_TRUE(update.geometry[i]);
      EXPECT_EQ(update.geometry[i]->index, b);
      view[{b.x(), b.y(), b.z()}] = update.mesh(i);
    }
  };
  MeshUpdate last;
  // An update kept while the mapper goes on: the geometry it shares must not change under it.
  MeshUpdate kept;
  std::vector<LabelledMesh> kept_copies;
  for (int k = 0; k < 8; ++k) {
    RgbdFrame frame;
    PanopticFrame panoptic;
    frameAt(k, &frame, &panoptic);
    mapper.integrate(frame, pose(k), &panoptic);
    if (k == 5) mapper.extractMesh();  // an export between updates loses no block
    if (k % 2 == 1) {
      last = mapper.updateMesh();
      EXPECT_FALSE(last.blocks.empty());
      apply(last);
      if (k == 1) {
        kept = last;
        for (size_t i = 0; i < kept.blocks.size(); ++i) kept_copies.push_back(kept.mesh(i));
      }
    }
  }
  size_t kept_vertices = 0;
  for (size_t i = 0; i < kept.blocks.size(); ++i) {
    const LabelledMesh now = kept.mesh(i);
    EXPECT_EQ(now.vertices, kept_copies[i].vertices)
        << "block " << i << " changed under its holder";
    EXPECT_EQ(now.faces, kept_copies[i].faces);
    EXPECT_EQ(now.superpoint, kept_copies[i].superpoint);
    kept_vertices += now.numVertices();
  }
  EXPECT_GT(kept_vertices, 100u);
  // Blocks the later updates re-meshed hold other geometry now: the kept one was not reused.
  size_t moved = 0;
  for (size_t i = 0; i < kept.blocks.size(); ++i) {
    const auto it = std::find(last.blocks.begin(), last.blocks.end(), kept.blocks[i]);
    if (it == last.blocks.end()) continue;
    const BlockMesh& newer = *last.geometry[it - last.blocks.begin()];
    moved += &newer != kept.geometry[i].get() && newer.vertices != kept_copies[i].vertices;
  }
  EXPECT_GT(moved, 0u);
  EXPECT_TRUE(mapper.updateMesh().blocks.empty());  // nothing integrated since

  // The blocks the viewer holds give exactly the exported mesh's vertices; those of the last
  // update carry the exported labels (older blocks keep the labels of their update).
  const LabelledMesh whole = mapper.extractMesh();
  std::map<std::array<float, 3>, std::array<int32_t, 3>> exported;
  for (size_t i = 0; i < whole.numVertices(); ++i) {
    const Eigen::Vector3f& p = whole.vertices[i];
    exported[{p.x(), p.y(), p.z()}] = {whole.superpoint[i], whole.semantic[i], whole.instance[i]};
  }
  std::set<std::array<float, 3>> held;
  for (const auto& [key, mesh] : view) {
    for (const Eigen::Vector3f& p : mesh.vertices) held.insert({p.x(), p.y(), p.z()});
  }
  EXPECT_EQ(held.size(), exported.size());
  for (const auto& p : held) ASSERT_TRUE(exported.count(p)) << "a vertex the export lacks";
  // Re-meshing only what integration changed (a block, and a lower neighbour only when a face
  // they share changed) loses nothing: the same geometry as meshing the map from scratch.
  MarchingCubesConfig scratch_config;
  scratch_config.max_sdf_jump_voxels = config().integrator.truncation_voxels;
  const LabelledMesh scratch = marchingCubes(mapper.map(), scratch_config);
  EXPECT_EQ(scratch.vertices, whole.vertices);
  EXPECT_EQ(scratch.faces, whole.faces);
  size_t checked = 0;
  for (size_t b = 0; b < last.blocks.size(); ++b) {
    const LabelledMesh mesh = last.mesh(b);
    for (size_t i = 0; i < mesh.numVertices(); ++i, ++checked) {
      const Eigen::Vector3f& p = mesh.vertices[i];
      ASSERT_EQ(exported.at({p.x(), p.y(), p.z()}),
                (std::array<int32_t, 3>{mesh.superpoint[i], mesh.semantic[i], mesh.instance[i]}));
    }
  }
  EXPECT_GT(checked, 100u);
}

TEST_F(BoxScene, SaveLoadRoundTripAndContinue) {
  test::TempDir dir;
  auto full = run(config(), 8);
  auto half = run(config(), 4);
  half->save(dir.path("half.panmap"));
  auto resumed = Mapper::load(dir.path("half.panmap"));
  resumed->save(dir.path("again.panmap"));
  EXPECT_EQ(readFileBytes(dir.path("half.panmap")), readFileBytes(dir.path("again.panmap")));
  for (int k = 4; k < 8; ++k) {
    RgbdFrame frame;
    PanopticFrame panoptic;
    frameAt(k, &frame, &panoptic);
    resumed->integrate(frame, pose(k), &panoptic);
  }
  full->save(dir.path("full.panmap"));
  resumed->save(dir.path("resumed.panmap"));
  EXPECT_EQ(readFileBytes(dir.path("full.panmap")), readFileBytes(dir.path("resumed.panmap")));
  // Corruption is detected, naming the file.
  auto bytes = readFileBytes(dir.path("full.panmap"));
  bytes[bytes.size() / 2] ^= 0x40;
  writeFileBytes(dir.path("bad.panmap"), bytes);
  try {
    Mapper::load(dir.path("bad.panmap"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.panmap: checksum"), std::string::npos) << e.what();
  }
  bytes.resize(100);
  writeFileBytes(dir.path("short.panmap"), bytes);
  EXPECT_THROW(Mapper::load(dir.path("short.panmap")), Error);
  EXPECT_THROW(Mapper::load(dir.path("missing.panmap")), Error);
}

TEST_F(BoxScene, BadInputIsRefusedAndTheMapIsUnharmed) {
  auto mapper = run(config(), 3);
  test::TempDir dir;
  mapper->save(dir.path("before.panmap"));
  RgbdFrame frame;
  PanopticFrame panoptic;
  frameAt(3, &frame, &panoptic);
  Eigen::Isometry3d nan_pose = pose(3);
  nan_pose.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(mapper->integrate(frame, nan_pose, &panoptic), Error);
  RgbdFrame small = frame;
  small.depth = DepthImage(320, 240);
  try {
    mapper->integrate(small, pose(3), &panoptic);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("320x240"), std::string::npos) << e.what();
  }
  RgbdFrame empty = frame;
  empty.depth = DepthImage();
  EXPECT_THROW(mapper->integrate(empty, pose(3), &panoptic), Error);
  PanopticFrame wrong = panoptic;
  wrong.segment_ids = LabelImage(10, 10);
  EXPECT_THROW(mapper->integrate(frame, pose(3), &wrong), Error);
  PanopticFrame duplicate = panoptic;
  if (!duplicate.segments.empty()) {
    duplicate.segments.push_back(duplicate.segments.front());
    EXPECT_THROW(mapper->integrate(frame, pose(3), &duplicate), Error);
    PanopticFrame huge = panoptic;
    huge.segments.front().id = kMaxPanopticSegmentId + 1;
    test::expectError([&] { mapper->integrate(frame, pose(3), &huge); },
                      {"panoptic segment ids", "1073741823", "got 1073741824"});
  }
  mapper->save(dir.path("after.panmap"));
  EXPECT_EQ(readFileBytes(dir.path("before.panmap")), readFileBytes(dir.path("after.panmap")));
  // Unknown classes (0) are simply background.
  PanopticFrame unknown = panoptic;
  for (auto& s : unknown.segments) s.category = 0;
  EXPECT_NO_THROW(mapper->integrate(frame, pose(3), &unknown));
}

}  // namespace
}  // namespace panmap

namespace panmap {
namespace {

// The bytes of a map file rewritten as an older version wrote them: version 8 without III-B's
// unlabelled_void_share (the double after apart_weight), version 7 also without apart_weight
// (the float after the mask_verdicts byte), version 6 also without the
// mask_verdicts byte (right after the pruning fields), version 5 also without the three graph
// pruning fields, which start one byte before the double at `share_offset`.
constexpr size_t kMapFileHeader = 20;  // magic, version, payload size

// Gives `file` another version number, payload size and checksum.
std::vector<uint8_t> reseal(std::vector<uint8_t> file, uint32_t version) {
  std::memcpy(&file[8], &version, sizeof(version));
  const uint64_t size = file.size() - kMapFileHeader - sizeof(uint32_t);
  std::memcpy(&file[12], &size, sizeof(size));
  const auto crc = static_cast<uint32_t>(crc32(0L, &file[kMapFileHeader], static_cast<uInt>(size)));
  std::memcpy(&file[kMapFileHeader + size], &crc, sizeof(crc));
  return file;
}

// Where the byte that version 12 added at the end of the config (whether a depth calibration
// follows) sits in a file of today's `config`: after the thread count, found where two files
// that differ only in it differ.
size_t calibrationFlagAt(const MapperConfig& config) {
  MapperConfig one = config, three = config;
  one.num_threads = 1;
  three.num_threads = 3;
  const std::vector<uint8_t> a = Mapper(one).serialize(), b = Mapper(three).serialize();
  size_t threads = 0;
  while (threads < a.size() && a[threads] == b[threads]) ++threads;
  return threads + sizeof(int32_t);
}

constexpr size_t kFillBytes = 1 + sizeof(double) + sizeof(int32_t);

// Bytes of auto tracking's depth check in the config (version 16): four int32 and a double.
constexpr size_t kDepthCheckConfigBytes = 4 * sizeof(int32_t) + sizeof(double);

// A file of today's `config` (without a calibration) whose mapper never tracked a frame,
// without what version 16 added: the depth check's config after the co-observation band, and
// its state (a verdict byte, a frame count, two halves of per-cell sums and counts, the counts
// of poses kept and corrected) after the tracking counts, found by its bytes. Its layout of
// version 15.
// Bytes of fusion's mask-only surfaces in the config (version 17): a flag and a float.
constexpr size_t kMaskOnlyBytes = 1 + sizeof(float);

// Bytes of III-B's join_mask_pieces and revisit_votes in the config (version 18): two flags.
constexpr size_t kReuseBytes = 2;

// A file of today's `config` (without a calibration) without what version 18 added after the
// mask-only surfaces: its layout of version 17.
std::vector<uint8_t> withoutReuseRules(std::vector<uint8_t> file, const MapperConfig& config) {
  const size_t at = calibrationFlagAt(config) + 1 + kFillBytes + sizeof(int32_t) +
                    kDepthCheckConfigBytes + kMaskOnlyBytes;
  EXPECT_LT(at + kReuseBytes, file.size());
  EXPECT_EQ(file[at], config.superpoints.join_mask_pieces ? 1 : 0);
  EXPECT_EQ(file[at + 1], config.superpoints.revisit_votes ? 1 : 0);
  file.erase(file.begin() + static_cast<std::ptrdiff_t>(at),
             file.begin() + static_cast<std::ptrdiff_t>(at + kReuseBytes));
  return file;
}

// A file of today's `config` (without a calibration) without what version 17 added after the
// depth check's config: its layout of version 16.
std::vector<uint8_t> withoutMaskOnlySurfaces(std::vector<uint8_t> file,
                                             const MapperConfig& config) {
  file = withoutReuseRules(std::move(file), config);
  const size_t at =
      calibrationFlagAt(config) + 1 + kFillBytes + sizeof(int32_t) + kDepthCheckConfigBytes;
  EXPECT_LT(at + kMaskOnlyBytes, file.size());
  EXPECT_EQ(file[at], config.fusion.mask_only_surfaces ? 1 : 0);
  file.erase(file.begin() + static_cast<std::ptrdiff_t>(at),
             file.begin() + static_cast<std::ptrdiff_t>(at + kMaskOnlyBytes));
  return file;
}

std::vector<uint8_t> withoutDepthCheck(std::vector<uint8_t> file, const MapperConfig& config) {
  file = withoutMaskOnlySurfaces(std::move(file), config);
  const size_t at = calibrationFlagAt(config) + 1 + kFillBytes + sizeof(int32_t);
  EXPECT_LT(at + kDepthCheckConfigBytes, file.size());
  int32_t frames = -1;
  std::memcpy(&frames, &file[at], sizeof(frames));
  EXPECT_EQ(frames, config.depth_check.frames);
  file.erase(file.begin() + static_cast<std::ptrdiff_t>(at),
             file.begin() + static_cast<std::ptrdiff_t>(at + kDepthCheckConfigBytes));
  const uint64_t cells = kResidualCellsX * kResidualCellsY;
  std::vector<uint8_t> state(1 + sizeof(int32_t), 0);
  state[0] = config.depth_check.frames == 0 ? 1 : 0;  // trusted, or pending
  for (int half = 0; half < 2; ++half) {
    const size_t count_at = state.size();
    state.resize(count_at + sizeof(uint64_t) + cells * (sizeof(double) + sizeof(int32_t)), 0);
    std::memcpy(&state[count_at], &cells, sizeof(cells));
  }
  state.resize(state.size() + 2 * sizeof(int64_t), 0);
  const auto found = std::search(file.begin(), file.end(), state.begin(), state.end());
  EXPECT_NE(found, file.end());
  if (found != file.end()) file.erase(found, found + static_cast<std::ptrdiff_t>(state.size()));
  return file;
}

// A file of today's `config` (without a calibration) without the co-observation band that
// version 15 added after the mask edge fill (an int32): its layout of version 14.
std::vector<uint8_t> withoutPairInterior(std::vector<uint8_t> file, const MapperConfig& config) {
  file = withoutDepthCheck(std::move(file), config);
  const size_t at = calibrationFlagAt(config) + 1 + kFillBytes;
  EXPECT_LT(at + sizeof(int32_t), file.size());
  int32_t stored = -1;
  std::memcpy(&stored, &file[at], sizeof(stored));
  EXPECT_EQ(stored, config.graph.pair_interior_px);
  file.erase(file.begin() + static_cast<std::ptrdiff_t>(at),
             file.begin() + static_cast<std::ptrdiff_t>(at + sizeof(int32_t)));
  return file;
}

// A file of today's `config` (without a calibration) without the mask edge fill that version
// 14 added after the calibration flag (a flag, a double and an int32) and what came after it:
// its layout of versions 12 and 13.
std::vector<uint8_t> withoutMaskFill(std::vector<uint8_t> file, const MapperConfig& config) {
  file = withoutPairInterior(std::move(file), config);
  const size_t flag = calibrationFlagAt(config);
  EXPECT_LT(flag + kFillBytes, file.size());
  EXPECT_EQ(file[flag], 0);  // no calibration
  EXPECT_EQ(file[flag + 1], config.mask_edge_fill.enabled ? 1 : 0);
  file.erase(file.begin() + static_cast<std::ptrdiff_t>(flag + 1),
             file.begin() + static_cast<std::ptrdiff_t>(flag + 1 + kFillBytes));
  return file;
}

// A file of today's `config` without the bytes that versions 12 and 14 added at the end of the
// config: its layout before version 12.
std::vector<uint8_t> withoutCalibrationFlag(std::vector<uint8_t> file, const MapperConfig& config) {
  file = withoutMaskFill(std::move(file), config);
  file.erase(file.begin() + static_cast<std::ptrdiff_t>(calibrationFlagAt(config)));
  return file;
}

std::vector<uint8_t> asVersion(std::vector<uint8_t> file, size_t share_offset, uint32_t version) {
  const size_t flag = share_offset + 8 + 4;
  const size_t apart = flag + 1;
  if (version <= 8) {
    file.erase(file.begin() + static_cast<std::ptrdiff_t>(apart + sizeof(float)),
               file.begin() + static_cast<std::ptrdiff_t>(apart + sizeof(float) + sizeof(double)));
  }
  if (version <= 7) {
    file.erase(file.begin() + static_cast<std::ptrdiff_t>(apart),
               file.begin() + static_cast<std::ptrdiff_t>(apart + sizeof(float)));
  }
  if (version <= 6) {
    file.erase(file.begin() + static_cast<std::ptrdiff_t>(flag),
               file.begin() + static_cast<std::ptrdiff_t>(flag + 1));
  }
  if (version == 5) {
    file.erase(file.begin() + static_cast<std::ptrdiff_t>(share_offset - 1),
               file.begin() + static_cast<std::ptrdiff_t>(share_offset + 8 + 4));
  }
  return reseal(std::move(file), version);
}

TEST(MapFile, KeepsItsSettingsAndReadsVersionsFiveToEighteen) {
  MapperConfig a;
  a.map.voxel_size_m = 0.05f;
  a.graph.prune_edges = false;
  a.graph.edge_min_share = 0.3;
  a.graph.surface_band_voxels = 1.5f;
  a.superpoints.mask_verdicts = true;
  a.superpoints.apart_weight = 2.5f;
  a.superpoints.unlabelled_void_share = 0.75;
  const auto back = Mapper::deserialize(Mapper(a).serialize(), "a.panmap");
  EXPECT_TRUE(back->config().superpoints.mask_verdicts);
  EXPECT_EQ(back->config().superpoints.apart_weight, 2.5f);
  EXPECT_EQ(back->config().superpoints.unlabelled_void_share, 0.75);
  EXPECT_FALSE(back->config().graph.prune_edges);
  EXPECT_EQ(back->config().graph.edge_min_share, 0.3);
  EXPECT_EQ(back->config().graph.surface_band_voxels, 1.5f);

  // A version 5 file was built without pruning: it loads with pruning off, whatever the
  // defaults say now. The share field is found where two files differ only in it.
  MapperConfig b = a;
  b.graph.prune_edges = true;
  MapperConfig c = b;
  c.graph.edge_min_share = 0.1;
  const std::vector<uint8_t> bytes_b = withoutCalibrationFlag(Mapper(b).serialize(), b);
  const std::vector<uint8_t> bytes_c = withoutCalibrationFlag(Mapper(c).serialize(), c);
  ASSERT_EQ(bytes_b.size(), bytes_c.size());
  size_t offset = 0;
  while (offset < bytes_b.size() && bytes_b[offset] == bytes_c[offset]) ++offset;
  ASSERT_LT(offset, bytes_b.size());
  const auto old = Mapper::deserialize(asVersion(bytes_b, offset, 5), "old.panmap");
  EXPECT_FALSE(old->config().graph.prune_edges);
  EXPECT_FALSE(old->config().superpoints.mask_verdicts);
  EXPECT_EQ(old->config().map.voxel_size_m, 0.05f);
  EXPECT_EQ(withoutCalibrationFlag(Mapper(old->config()).serialize(), old->config()).size(),
            bytes_b.size());

  // A version 6 file keeps its pruning and was built without III-B's mask verdicts.
  const auto six = Mapper::deserialize(asVersion(bytes_b, offset, 6), "six.panmap");
  EXPECT_TRUE(six->config().graph.prune_edges);
  EXPECT_EQ(six->config().graph.edge_min_share, 0.3);
  EXPECT_FALSE(six->config().superpoints.mask_verdicts);
  EXPECT_EQ(six->config().superpoints.apart_weight, 1.0f);

  // A version 7 file keeps its mask verdicts and was built with the plain majority rule.
  const auto seven = Mapper::deserialize(asVersion(bytes_b, offset, 7), "seven.panmap");
  EXPECT_TRUE(seven->config().superpoints.mask_verdicts);
  EXPECT_EQ(seven->config().superpoints.apart_weight, 1.0f);
  EXPECT_EQ(seven->config().graph.edge_min_share, 0.3);
  EXPECT_EQ(seven->config().superpoints.unlabelled_void_share, 1.0);

  // A version 8 file keeps its apart_weight and was built without the unlabelled-merge rule.
  const auto eight = Mapper::deserialize(asVersion(bytes_b, offset, 8), "eight.panmap");
  EXPECT_EQ(eight->config().superpoints.apart_weight, 2.5f);
  EXPECT_EQ(eight->config().superpoints.unlabelled_void_share, 1.0);
  EXPECT_EQ(eight->config().graph.edge_min_share, 0.3);

  // A version 9 file keeps its unlabelled-merge rule.
  const auto nine = Mapper::deserialize(asVersion(bytes_b, offset, 9), "nine.panmap");
  EXPECT_EQ(nine->config().superpoints.unlabelled_void_share, 0.75);

  // A version 11 file has no depth calibration.
  EXPECT_FALSE(
      Mapper::deserialize(asVersion(bytes_b, offset, 11), "11.panmap")->config().depth_calibration);

  // A version 13 file was built without the mask edge fill; a version 14 file keeps it.
  MapperConfig fill = b;
  fill.mask_edge_fill.max_depth_step = 0.02;
  fill.mask_edge_fill.max_distance_px = 9;
  EXPECT_FALSE(
      Mapper::deserialize(reseal(withoutMaskFill(Mapper(fill).serialize(), fill), 13), "13.panmap")
          ->config()
          .mask_edge_fill.enabled);
  fill.graph.pair_interior_px = 3;
  const auto fourteen = Mapper::deserialize(
      reseal(withoutPairInterior(Mapper(fill).serialize(), fill), 14), "14.panmap");
  EXPECT_TRUE(fourteen->config().mask_edge_fill.enabled);
  EXPECT_EQ(fourteen->config().mask_edge_fill.max_depth_step, 0.02);
  EXPECT_EQ(fourteen->config().mask_edge_fill.max_distance_px, 9);
  // A version 14 file counted every pixel of a mask as co-observation; version 15 keeps its band.
  EXPECT_EQ(fourteen->config().graph.pair_interior_px, 0);
  fill.depth_check.frames = 12;
  fill.depth_check.max_pattern_m = 0.002;
  const auto fifteen = Mapper::deserialize(
      reseal(withoutDepthCheck(Mapper(fill).serialize(), fill), 15), "15.panmap");
  EXPECT_EQ(fifteen->config().graph.pair_interior_px, 3);
  // A version 15 file refined poses with no depth check: it goes on trusting the depth.
  EXPECT_EQ(fifteen->config().depth_check.frames, 0);
  EXPECT_EQ(fifteen->depthCheck().verdict(), DepthPatternMonitor::Verdict::kTrusted);
  // Version 16 keeps the check's settings and its state, and was built without mask-only
  // surfaces.
  const auto sixteen = Mapper::deserialize(
      reseal(withoutMaskOnlySurfaces(Mapper(fill).serialize(), fill), 16), "16.panmap");
  EXPECT_EQ(sixteen->config().depth_check.frames, 12);
  EXPECT_EQ(sixteen->config().depth_check.max_pattern_m, 0.002);
  EXPECT_EQ(sixteen->depthCheck().verdict(), DepthPatternMonitor::Verdict::kPending);
  EXPECT_FALSE(sixteen->config().fusion.mask_only_surfaces);
  // Version 17 keeps them, on or off, with their depth step, and was built without III-B's
  // reuse rules.
  EXPECT_TRUE(fill.fusion.mask_only_surfaces);
  fill.superpoints.join_mask_pieces = true;
  fill.superpoints.revisit_votes = true;
  fill.fusion.mask_only_depth_step = 0.03f;
  const auto on = Mapper::deserialize(reseal(withoutReuseRules(Mapper(fill).serialize(), fill), 17),
                                      "17.panmap");
  EXPECT_TRUE(on->config().fusion.mask_only_surfaces);
  EXPECT_EQ(on->config().fusion.mask_only_depth_step, 0.03f);
  EXPECT_FALSE(on->config().superpoints.join_mask_pieces);
  EXPECT_FALSE(on->config().superpoints.revisit_votes);
  fill.fusion.mask_only_surfaces = false;
  EXPECT_FALSE(Mapper::deserialize(reseal(withoutReuseRules(Mapper(fill).serialize(), fill), 17),
                                   "17.panmap")
                   ->config()
                   .fusion.mask_only_surfaces);
  // Version 18 keeps each rule, on or off.
  for (const auto& [join, revisit] : {std::pair{true, false}, std::pair{false, true}}) {
    fill.superpoints.join_mask_pieces = join;
    fill.superpoints.revisit_votes = revisit;
    const auto eighteen = Mapper::deserialize(Mapper(fill).serialize(), "18.panmap");
    EXPECT_EQ(eighteen->config().superpoints.join_mask_pieces, join);
    EXPECT_EQ(eighteen->config().superpoints.revisit_votes, revisit);
  }

  // Versions outside 5-18 are refused by name.
  std::vector<uint8_t> future = Mapper(b).serialize();
  future[8] = 19;
  test::expectError([&] { Mapper::deserialize(future, "future.panmap"); },
                    {"future.panmap", "version 19", "reads 5 to 18"});
}

// Bytes before a block's voxels in a map file: its index and its updated flag.
constexpr size_t kRecordHead = 3 * sizeof(int32_t) + 1;

// Where the first block's record of `map` starts in `file` (blocks are stored in allocation
// order, each as index, updated flag, voxels and votes: it is found by its bytes), or
// file.size() when it is not there.
size_t firstBlockRecord(const std::vector<uint8_t>& file, const TsdfMap& map) {
  const Block& first = *map.blocks()[0];
  std::vector<uint8_t> pattern(kRecordHead + sizeof(Block::voxels));
  const int32_t index[3] = {first.index.x(), first.index.y(), first.index.z()};
  std::memcpy(pattern.data(), index, sizeof(index));
  pattern[12] = first.updated;
  std::memcpy(pattern.data() + kRecordHead, first.voxels, sizeof(Block::voxels));
  return static_cast<size_t>(std::search(file.begin(), file.end(), pattern.begin(), pattern.end()) -
                             file.begin());
}

// `file` (written by `mapper`) with its voxels as versions before 13 stored them, every voxel
// with its four vote slots: 4-byte distance and weight and vote counts of 4 bytes (version 9)
// or 2 (version 10); as today's 8 bytes, then the slots (versions 11 and 12). Voxel 0 of block
// 0 gets the labels 77-80 with `first_counts`.
std::vector<uint8_t> withLegacyVoxels(const std::vector<uint8_t>& file, const TsdfMap& map,
                                      uint32_t version, const uint32_t first_counts[kVoteSlots]) {
  const size_t begin = firstBlockRecord(file, map);
  EXPECT_NE(begin, file.size());
  if (begin == file.size()) return {};
  const auto found = file.begin() + static_cast<std::ptrdiff_t>(begin);
  size_t end = begin;
  for (const auto& block : map.blocks()) {
    end += kRecordHead + sizeof(Block::voxels) + 2 +
           block->vote_sets.size() * (2 + sizeof(VoxelVotes));
  }
  const size_t count_bytes = version >= 10 ? 2 : 4;
  std::vector<uint8_t> old(file.begin(), found);
  for (size_t b = 0; b < map.numBlocks(); ++b) {
    const Block& block = *map.blocks()[b];
    const int32_t block_index[3] = {block.index.x(), block.index.y(), block.index.z()};
    std::vector<uint8_t> record(kRecordHead);
    std::memcpy(record.data(), block_index, sizeof(block_index));
    record[12] = block.updated;
    old.insert(old.end(), record.begin(), record.end());
    for (int i = 0; i < kBlockVoxels; ++i) {
      const Voxel& v = block.voxels[i];
      const VoxelVotes none;
      const VoxelVotes& votes = block.votes(i) ? *block.votes(i) : none;
      std::vector<uint8_t> bytes;
      if (version >= 11) {
        bytes.resize(sizeof(Voxel) + kVoteSlots * 6);
        std::memcpy(bytes.data(), &v, sizeof(Voxel));
      } else {
        bytes.resize(12 + kVoteSlots * (4 + count_bytes));
        const float sdf_m = v.sdf_m, weight = v.weight;
        std::memcpy(bytes.data(), &sdf_m, 4);
        std::memcpy(bytes.data() + 4, &weight, 4);
        bytes[8] = v.color.r;
        bytes[9] = v.color.g;
        bytes[10] = v.color.b;
        bytes[11] = v.flags;
      }
      const size_t slots_at = version >= 11 ? sizeof(Voxel) : 12;
      const size_t slot_bytes = version >= 11 ? 6 : 4 + count_bytes;
      for (int k = 0; k < kVoteSlots; ++k) {
        int32_t label = votes.slots[k].label;
        uint32_t count = votes.slots[k].count;
        if (b == 0 && i == 0) {
          label = 77 + k;
          count = first_counts[k];
        }
        uint8_t* slot = bytes.data() + slots_at + slot_bytes * k;
        std::memcpy(slot, &label, 4);
        const uint16_t short_count = static_cast<uint16_t>(count);
        std::memcpy(slot + 4, slot_bytes == 6 ? static_cast<const void*>(&short_count) : &count,
                    slot_bytes - 4);
      }
      old.insert(old.end(), bytes.begin(), bytes.end());
    }
  }
  old.insert(old.end(), file.begin() + static_cast<std::ptrdiff_t>(end), file.end());
  return reseal(old, version);
}

// Files before version 11 hold 44-byte (version 9) or 36-byte (version 10) voxels with 4-byte
// distances and weights, versions 11 and 12 32-byte ones with the four vote slots in every
// voxel: they load into today's 8-byte voxels and vote sets with every value kept (the 2-byte
// floats round-trip through 4-byte ones exactly); counts beyond 65,535 are scaled down; a
// voxel without a vote gets no vote set.
TEST_F(BoxScene, MapFilesBeforeVersionThirteenLoadTheirVoxels) {
  const auto mapper = run(config(), 3);
  const std::vector<uint8_t> file = withoutCalibrationFlag(mapper->serialize(), mapper->config());
  const TsdfMap& map = mapper->map();
  ASSERT_GT(map.numBlocks(), 10u);
  const uint32_t nine_counts[kVoteSlots] = {140000, 70000, 1, 0};
  const uint32_t ten_counts[kVoteSlots] = {65535, 1000, 1, 0};
  for (const uint32_t version : {9u, 10u, 11u}) {
    SCOPED_TRACE(version);
    const std::vector<uint8_t> old =
        withLegacyVoxels(file, map, version, version == 9 ? nine_counts : ten_counts);
    ASSERT_FALSE(old.empty());
    const auto loaded = Mapper::deserialize(old, "old.panmap");
    const TsdfMap& back = loaded->map();
    ASSERT_EQ(back.numBlocks(), map.numBlocks());
    size_t voted = 0;
    for (size_t b = 0; b < map.numBlocks(); ++b) {
      const Block& want = *map.blocks()[b];
      const Block& got = *back.blocks()[b];
      ASSERT_EQ(got.index, want.index);
      for (int i = 0; i < kBlockVoxels; ++i) {
        ASSERT_EQ(0, std::memcmp(&got.voxels[i], &want.voxels[i], sizeof(Voxel))) << b << " " << i;
        if (b == 0 && i == 0) continue;
        ASSERT_EQ(got.votes(i) == nullptr, want.votes(i) == nullptr) << b << " " << i;
        if (!want.votes(i)) continue;
        ASSERT_EQ(0, std::memcmp(got.votes(i), want.votes(i), sizeof(VoxelVotes))) << b << " " << i;
        ++voted;
      }
    }
    EXPECT_GT(voted, 100u);  // the votes were carried, not only empty slots
    ASSERT_NE(back.blocks()[0]->votes(0), nullptr);
    const VoxelVotes& first = *back.blocks()[0]->votes(0);
    EXPECT_EQ(first.slots[0].label, 77);
    EXPECT_EQ(first.slots[0].count, kMaxVoteCount);
    EXPECT_EQ(first.slots[1].label, 78);
    // Version 9: half of 65,535, rounded up; versions 10 and 11 kept their count.
    EXPECT_EQ(first.slots[1].count, version == 9 ? 32768u : 1000u);
    EXPECT_EQ(first.slots[2].count, 1u);  // a vote stays a vote
    EXPECT_EQ(first.slots[3].count, 0u);
  }
}

// Version 13 stores each block's votes as a list of the voted voxels: a reloaded map has the
// same votes voxel by voxel and saves to the same bytes, and a list that is too long or out of
// order is refused with the file's name.
TEST_F(BoxScene, MapFileVotesRoundTripAndBadVoteListsAreRefused) {
  const auto mapper = run(config(), 3);
  const std::vector<uint8_t> file = mapper->serialize();
  const auto loaded = Mapper::deserialize(file, "map.panmap");
  const TsdfMap& map = mapper->map();
  size_t voted = 0;
  ASSERT_EQ(loaded->map().numBlocks(), map.numBlocks());
  for (size_t b = 0; b < map.numBlocks(); ++b) {
    const Block& want = *map.blocks()[b];
    const Block& got = *loaded->map().blocks()[b];
    for (int i = 0; i < kBlockVoxels; ++i) {
      ASSERT_EQ(got.votes(i) == nullptr, want.votes(i) == nullptr) << b << " " << i;
      if (!want.votes(i)) continue;
      ASSERT_EQ(0, std::memcmp(got.votes(i), want.votes(i), sizeof(VoxelVotes)));
      ++voted;
    }
  }
  EXPECT_GT(voted, 100u);
  EXPECT_LT(voted, map.numBlocks() * kBlockVoxels / 2);  // sparse: most voxels hold none
  for (const auto& block : map.blocks()) {
    for (const VoxelVotes& votes : block->vote_sets) ASSERT_GT(votes.total(), 0u);  // no empty set
  }
  EXPECT_EQ(loaded->serialize(), file);

  // The record of the first block with two voted voxels: head, voxels, count, then entries.
  size_t at = firstBlockRecord(file, map);
  ASSERT_NE(at, file.size());
  for (const auto& block : map.blocks()) {
    const size_t n = block->vote_sets.size();
    if (n >= 2) break;
    at += kRecordHead + sizeof(Block::voxels) + 2 + n * (2 + sizeof(VoxelVotes));
  }
  const size_t count_at = at + kRecordHead + sizeof(Block::voxels);
  const size_t second_at = count_at + 2 + 2 + sizeof(VoxelVotes);
  std::vector<uint8_t> repeated = file;  // the second voted voxel's index made the first's
  std::memcpy(&repeated[second_at], &file[count_at + 2], 2);
  test::expectError([&] { Mapper::deserialize(reseal(repeated, 18), "repeated.panmap"); },
                    {"repeated.panmap", "out of order"});
  std::vector<uint8_t> too_many = file;
  const uint16_t n = kBlockVoxels + 1;
  std::memcpy(&too_many[count_at], &n, 2);
  test::expectError([&] { Mapper::deserialize(reseal(too_many, 18), "many.panmap"); },
                    {"many.panmap", "513 voted voxels"});
}

}  // namespace
}  // namespace panmap
