#include "panmap/io/internal/ply_format.h"

#include <charconv>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "panmap/core/error.h"

namespace panmap {
namespace internal {
namespace ply {
namespace {

bool parseScalarType(const std::string& name, ScalarType* type) {
  static const struct {
    const char* name;
    ScalarType type;
  } kTypes[] = {{"char", ScalarType::kInt8},      {"int8", ScalarType::kInt8},
                {"uchar", ScalarType::kUint8},    {"uint8", ScalarType::kUint8},
                {"short", ScalarType::kInt16},    {"int16", ScalarType::kInt16},
                {"ushort", ScalarType::kUint16},  {"uint16", ScalarType::kUint16},
                {"int", ScalarType::kInt32},      {"int32", ScalarType::kInt32},
                {"uint", ScalarType::kUint32},    {"uint32", ScalarType::kUint32},
                {"float", ScalarType::kFloat32},  {"float32", ScalarType::kFloat32},
                {"double", ScalarType::kFloat64}, {"float64", ScalarType::kFloat64}};
  for (const auto& t : kTypes) {
    if (name == t.name) {
      *type = t.type;
      return true;
    }
  }
  return false;
}

std::vector<std::string> splitWords(const std::string& line) {
  std::vector<std::string> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) words.push_back(line.substr(i, j - i));
    i = j;
  }
  return words;
}

bool parseCount(const std::string& text, size_t* count) {
  const char* end = text.data() + text.size();
  unsigned long long value = 0;
  const auto result = std::from_chars(text.data(), end, value);
  if (result.ec != std::errc() || result.ptr != end) return false;
  if (value > std::numeric_limits<size_t>::max()) return false;
  *count = static_cast<size_t>(value);
  return true;
}

}  // namespace

Header parseHeader(const std::string& data, const std::string& path) {
  // The magic line decides whether this is a PLY file at all, before any other complaint.
  if (data.compare(0, 4, "ply\n") != 0 && data.compare(0, 5, "ply\r\n") != 0) {
    throw Error(path + ": not a PLY file (first line is not 'ply')");
  }
  Header header;
  bool have_format = false;
  size_t pos = data.find('\n') + 1;
  int line_number = 1;
  while (pos < data.size()) {
    const size_t eol = data.find('\n', pos);
    const size_t next = eol == std::string::npos ? data.size() : eol + 1;
    std::string line = data.substr(pos, (eol == std::string::npos ? data.size() : eol) - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = next;
    ++line_number;
    const std::string where = path + ": header line " + std::to_string(line_number) + ": ";
    const std::vector<std::string> w = splitWords(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (w.size() != 3) throw Error(where + "expected 'format <encoding> 1.0'");
      if (w[1] == "ascii") {
        header.encoding = Encoding::kAscii;
      } else if (w[1] == "binary_little_endian") {
        header.encoding = Encoding::kBinaryLittleEndian;
      } else if (w[1] == "binary_big_endian") {
        header.encoding = Encoding::kBinaryBigEndian;
      } else {
        throw Error(where + "unsupported PLY format '" + w[1] + "'");
      }
      if (w[2] != "1.0") throw Error(where + "unsupported PLY version '" + w[2] + "'");
      have_format = true;
    } else if (w[0] == "element") {
      Element element;
      if (w.size() != 3 || !parseCount(w[2], &element.count)) {
        throw Error(where + "expected 'element <name> <count>'");
      }
      element.name = w[1];
      for (const Element& e : header.elements) {
        if (e.name == element.name) throw Error(where + "element " + w[1] + " declared twice");
      }
      header.elements.push_back(element);
    } else if (w[0] == "property") {
      if (header.elements.empty()) throw Error(where + "property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        p.is_list = true;
        if (!parseScalarType(w[2], &p.count_type) || !parseScalarType(w[3], &p.type)) {
          throw Error(where + "unknown type in '" + line + "'");
        }
        if (!isInteger(p.count_type)) throw Error(where + "list count type must be an integer");
        p.name = w[4];
      } else if (w.size() == 3) {
        if (!parseScalarType(w[1], &p.type)) throw Error(where + "unknown type '" + w[1] + "'");
        p.name = w[2];
      } else {
        throw Error(where + "expected 'property <type> <name>' or 'property list ...'");
      }
      std::vector<Property>& properties = header.elements.back().properties;
      for (const Property& q : properties) {
        if (q.name == p.name) throw Error(where + "property " + p.name + " declared twice");
      }
      properties.push_back(p);
    } else if (w[0] == "end_header") {
      if (w.size() != 1) throw Error(where + "unexpected words after end_header");
      if (!have_format) throw Error(path + ": PLY header has no format line");
      header.data_offset = pos;
      return header;
    } else {
      throw Error(where + "unexpected '" + w[0] + "'");
    }
  }
  throw Error(path + ": PLY header has no end_header line");
}

size_t assignTargets(Header* header, const std::string& path, const std::string& extra_name) {
  static const struct {
    const char* name;
    Target target;
    int slot;
  } kVertexProperties[] = {{"x", Target::kPosition, 0},
                           {"y", Target::kPosition, 1},
                           {"z", Target::kPosition, 2},
                           {"red", Target::kColour, 0},
                           {"green", Target::kColour, 1},
                           {"blue", Target::kColour, 2},
                           {"semantic", Target::kLabel, kSemanticSlot},
                           {"instance", Target::kLabel, kInstanceSlot},
                           {"superpoint", Target::kLabel, kSuperpointSlot}};
  size_t vertex_index = header->elements.size();
  for (size_t i = 0; i < header->elements.size(); ++i) {
    Element& element = header->elements[i];
    if (element.name == "vertex") {
      vertex_index = i;
      for (Property& p : element.properties) {
        if (!extra_name.empty() && p.name == extra_name) {
          p.target = Target::kLabel;
          p.slot = kExtraSlot;
        } else {
          for (const auto& known : kVertexProperties) {
            if (p.name == known.name) {
              p.target = known.target;
              p.slot = known.slot;
            }
          }
        }
        if (p.target == Target::kSkip) continue;
        if (p.is_list) throw Error(path + ": vertex property " + p.name + " must not be a list");
        const bool position = p.target == Target::kPosition;
        if (position && isInteger(p.type)) {
          throw Error(path + ": vertex property " + p.name + " must be float or double");
        }
        if (!position && !isInteger(p.type)) {
          throw Error(path + ": vertex property " + p.name + " must be of an integer type");
        }
      }
    } else if (element.name == "face") {
      bool found = false;
      for (Property& p : element.properties) {
        if (found || !p.is_list || (p.name != "vertex_indices" && p.name != "vertex_index")) {
          continue;
        }
        if (!isInteger(p.type)) throw Error(path + ": face " + p.name + " must hold integers");
        p.target = Target::kFaceIndices;
        found = true;
      }
      if (!found && element.count > 0) {
        throw Error(path + ": face element has no list property vertex_indices");
      }
    }
  }
  if (vertex_index == header->elements.size()) throw Error(path + ": no vertex element");
  const std::vector<Property>& vp = header->elements[vertex_index].properties;
  auto has = [&vp](Target target, int slot) {
    for (const Property& p : vp) {
      if (p.target == target && p.slot == slot) return true;
    }
    return false;
  };
  for (int axis = 0; axis < 3; ++axis) {
    if (!has(Target::kPosition, axis)) {
      throw Error(path + ": vertex element has no property " + "xyz"[axis]);
    }
  }
  const int colours = has(Target::kColour, 0) + has(Target::kColour, 1) + has(Target::kColour, 2);
  if (colours != 0 && colours != 3) {
    throw Error(path + ": vertex element has only some of red, green, blue");
  }
  if (!extra_name.empty() && !has(Target::kLabel, kExtraSlot)) {
    throw Error(path + ": vertex element has no property " + extra_name);
  }
  return vertex_index;
}

}  // namespace ply
}  // namespace internal
}  // namespace panmap
