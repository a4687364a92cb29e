#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace panmap {
namespace internal {
namespace ply {

/// Body encodings a PLY header may declare.
enum class Encoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

/// PLY scalar types (each has two names in the header).
enum class ScalarType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

/// Where the value of a property goes; Property::slot says which axis, channel or label array.
enum class Target { kSkip, kPosition, kColour, kLabel, kFaceIndices };

/// Label arrays by slot; kExtraSlot is readPlyVertexIntProperty's.
enum LabelSlot { kSemanticSlot = 0, kInstanceSlot, kSuperpointSlot, kExtraSlot };

/// One `property` line of the header, and where its values go.
struct Property {
  std::string name;
  bool is_list = false;
  ScalarType count_type = ScalarType::kUint8;  ///< lists only
  ScalarType type = ScalarType::kFloat32;      ///< the value, or each list item
  Target target = Target::kSkip;
  int slot = 0;
};

/// One `element` line of the header with its properties.
struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

/// A parsed PLY header.
struct Header {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  size_t data_offset = 0;  ///< first byte after the end_header line
};

/// True for the integer scalar types.
inline bool isInteger(ScalarType t) {
  return t != ScalarType::kFloat32 && t != ScalarType::kFloat64;
}

/// True when this machine stores the low byte first (binary PLY names its byte order).
inline bool hostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

/// Parses the header at the start of a whole PLY file. Throws Error naming `path` and the line
/// on a bad header; all targets are kSkip.
Header parseHeader(const std::string& data, const std::string& path);

/// Decides where each property goes (x y z, red green blue, semantic instance superpoint, the
/// face indices, and `extra_name` into kExtraSlot when not empty) and checks the types panmap
/// relies on. Returns the index of the vertex element. Throws Error naming `path`.
size_t assignTargets(Header* header, const std::string& path, const std::string& extra_name);

}  // namespace ply
}  // namespace internal
}  // namespace panmap
