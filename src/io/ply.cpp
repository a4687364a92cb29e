#include "panmap/io/ply.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "panmap/core/error.h"
#include "panmap/io/text_files.h"

namespace panmap {
namespace {

enum class Encoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

enum class ScalarType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

// Where the value of a property goes; Property::slot says which axis, channel or label array.
enum class Target { kSkip, kPosition, kColour, kLabel, kFaceIndices };

// Label arrays by slot; kExtraSlot is readPlyVertexIntProperty's.
enum LabelSlot { kSemanticSlot = 0, kInstanceSlot, kSuperpointSlot, kExtraSlot };

struct Property {
  std::string name;
  bool is_list = false;
  ScalarType count_type = ScalarType::kUint8;  // lists only
  ScalarType type = ScalarType::kFloat32;      // the value, or each list item
  Target target = Target::kSkip;
  int slot = 0;
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  size_t data_offset = 0;  // first byte after the end_header line
};

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

bool isInteger(ScalarType t) { return t != ScalarType::kFloat32 && t != ScalarType::kFloat64; }

// Value ranges of the integer types, indexed by ScalarType.
constexpr long long kIntegerMin[] = {-128, 0, -32768, 0, -2147483648LL, 0};
constexpr long long kIntegerMax[] = {127, 255, 32767, 65535, 2147483647LL, 4294967295LL};

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

const int32_t kInt32Min = std::numeric_limits<int32_t>::min();
const int32_t kInt32Max = std::numeric_limits<int32_t>::max();

// Decides where each property goes and checks the types panmap relies on. Returns the index
// of the vertex element.
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

// Position in the body, for messages.
struct Location {
  const Element* element = nullptr;
  size_t row = 0;
  std::string describe() const {
    return "element " + element->name + " row " + std::to_string(row) + " of " +
           std::to_string(element->count);
  }
};

bool hostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

template <typename T>
T loadBytes(const char* p, bool swap) {
  T value;
  if (!swap) {
    std::memcpy(&value, p, sizeof(T));
  } else {
    char bytes[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) bytes[i] = p[sizeof(T) - 1 - i];
    std::memcpy(&value, bytes, sizeof(T));
  }
  return value;
}

// Binary body: values straight from the file buffer. Every PLY scalar type converts to double
// exactly, so one value type serves all properties.
class BinarySource {
 public:
  BinarySource(const std::string& data, size_t offset, bool big_endian, const std::string& path)
      : p_(data.data() + offset),
        end_(data.data() + data.size()),
        swap_(big_endian == hostIsLittleEndian()),
        path_(path) {}

  Location location;

  double next(ScalarType type) {
    switch (type) {
      case ScalarType::kInt8:
        return take<int8_t>();
      case ScalarType::kUint8:
        return take<uint8_t>();
      case ScalarType::kInt16:
        return take<int16_t>();
      case ScalarType::kUint16:
        return take<uint16_t>();
      case ScalarType::kInt32:
        return take<int32_t>();
      case ScalarType::kUint32:
        return take<uint32_t>();
      case ScalarType::kFloat32:
        return take<float>();
      case ScalarType::kFloat64:
        return take<double>();
    }
    return 0.0;
  }

  size_t remainingBytes() const { return static_cast<size_t>(end_ - p_); }

  void finish() const {
    if (p_ != end_) {
      throw Error(path_ + ": " + std::to_string(end_ - p_) + " bytes after the last element");
    }
  }

 private:
  template <typename T>
  double take() {
    if (static_cast<size_t>(end_ - p_) < sizeof(T)) {
      throw Error(path_ + ": truncated binary data in " + location.describe());
    }
    const T value = loadBytes<T>(p_, swap_);
    p_ += sizeof(T);
    return static_cast<double>(value);
  }

  const char* p_;
  const char* end_;
  bool swap_;
  const std::string& path_;
};

// Ascii body: whitespace-separated tokens; integers must be written as integers in range.
class AsciiSource {
 public:
  AsciiSource(const std::string& data, size_t offset, const std::string& path)
      : p_(data.data() + offset), end_(data.data() + data.size()), path_(path) {}

  Location location;

  double next(ScalarType type) {
    skipSpace();
    if (p_ == end_) throw Error(path_ + ": truncated ascii data in " + location.describe());
    const char* token_end = p_;
    while (token_end != end_ && !isSpace(*token_end)) ++token_end;
    const std::string token(p_, token_end);
    double value = 0.0;
    bool ok = false;
    if (isInteger(type)) {
      long long integer = 0;
      const auto result = std::from_chars(token.data(), token.data() + token.size(), integer);
      ok = result.ec == std::errc() && result.ptr == token.data() + token.size() &&
           integer >= kIntegerMin[static_cast<int>(type)] &&
           integer <= kIntegerMax[static_cast<int>(type)];
      value = static_cast<double>(integer);
    } else {
      // strtof for float properties: reading through double could round twice.
      char* parsed_end = nullptr;
      value = type == ScalarType::kFloat32 ? std::strtof(token.c_str(), &parsed_end)
                                           : std::strtod(token.c_str(), &parsed_end);
      ok = parsed_end == token.c_str() + token.size() && !token.empty();
    }
    if (!ok) {
      throw Error(path_ + ": bad ascii value '" + token + "' in " + location.describe());
    }
    p_ = token_end;
    return value;
  }

  size_t remainingBytes() const { return static_cast<size_t>(end_ - p_); }

  void finish() {
    skipSpace();
    if (p_ != end_) throw Error(path_ + ": unexpected data after the last element");
  }

 private:
  static bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }
  void skipSpace() {
    while (p_ != end_ && isSpace(*p_)) ++p_;
  }

  const char* p_;
  const char* end_;
  const std::string& path_;
};

// Reads the list length; the header already checked the count type is an integer.
template <class Source>
size_t readListCount(Source* src, const Property& p, const std::string& path) {
  const double n = src->next(p.count_type);
  if (n < 0) {
    throw Error(path + ": negative list length in " + src->location.describe());
  }
  return static_cast<size_t>(n);
}

template <class Source>
void skipProperty(Source* src, const Property& p, const std::string& path) {
  if (!p.is_list) {
    src->next(p.type);
    return;
  }
  const size_t n = readListCount(src, p, path);
  for (size_t k = 0; k < n; ++k) src->next(p.type);
}

int32_t toInt32(double value, const Property& p, const Location& at, const std::string& path) {
  if (value < kInt32Min || value > kInt32Max) {
    throw Error(path + ": " + p.name + " value " + std::to_string(static_cast<long long>(value)) +
                " does not fit int32 in " + at.describe());
  }
  return static_cast<int32_t>(value);
}

uint8_t toColour(double value, const Property& p, const Location& at, const std::string& path) {
  if (value < 0 || value > 255) {
    throw Error(path + ": " + p.name + " value " + std::to_string(static_cast<long long>(value)) +
                " is not in 0..255 in " + at.describe());
  }
  return static_cast<uint8_t>(value);
}

template <class Source>
void readVertices(Source* src, const Element& element, const std::string& path, LabelledMesh* mesh,
                  std::vector<int32_t>* extra) {
  // Every row takes at least one byte, so a count beyond the file size is a truncation; this
  // check also keeps a corrupt count from allocating without bound.
  if (element.count > src->remainingBytes()) {
    throw Error(path + ": truncated data: " + std::to_string(element.count) +
                " vertices declared, " + std::to_string(src->remainingBytes()) + " bytes left");
  }
  const size_t n = element.count;
  std::vector<int32_t>* labels[] = {&mesh->semantic, &mesh->instance, &mesh->superpoint, extra};
  mesh->vertices.resize(n);
  for (const Property& p : element.properties) {
    if (p.target == Target::kColour) mesh->colors.resize(n);
    if (p.target == Target::kLabel) labels[p.slot]->resize(n);
  }
  for (size_t v = 0; v < n; ++v) {
    src->location.row = v;
    for (const Property& p : element.properties) {
      if (p.target == Target::kSkip) {
        skipProperty(src, p, path);
        continue;
      }
      const double value = src->next(p.type);
      if (p.target == Target::kPosition) {
        mesh->vertices[v][p.slot] = static_cast<float>(value);
      } else if (p.target == Target::kColour) {
        Rgb8& c = mesh->colors[v];
        (p.slot == 0 ? c.r : p.slot == 1 ? c.g : c.b) = toColour(value, p, src->location, path);
      } else {
        (*labels[p.slot])[v] = toInt32(value, p, src->location, path);
      }
    }
  }
}

template <class Source>
void readFaces(Source* src, const Element& element, size_t num_vertices, const std::string& path,
               LabelledMesh* mesh) {
  mesh->faces.reserve(std::min(element.count, src->remainingBytes()));
  std::vector<int32_t> corners;
  for (size_t f = 0; f < element.count; ++f) {
    src->location.row = f;
    for (const Property& p : element.properties) {
      if (p.target != Target::kFaceIndices) {
        skipProperty(src, p, path);
        continue;
      }
      const size_t n = readListCount(src, p, path);
      if (n < 3) {
        throw Error(path + ": face " + std::to_string(f) + " has " + std::to_string(n) +
                    " corners, need at least 3");
      }
      corners.clear();
      for (size_t k = 0; k < n; ++k) {
        const double index = src->next(p.type);
        if (index < 0 || index >= static_cast<double>(num_vertices)) {
          throw Error(path + ": face " + std::to_string(f) + " refers to vertex " +
                      std::to_string(static_cast<long long>(index)) + " of " +
                      std::to_string(num_vertices));
        }
        corners.push_back(static_cast<int32_t>(index));
      }
      // Fan triangulation keeps the polygon's winding in every triangle.
      for (size_t k = 1; k + 1 < n; ++k) {
        mesh->faces.emplace_back(corners[0], corners[k], corners[k + 1]);
      }
    }
  }
}

template <class Source>
void readBody(Source* src, const Header& header, size_t vertex_index, const std::string& path,
              LabelledMesh* mesh, std::vector<int32_t>* extra) {
  const size_t num_vertices = header.elements[vertex_index].count;
  if (num_vertices > static_cast<size_t>(kInt32Max)) {
    throw Error(path + ": " + std::to_string(num_vertices) + " vertices exceed int32 indices");
  }
  for (size_t i = 0; i < header.elements.size(); ++i) {
    const Element& element = header.elements[i];
    src->location.element = &element;
    src->location.row = 0;
    if (i == vertex_index) {
      readVertices(src, element, path, mesh, extra);
    } else if (element.name == "face") {
      readFaces(src, element, num_vertices, path, mesh);
    } else if (!element.properties.empty()) {
      for (size_t r = 0; r < element.count; ++r) {
        src->location.row = r;
        for (const Property& p : element.properties) skipProperty(src, p, path);
      }
    }
  }
  src->finish();
}

std::string readWholeFile(const std::string& path) {
  if (!isRegularFile(path)) throw Error("cannot read " + path + " (no such file)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read " + path);
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) throw Error("cannot read " + path);
  std::string data(static_cast<size_t>(size), '\0');
  in.read(data.data(), size);
  if (!in) throw Error("cannot read " + path);
  return data;
}

LabelledMesh readPlyImpl(const std::string& path, const std::string& extra_name,
                         std::vector<int32_t>* extra) {
  const std::string data = readWholeFile(path);
  Header header = parseHeader(data, path);
  const size_t vertex_index = assignTargets(&header, path, extra_name);
  LabelledMesh mesh;
  if (header.encoding == Encoding::kAscii) {
    AsciiSource src(data, header.data_offset, path);
    readBody(&src, header, vertex_index, path, &mesh, extra);
  } else {
    BinarySource src(data, header.data_offset, header.encoding == Encoding::kBinaryBigEndian, path);
    readBody(&src, header, vertex_index, path, &mesh, extra);
  }
  return mesh;
}

// Little-endian binary writer into a preallocated buffer.
class LittleEndianWriter {
 public:
  explicit LittleEndianWriter(char* p) : p_(p), swap_(!hostIsLittleEndian()) {}
  template <typename T>
  void put(T value) {
    std::memcpy(p_, &value, sizeof(T));
    if (swap_) {
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(p_[i], p_[sizeof(T) - 1 - i]);
    }
    p_ += sizeof(T);
  }

 private:
  char* p_;
  bool swap_;
};

template <typename T>
void appendNumber(std::string* out, T value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

}  // namespace

LabelledMesh readPly(const std::string& path) { return readPlyImpl(path, "", nullptr); }

std::vector<int32_t> readPlyVertexIntProperty(const std::string& path, const std::string& name) {
  if (name.empty() || name == "x" || name == "y" || name == "z") {
    throw Error(path + ": '" + name + "' is not an integer vertex property name");
  }
  std::vector<int32_t> values;
  readPlyImpl(path, name, &values);
  return values;
}

void writePly(const std::string& path, const LabelledMesh& mesh, PlyFormat format) {
  const std::string problem = mesh.check();
  if (!problem.empty()) throw Error(path + ": cannot write an inconsistent mesh: " + problem);
  const size_t n = mesh.numVertices();
  const bool colours = !mesh.colors.empty();
  const bool semantic = !mesh.semantic.empty();
  const bool instance = !mesh.instance.empty();
  const bool superpoint = !mesh.superpoint.empty();

  std::string header = "ply\nformat ";
  header += format == PlyFormat::kAscii ? "ascii 1.0\n" : "binary_little_endian 1.0\n";
  header += "comment written by panmap\n";
  header += "element vertex " + std::to_string(n) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  if (colours) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (semantic) header += "property int semantic\n";
  if (instance) header += "property int instance\n";
  if (superpoint) header += "property int superpoint\n";
  header += "element face " + std::to_string(mesh.numFaces()) + "\n";
  header += "property list uchar int vertex_indices\nend_header\n";

  std::string body;
  if (format == PlyFormat::kBinaryLittleEndian) {
    const size_t vertex_bytes = 12 + (colours ? 3 : 0) + 4 * (semantic + instance + superpoint);
    body.resize(n * vertex_bytes + mesh.numFaces() * 13);
    LittleEndianWriter out(body.data());
    for (size_t v = 0; v < n; ++v) {
      out.put(mesh.vertices[v].x());
      out.put(mesh.vertices[v].y());
      out.put(mesh.vertices[v].z());
      if (colours) {
        out.put(mesh.colors[v].r);
        out.put(mesh.colors[v].g);
        out.put(mesh.colors[v].b);
      }
      if (semantic) out.put(mesh.semantic[v]);
      if (instance) out.put(mesh.instance[v]);
      if (superpoint) out.put(mesh.superpoint[v]);
    }
    for (const Eigen::Vector3i& f : mesh.faces) {
      out.put(static_cast<uint8_t>(3));
      out.put(static_cast<int32_t>(f[0]));
      out.put(static_cast<int32_t>(f[1]));
      out.put(static_cast<int32_t>(f[2]));
    }
  } else {
    body.reserve(n * 48 + mesh.numFaces() * 24);
    for (size_t v = 0; v < n; ++v) {
      // to_chars(float) gives the shortest text that reads back to the same float.
      for (int k = 0; k < 3; ++k) {
        if (k > 0) body += ' ';
        appendNumber(&body, mesh.vertices[v][k]);
      }
      if (colours) {
        for (const uint8_t c : {mesh.colors[v].r, mesh.colors[v].g, mesh.colors[v].b}) {
          body += ' ';
          appendNumber(&body, static_cast<int>(c));
        }
      }
      for (const std::vector<int32_t>* labels :
           {&mesh.semantic, &mesh.instance, &mesh.superpoint}) {
        if (labels->empty()) continue;
        body += ' ';
        appendNumber(&body, (*labels)[v]);
      }
      body += '\n';
    }
    for (const Eigen::Vector3i& f : mesh.faces) {
      body += '3';
      for (int k = 0; k < 3; ++k) {
        body += ' ';
        appendNumber(&body, f[k]);
      }
      body += '\n';
    }
  }

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error("cannot write " + path);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  out.close();
  if (!out) throw Error("cannot write " + path + " (disk full?)");
}

}  // namespace panmap
