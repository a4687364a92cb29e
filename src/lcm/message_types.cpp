#include "panmap/lcm/message_types.h"

#include <cstring>
#include <exception>

#include "panmap/command_t.hpp"
#include "panmap/core/error.h"
#include "panmap/graph_labels_t.hpp"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/object_list_t.hpp"
#include "panmap/octomap_t.hpp"
#include "panmap/panoptic_t.hpp"
#include "panmap/pose_correction_t.hpp"
#include "panmap/pose_t.hpp"
#include "panmap/rgbd_frame_t.hpp"
#include "panmap/status_t.hpp"
#include "panmap/superpoint_graph_t.hpp"

namespace panmap {
namespace {

// Content checks beyond decoding: images decode to their declared sizes, values are sane.
void deepCheck(const rgbd_frame_t& m) { fromMessage(m); }
void deepCheck(const pose_t& m) { fromMessage(m); }
void deepCheck(const panoptic_t& m) { fromMessage(m); }
void deepCheck(const pose_correction_t& m) { fromMessage(m); }
template <typename T>
void deepCheck(const T&) {}

template <typename T>
MessageCheck decodeAs(const char* name, const void* data, size_t size, bool deep) {
  MessageCheck check;
  check.type = name;
  T msg;
  int used = -1;
  try {
    used = msg.decode(data, 0, static_cast<int>(size));
  } catch (const std::exception& e) {
    // Generated decoders resize arrays from length fields before reading them.
    check.error = std::string("does not decode as ") + name + " (" + e.what() + ")";
    return check;
  }
  if (used < 0) {
    check.error = std::string("does not decode as ") + name + " (truncated or malformed)";
    return check;
  }
  if (static_cast<size_t>(used) != size) {
    check.error = std::string("decodes as ") + name + " but " + std::to_string(size - used) +
                  " trailing bytes remain";
    return check;
  }
  check.utime = msg.utime;
  if (deep) {
    try {
      deepCheck(msg);
    } catch (const std::exception& e) {
      check.error = e.what();
      return check;
    }
  }
  check.ok = true;
  return check;
}

struct TypeEntry {
  const char* name;
  int64_t hash;
  MessageCheck (*check)(const char*, const void*, size_t, bool);
};

#define PANMAP_TYPE(T) \
  TypeEntry { #T, T::getHash(), &decodeAs < T> }

const std::vector<TypeEntry>& types() {
  static const std::vector<TypeEntry> kTypes = {
      PANMAP_TYPE(rgbd_frame_t),       PANMAP_TYPE(pose_t),         PANMAP_TYPE(panoptic_t),
      PANMAP_TYPE(status_t),           PANMAP_TYPE(object_list_t),  PANMAP_TYPE(octomap_t),
      PANMAP_TYPE(superpoint_graph_t), PANMAP_TYPE(graph_labels_t), PANMAP_TYPE(command_t),
      PANMAP_TYPE(pose_correction_t)};
  return kTypes;
}

#undef PANMAP_TYPE

}  // namespace

MessageCheck checkMessage(const void* data, size_t size, bool deep) {
  MessageCheck unknown;
  if (size < 8) {
    unknown.error = "shorter than an LCM fingerprint (" + std::to_string(size) + " bytes)";
    return unknown;
  }
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | b[i];  // big-endian on the wire
  for (const TypeEntry& t : types()) {
    if (static_cast<uint64_t>(t.hash) == hash) return t.check(t.name, data, size, deep);
  }
  unknown.error = "fingerprint matches no panmap type";
  return unknown;
}

std::vector<std::string> messageTypeNames() {
  std::vector<std::string> names;
  for (const TypeEntry& t : types()) names.push_back(t.name);
  return names;
}

}  // namespace panmap
