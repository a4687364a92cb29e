// panmap-fuzz-seeds FIXTURE_DIR REPO_DIR OUT_DIR: writes the seed corpora of every fuzz target
// (OUT_DIR/<target>/<seed>) from the test fixtures and from small messages, maps and configs
// made with panmap's own writers. The committed fuzz/corpus/ was made with it.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "file_names.h"
#include "fuzz_common.h"
#include "lcm_fingerprint.h"
#include "panmap/command_t.hpp"
#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/plane_codec.h"
#include "panmap/io/ply.h"
#include "panmap/io/scannet_sens.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/graph_conversions.h"
#include "panmap/lcm/mapping_session.h"
#include "panmap/lcm/object_conversions.h"
#include "panmap/mapper/config_file.h"
#include "panmap/occupancy/octree_io.h"
#include "panmap/octomap_t.hpp"
#include "panmap/status_t.hpp"

namespace fs = std::filesystem;
using panmap::fuzz::Entry;
using Bytes = std::vector<uint8_t>;

namespace {

std::string g_fixtures, g_repo, g_out;

Bytes fixture(const std::string& relative) {
  return panmap::readFileBytes(g_fixtures + "/" + relative);
}
Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }

void seed(const std::string& target, const std::string& name, const Bytes& bytes) {
  const std::string path = g_out + "/" + target + "/" + name;
  panmap::fuzz::writeFile(path, bytes.data(), bytes.size());
}

// Index of a file name in a target's list.
uint8_t nameIndex(const std::vector<std::string>& names, const std::string& name) {
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<uint8_t>(i);
  }
  throw panmap::Error("no file name " + name + " in the list");
}

Bytes container(const std::vector<std::string>& names,
                const std::vector<std::pair<std::string, Bytes>>& files) {
  std::vector<Entry> entries;
  for (const auto& [name, bytes] : files) entries.push_back(Entry{nameIndex(names, name), bytes});
  return panmap::fuzz::pack(entries);
}

// A tiny 8x6 scene: a plane at 0.3 m, two panoptic segments.
constexpr int kW = 8, kH = 6;
panmap::RgbdFrame tinyFrame(int64_t utime, int64_t frame_id) {
  panmap::RgbdFrame f;
  f.utime = utime;
  f.frame_id = frame_id;
  f.camera_name = "fuzz";
  f.camera = panmap::PinholeCamera{10.0, 10.0, 3.5, 2.5, kW, kH};
  f.depth = panmap::DepthImage(kW, kH, 300);
  f.color = panmap::ColorImage(kW, kH);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      f.color(u, v) = panmap::Rgb8{static_cast<uint8_t>(30 * u), static_cast<uint8_t>(40 * v), 90};
      if (u >= 4) f.depth(u, v) = 280;
    }
  }
  return f;
}

panmap::PanopticFrame tinyPanoptic(int64_t utime, int64_t frame_id) {
  panmap::PanopticFrame p;
  p.utime = utime;
  p.frame_id = frame_id;
  p.segment_ids = panmap::LabelImage(kW, kH, 1);
  for (int v = 0; v < kH; ++v) {
    for (int u = 4; u < kW; ++u) p.segment_ids(u, v) = 2;
  }
  p.segments = {panmap::PanopticSegment{1, 1, 1, false, 1.0f},
                panmap::PanopticSegment{2, 5, 62, true, 0.8f}};
  return p;
}

panmap::StampedPose tinyPose(int64_t utime, int64_t frame_id, double x) {
  panmap::StampedPose p;
  p.utime = utime;
  p.frame_id = frame_id;
  p.T_W_C.translation() = Eigen::Vector3d(x, 0.0, 0.0);
  p.source = panmap::PoseSource::kGroundTruth;
  return p;
}

// The encoded message without its 8-byte fingerprint (the LCM targets add it back).
template <typename T>
Bytes body(const T& msg) {
  Bytes bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return Bytes(bytes.begin() + 8, bytes.end());
}

template <typename T>
Bytes selected(uint8_t selector, const T& msg) {
  Bytes out = {selector};
  const Bytes b = body(msg);
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

panmap::ImageEncoding encodingOf(int8_t color, int8_t others) {
  panmap::ImageEncoding e;
  e.color = color;
  e.depth = others;
  e.labels = others;
  return e;
}

void imageSeeds() {
  seed("image_codec", "depth.png", fixture("tum_tiny/depth/1.005000.png"));
  seed("image_codec", "rgb.png", fixture("tum_tiny/rgb/1.000000.png"));
  seed("image_codec", "coco_labels.png", fixture("coco_tiny/panoptic/frame-000000.color.png"));
  const panmap::RgbdFrame f = tinyFrame(0, 0);
  seed("image_codec", "color.jpg", panmap::encodeJpeg(f.color, 80));
  panmap::LabelImage grey(kW, kH, 7);
  seed("image_codec", "labels_rgb.png", panmap::encodeLabelPng(tinyPanoptic(0, 0).segment_ids));
  seed("image_codec", "depth.zst", panmap::encodePlane(f.depth));
  seed("image_codec", "labels.zst", panmap::encodePlane(tinyPanoptic(0, 0).segment_ids));
}

void plySeeds() {
  seed("ply", "scannet_mesh.ply", fixture("scannet_gt_tiny/scene0000_00_vh_clean_2.ply"));
  seed("ply", "scannet_labels.ply", fixture("scannet_gt_tiny/scene0000_00_vh_clean_2.labels.ply"));
  panmap::LabelledMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.5f}};
  mesh.colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {9, 9, 9}};
  mesh.semantic = {1, 5, 5, 0};
  mesh.instance = {0, 2, 2, 0};
  mesh.superpoint = {3, 4, 4, 1};
  mesh.faces = {{0, 1, 2}, {1, 3, 2}};
  const std::string tmp = panmap::fuzz::scratchDir() + "/seed.ply";
  panmap::writePly(tmp, mesh, panmap::PlyFormat::kAscii);
  seed("ply", "labelled_ascii.ply", panmap::readFileBytes(tmp));
  panmap::writePly(tmp, mesh, panmap::PlyFormat::kBinaryLittleEndian);
  seed("ply", "labelled_binary.ply", panmap::readFileBytes(tmp));
  // Big-endian doubles, a quad and a ushort label: paths panmap's writer never takes.
  std::string be =
      "ply\nformat binary_big_endian 1.0\ncomment fuzz seed\nelement vertex 4\n"
      "property double x\nproperty double y\nproperty double z\nproperty ushort label\n"
      "element face 1\nproperty list uchar uint vertex_index\nend_header\n";
  Bytes b(be.begin(), be.end());
  const auto putBe = [&b](const void* p, size_t n) {
    const auto* q = static_cast<const uint8_t*>(p);
    for (size_t i = 0; i < n; ++i) b.push_back(q[n - 1 - i]);
  };
  for (int i = 0; i < 4; ++i) {
    for (double c : {double(i & 1), double(i >> 1), 0.25 * i}) putBe(&c, sizeof(c));
    const uint16_t label = static_cast<uint16_t>(i + 1);
    putBe(&label, sizeof(label));
  }
  b.push_back(4);
  for (uint32_t i : {0u, 1u, 3u, 2u}) putBe(&i, sizeof(i));
  seed("ply", "quad_big_endian.ply", b);
}

void configSeeds() {
  seed("config", "printed.yaml", text(panmap::configToYaml(panmap::PanmapConfig{})));
  for (const char* name : {"ablation_no_graph.yaml", "drift_filter.yaml", "fast_2cm.yaml"}) {
    seed("config", name, panmap::readFileBytes(g_repo + "/configs/" + name));
  }
  seed("config", "minimal.yaml", text("%YAML:1.0\nmap:\n  voxel_size_m: 0.05\n"));
}

void textSeeds() {
  seed("text_files", "intrinsics3x3.txt", fixture("tum_tiny/camera-intrinsics.txt"));
  seed("text_files", "groundtruth.txt", fixture("tum_tiny/groundtruth.txt"));
  seed("text_files", "labels.tsv", fixture("coco_tiny/labels.tsv"));
  seed("text_files", "pose4x4.txt", text("1 0 0 0.5\n0 1 0 -inf\n0 0 1 1e-3\n0 0 0 1\n"));
  seed("text_files", "scannet_labels.tsv",
       text("id\traw_category\tcategory\tcount\tnyu40id\n1\twall\twall\t8277\t1\n"
            "2\tchair\tchair\t4646\t5\n"));
  seed("text_files", "instances.txt", text("0\n5001\n5001\n40002\n"));
}

const std::string kFourByFour = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";

void datasetSeeds() {
  const auto& n = panmap::fuzz::datasetFileNames();
  const Bytes d0 = fixture("tum_tiny/depth/1.005000.png");
  const Bytes d1 = fixture("tum_tiny/depth/1.040000.png");
  const Bytes c0 = fixture("tum_tiny/rgb/1.000000.png");
  const Bytes c1 = fixture("tum_tiny/rgb/1.033000.png");
  const Bytes k3 = fixture("tum_tiny/camera-intrinsics.txt");
  const Bytes jpg = panmap::encodeJpeg(tinyFrame(0, 0).color, 80);
  seed("dataset", "tum",
       container(n, {{"rgb.txt", fixture("tum_tiny/rgb.txt")},
                     {"depth.txt", fixture("tum_tiny/depth.txt")},
                     {"groundtruth.txt", fixture("tum_tiny/groundtruth.txt")},
                     {"camera-intrinsics.txt", k3},
                     {"rgb/1.000000.png", c0},
                     {"depth/1.005000.png", d0},
                     {"rgb/1.033000.png", c1},
                     {"depth/1.040000.png", d1}}));
  seed("dataset", "7scenes",
       container(n, {{"camera-intrinsics.txt", k3},
                     {"frame-000000.color.png", c0},
                     {"frame-000000.depth.png", d0},
                     {"frame-000000.pose.txt", text(kFourByFour)},
                     {"frame-000001.color.png", c1},
                     {"frame-000001.depth.png", d1},
                     {"frame-000001.pose.txt", text("-inf -inf\n")}}));
  const std::string k4 = "10 0 3.5 0\n0 10 2.5 0\n0 0 1 0\n0 0 0 1\n";
  const std::string meta =
      "colorHeight = 6\ncolorWidth = 8\ndepthHeight = 6\ndepthWidth = 8\n"
      "colorToDepthExtrinsics = 1 0 0 0.02 0 1 0 0 0 0 1 0 0 0 0 1\n";
  seed("dataset", "scannet",
       container(n, {{"color/0.jpg", jpg},
                     {"depth/0.png", d0},
                     {"pose/0.txt", text(kFourByFour)},
                     {"color/1.jpg", jpg},
                     {"depth/1.png", d1},
                     {"intrinsic/intrinsic_depth.txt", text(k4)},
                     {"intrinsic/intrinsic_color.txt", text(k4)},
                     {"scene0000_00.txt", text(meta)}}));
  seed("dataset", "scannet_extrinsics",
       container(n, {{"color/0.png", c0},
                     {"depth/0.png", d0},
                     {"intrinsic/intrinsic_depth.txt", text(k4)},
                     {"intrinsic/intrinsic_color.txt", text(k4)},
                     {"intrinsic/extrinsic_color.txt", text(kFourByFour)},
                     {"intrinsic/extrinsic_depth.txt", text(kFourByFour)}}));
  // A .sens recording: two frames, JPEG colour and deflated depth, the second pose lost.
  {
    panmap::ScanNetSensHeader h;
    h.sensor_name = "StructureSensor";
    h.intrinsic_depth.topLeftCorner<2, 3>() << 10, 0, 3.5, 0, 10, 2.5;
    h.intrinsic_color = h.intrinsic_depth;
    const panmap::DepthImage depth =
        panmap::readDepthFile(g_fixtures + "/tum_tiny/depth/1.005000.png");
    h.depth_width = static_cast<uint32_t>(depth.width());
    h.depth_height = static_cast<uint32_t>(depth.height());
    h.color_width = static_cast<uint32_t>(tinyFrame(0, 0).color.width());
    h.color_height = static_cast<uint32_t>(tinyFrame(0, 0).color.height());
    std::vector<panmap::ScanNetSensFrame> frames(2);
    for (panmap::ScanNetSensFrame& f : frames) {
      f.color = jpg;
      f.depth = panmap::compressSensDepth(depth);
    }
    frames[1].camera_to_world.setConstant(-std::numeric_limits<float>::infinity());
    const std::string path = g_out + "/sens.tmp";
    panmap::writeScanNetSens(path, h, frames);
    const Bytes sens = panmap::readFileBytes(path);
    fs::remove(path);
    seed("dataset", "scannet_sens", container(n, {{"scene0000_00.sens", sens}}));
    seed("dataset", "scannet_sens_meta",
         container(n, {{"scene0000_00.sens", sens}, {"scene0000_00.txt", text(meta)}}));
  }
  // The generic layout: numbered rgb/ and depth/ images, intrinsics, TUM or 4x4 poses.
  seed("dataset", "generic_tum_poses",
       container(n, {{"rgb/000000.png", c0},
                     {"depth/000000.png", d0},
                     {"rgb/000001.png", c1},
                     {"depth/000001.png", d1},
                     {"intrinsics.txt", k3},
                     {"poses.txt", text("0 0 0 0 0 0 0 1\n0.033 0.1 0 0 0 0 0 1\n")}}));
  seed("dataset", "generic_4x4_poses",
       container(n, {{"rgb/000000.jpg", jpg},
                     {"depth/000000.png", d0},
                     {"intrinsic.txt", text("10 10 3.5 2.5\n")},
                     {"pose/000000.txt", text(kFourByFour)},
                     {"gt_pose.txt", text(kFourByFour)}}));
}

void cocoSeeds() {
  const auto& n = panmap::fuzz::cocoFileNames();
  seed("coco_panoptic", "coco_file",
       container(n, {{"panoptic.json", fixture("coco_tiny/panoptic.json")},
                     {"labels.tsv", fixture("coco_tiny/labels.tsv")},
                     {"masks/frame-000000.color.png",
                      fixture("coco_tiny/panoptic/frame-000000.color.png")}}));
  seed(
      "coco_panoptic", "per_frame",
      container(
          n,
          {{"masks/frame-000000.color.png", fixture("coco_tiny/perframe/frame-000000.color.png")},
           {"masks/frame-000000.color.json", fixture("coco_tiny/perframe/frame-000000.color.json")},
           {"masks/0.png", panmap::encodeLabelPng(tinyPanoptic(0, 0).segment_ids)},
           {"masks/0.json", text(R"([{"id": 1, "category_id": 3}])")}}));
}

void scannetGtSeeds() {
  const auto& n = panmap::fuzz::scannetGtFileNames();
  const std::string tsv =
      "id\traw_category\tcategory\tcount\tnyu40id\n1\twall\twall\t8277\t1\n"
      "2\tchair\tchair\t4646\t5\n3\tkitchen cabinets\tcabinet\t100\t3\n"
      "4\ttrash bin\ttrash can\t100\t39\n";
  seed("scannet_gt", "scene",
       container(
           n, {{"scene_vh_clean_2.ply", fixture("scannet_gt_tiny/scene0000_00_vh_clean_2.ply")},
               {"scene.aggregation.json", fixture("scannet_gt_tiny/scene0000_00.aggregation.json")},
               {"scene_vh_clean_2.0.010000.segs.json",
                fixture("scannet_gt_tiny/scene0000_00_vh_clean_2.0.010000.segs.json")},
               {"labels.combined.tsv", text(tsv)},
               {"scene_vh_clean_2.labels.ply",
                fixture("scannet_gt_tiny/scene0000_00_vh_clean_2.labels.ply")}}));
}

panmap::MapperConfig smallMapperConfig() {
  panmap::MapperConfig config;
  config.num_threads = 1;
  return config;
}

void mapSeeds() {
  const std::string tmp = panmap::fuzz::scratchDir() + "/seed.panmap";
  const auto add = [&](const std::string& name, const panmap::Mapper& mapper) {
    mapper.save(tmp);
    const Bytes file = panmap::readFileBytes(tmp);
    // Odd first byte: payload only (the target adds header and checksum).
    Bytes payload = {1};
    payload.insert(payload.end(), file.begin() + 20, file.end() - 4);
    seed("map_file", name + "_payload", payload);
    Bytes whole = {0};
    whole.insert(whole.end(), file.begin(), file.end());
    seed("map_file", name + "_file", whole);
  };
  panmap::Mapper empty(smallMapperConfig());
  add("empty", empty);
  // Coarse voxels and a camera inside one block keep the mapped seed to a block or two (a
  // block is 22.5 KB).
  panmap::MapperConfig coarse = smallMapperConfig();
  coarse.map.voxel_size_m = 0.2f;
  panmap::Mapper mapped(coarse);
  const panmap::PanopticFrame p = tinyPanoptic(1000, 0);
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  T_W_C.translation() = Eigen::Vector3d(0.8, 0.8, 0.3);
  mapped.integrate(tinyFrame(1000, 0), T_W_C, &p, panmap::PoseSource::kGroundTruth);
  std::cout << "map_file seed: " << mapped.map().numBlocks() << " blocks\n";
  add("one_frame", mapped);
}

panmap::SuperpointGraph tinyGraph() {
  panmap::SuperpointGraph g;
  g.classes = {1, 5, 39};
  g.background = {1};
  g.voxel_size_m = 0.02;
  for (int i = 1; i <= 3; ++i) {
    panmap::GraphVertex v;
    v.id = i;
    v.num_voxels = 10 * i;
    v.centroid = Eigen::Vector3d(0.1 * i, 0.0, 1.0);
    v.instance = i == 1 ? 0 : 1;
    v.semantic = i == 1 ? 1 : 5;
    v.scores = {{1, i == 1 ? 0.9 : 0.1}, {5, i == 1 ? 0.1 : 0.8}};
    g.vertices.push_back(v);
  }
  panmap::GraphEdge e;
  e.a = 2;
  e.b = 3;
  e.confidences = {{5, 0.7}};
  e.separations = {{5, 0.1}};
  e.apart = 0.05;
  g.edges.push_back(e);
  e.a = 1;
  e.b = 2;
  e.confidences = {{1, 0.1}};
  e.separations = {};
  e.apart = 0.5;
  g.edges.push_back(e);
  return g;
}

void lcmSeeds() {
  const panmap::RgbdFrame f = tinyFrame(1000, 0);
  using panmap::image_t;
  seed("lcm_messages", "rgbd_raw",
       selected(0, panmap::toMessage(
                       f, encodingOf(image_t::COMPRESSION_NONE, image_t::COMPRESSION_NONE))));
  seed("lcm_messages", "rgbd_png",
       selected(0, panmap::toMessage(
                       f, encodingOf(image_t::COMPRESSION_PNG, image_t::COMPRESSION_PNG))));
  seed("lcm_messages", "rgbd_jpeg",
       selected(0, panmap::toMessage(
                       f, encodingOf(image_t::COMPRESSION_JPEG, image_t::COMPRESSION_NONE))));
  seed("lcm_messages", "pose", selected(1, panmap::toMessage(tinyPose(1000, 0, 0.5))));
  const panmap::PanopticFrame p = tinyPanoptic(1000, 0);
  seed("lcm_messages", "panoptic_raw",
       selected(2, panmap::toMessage(p, encodingOf(0, image_t::COMPRESSION_NONE))));
  seed("lcm_messages", "panoptic_png",
       selected(2, panmap::toMessage(p, encodingOf(0, image_t::COMPRESSION_PNG))));
  panmap::status_t status{};  // LCM types leave plain fields uninitialised
  status.utime = 5;
  status.state = "mapping";
  status.num_reject_reasons = 2;
  status.reject_reasons = {"nan pose", "malformed CAMERA_RGBD"};
  status.reject_counts = {3, 1};
  status.num_stages = 1;
  status.stage_names = {"integration"};
  status.stage_median_ms = {2.5f};
  status.stage_last_ms = {3.0f};
  status.depth_check = "pending";
  status.depth_pattern_mm = -1.0f;
  status.num_commands = 1;
  status.command_utimes = {4};
  status.command_states = {"failed"};
  status.command_results = {"cannot write /x/map.panmap"};
  seed("lcm_messages", "status", selected(3, status));
  panmap::MappedObject o;
  o.id = 2;
  o.class_id = 5;
  o.confidence = 0.7f;
  o.num_voxels = 40;
  o.aabb_max_W = Eigen::Vector3d(0.5, 0.5, 0.8);
  o.obb_extent_m = Eigen::Vector3d(0.5, 0.4, 0.8);
  o.superpoints = {2, 3};
  seed("lcm_messages", "objects", selected(4, panmap::toMessage({o}, 7)));
  octomap::OcTree tree(0.1);
  tree.updateNode(octomap::point3d(0.05f, 0.05f, 0.05f), true);
  tree.updateNode(octomap::point3d(0.35f, -0.15f, 0.05f), false);
  panmap::octomap_t octo{};
  octo.utime = 9;
  octo.resolution_m = 0.1;
  octo.tree_type = "OcTree";
  octo.binary = true;
  const std::string data = panmap::toBinaryData(tree);
  octo.data.assign(data.begin(), data.end());
  octo.size = static_cast<int32_t>(octo.data.size());
  seed("lcm_messages", "octomap", selected(5, octo));
  seed("lcm_messages", "graph", selected(6, panmap::toMessage(tinyGraph(), 11, 1)));
  panmap::GraphLabels labels;
  labels.semantic = {{1, 1}, {2, 5}, {3, 5}};
  labels.instance = {{1, 0}, {2, 1}, {3, 1}};
  labels.instance_confidence = {{1, 0.9f}};
  labels.instance_evidence = {{1, panmap::ObjectEvidence{0.2f, 3.0f, 0.8f}}};
  seed("lcm_messages", "labels", selected(7, panmap::toMessage(labels, 12, 1)));
  panmap::command_t command{};
  command.utime = 13;
  command.command = panmap::command_t::COMMAND_SAVE;
  command.argument = "/tmp/map.panmap";
  seed("lcm_messages", "command", selected(8, command));
  panmap::PoseCorrection correction;
  correction.utime = 14;
  correction.correction_id = 1;
  correction.poses = {tinyPose(1000, 0, 0.5), tinyPose(100000, 1, 0.6)};
  seed("lcm_messages", "pose_correction", selected(9, panmap::toMessage(correction)));

  // The session: two frames with poses and masks, one without a pose, noise on the side.
  std::vector<Entry> stream;
  for (int i = 0; i < 2; ++i) {
    const int64_t t = 1000 + 33000 * i;
    stream.push_back(
        {0, body(panmap::toMessage(tinyFrame(t, i), encodingOf(image_t::COMPRESSION_NONE,
                                                               image_t::COMPRESSION_PNG)))});
    stream.push_back(
        {2, body(panmap::toMessage(tinyPanoptic(t, i), encodingOf(0, image_t::COMPRESSION_NONE)))});
    stream.push_back({1, body(panmap::toMessage(tinyPose(t, i, 0.01 * i)))});
  }
  stream.push_back({0, body(panmap::toMessage(tinyFrame(70000, 2), panmap::ImageEncoding{}))});
  stream.push_back({3, body(status)});
  stream.push_back({0x81, text("not a pose")});
  seed("lcm_session", "two_frames", panmap::fuzz::pack(stream));

  // Check that the session seed maps frames (else the seed would teach the fuzzer little).
  panmap::Mapper mapper(smallMapperConfig());
  panmap::MappingSession session(panmap::SessionOptions{}, &mapper);
  for (const Entry& e : stream) {
    Bytes bytes;
    const char* channel[] = {"CAMERA_RGBD", "CAMERA_POSE", "PANOPTIC", "PANMAP_STATUS"};
    if (e.name & 0x80) {
      bytes = e.bytes;
    } else if ((e.name & 3) == 0) {
      bytes = panmap::fuzz::withFingerprint<panmap::rgbd_frame_t>(e.bytes.data(), e.bytes.size());
    } else if ((e.name & 3) == 1) {
      bytes = panmap::fuzz::withFingerprint<panmap::pose_t>(e.bytes.data(), e.bytes.size());
    } else if ((e.name & 3) == 2) {
      bytes = panmap::fuzz::withFingerprint<panmap::panoptic_t>(e.bytes.data(), e.bytes.size());
    } else {
      bytes = e.bytes;
    }
    session.handle(channel[e.name & 3], bytes.data(), bytes.size());
  }
  session.flush();
  const panmap::SessionStats stats = session.stats();
  std::cout << "lcm_session seed: " << stats.frames_received << " frames received, "
            << stats.frames_integrated << " integrated\n";
  for (const auto& [reason, n] : stats.rejected)
    std::cout << "  rejected " << reason << ": " << n << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: panmap-fuzz-seeds FIXTURE_DIR REPO_DIR OUT_DIR\n";
    return 2;
  }
  g_fixtures = argv[1];
  g_repo = argv[2];
  g_out = argv[3];
  try {
    imageSeeds();
    plySeeds();
    configSeeds();
    textSeeds();
    datasetSeeds();
    cocoSeeds();
    scannetGtSeeds();
    mapSeeds();
    lcmSeeds();
  } catch (const std::exception& e) {
    std::cerr << "panmap-fuzz-seeds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
