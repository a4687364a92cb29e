// Feeds each panmap LCM message type (chosen by the first byte; the rest is the encoded body
// after the fingerprint) to decodeExactly, its conversion and checkMessage.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "lcm_fingerprint.h"
#include "panmap/command_t.hpp"
#include "panmap/graph/optimiser.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/decode.h"
#include "panmap/lcm/graph_conversions.h"
#include "panmap/lcm/message_types.h"
#include "panmap/lcm/object_conversions.h"
#include "panmap/occupancy/octree_io.h"
#include "panmap/octomap_t.hpp"
#include "panmap/status_t.hpp"

namespace {

// What each receiver does with a decoded message; Error / std::exception means refused.
void convert(const panmap::rgbd_frame_t& m) { panmap::fromMessage(m); }
void convert(const panmap::pose_t& m) { panmap::fromMessage(m); }
void convert(const panmap::panoptic_t& m) { panmap::fromMessage(m); }
void convert(const panmap::object_list_t& m) { panmap::fromMessage(m); }
void convert(const panmap::graph_labels_t& m) { panmap::fromMessage(m); }
void convert(const panmap::superpoint_graph_t& m) {
  // panmap-optimizer answers every graph that converts (OptimizerNode::onGraph).
  panmap::optimise(panmap::fromMessage(m), panmap::OptimiserConfig{});
}
void convert(const panmap::octomap_t& m) {
  // What panmap-occupancy-probe does with the planners' tree.
  if (m.tree_type != "OcTree") return;
  panmap::treeFromBinaryData(std::string(m.data.begin(), m.data.end()), m.resolution_m);
}
void convert(const panmap::pose_correction_t& m) {
  // Applied to the trajectory the map was built with (three frames 0.1 s apart here).
  static const std::vector<panmap::StampedPose> kTrajectory = [] {
    std::vector<panmap::StampedPose> t(3);
    for (int i = 0; i < 3; ++i) t[i].utime = 1000 + 100000 * i;
    return t;
  }();
  panmap::applyCorrection(kTrajectory, panmap::fromMessage(m), 50000);
}
void convert(const panmap::status_t&) {}   // read field by field by tools only
void convert(const panmap::command_t&) {}  // switch on the command (LiveMapper::onCommand)

template <typename T>
void fuzzType(const uint8_t* body, size_t size) {
  const std::vector<uint8_t> bytes = panmap::fuzz::withFingerprint<T>(body, size);
  T msg;
  if (panmap::decodeExactly(bytes.data(), bytes.size(), &msg)) {
    try {
      convert(msg);
    } catch (const std::exception&) {
    }
  }
  // panmap-loginfo's check of every logged message (never throws).
  panmap::checkMessage(bytes.data(), bytes.size(), /*deep=*/true);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const uint8_t* body = data + 1;
  const size_t n = size - 1;
  switch (data[0] % 10) {
    case 0:
      fuzzType<panmap::rgbd_frame_t>(body, n);
      break;
    case 1:
      fuzzType<panmap::pose_t>(body, n);
      break;
    case 2:
      fuzzType<panmap::panoptic_t>(body, n);
      break;
    case 3:
      fuzzType<panmap::status_t>(body, n);
      break;
    case 4:
      fuzzType<panmap::object_list_t>(body, n);
      break;
    case 5:
      fuzzType<panmap::octomap_t>(body, n);
      break;
    case 6:
      fuzzType<panmap::superpoint_graph_t>(body, n);
      break;
    case 7:
      fuzzType<panmap::graph_labels_t>(body, n);
      break;
    case 8:
      fuzzType<panmap::command_t>(body, n);
      break;
    default:
      fuzzType<panmap::pose_correction_t>(body, n);
      break;
  }
  return 0;
}
