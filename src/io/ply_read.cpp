#include "panmap/io/ply.h"

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "panmap/core/error.h"
#include "panmap/io/internal/ply_format.h"
#include "panmap/io/text_files.h"

namespace panmap {
namespace {

using internal::ply::assignTargets;
using internal::ply::Element;
using internal::ply::Encoding;
using internal::ply::Header;
using internal::ply::hostIsLittleEndian;
using internal::ply::isInteger;
using internal::ply::parseHeader;
using internal::ply::Property;
using internal::ply::ScalarType;
using internal::ply::Target;

// Value ranges of the integer types, indexed by ScalarType.
constexpr long long kIntegerMin[] = {-128, 0, -32768, 0, -2147483648LL, 0};
constexpr long long kIntegerMax[] = {127, 255, 32767, 65535, 2147483647LL, 4294967295LL};

const int32_t kInt32Min = std::numeric_limits<int32_t>::min();
const int32_t kInt32Max = std::numeric_limits<int32_t>::max();

// Position in the body, for messages.
struct Location {
  const Element* element = nullptr;
  size_t row = 0;
  std::string describe() const {
    return "element " + element->name + " row " + std::to_string(row) + " of " +
           std::to_string(element->count);
  }
};

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

}  // namespace panmap
