#include "panmap/io/ply.h"

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>

#include "panmap/core/error.h"
#include "panmap/io/internal/ply_format.h"

namespace panmap {
namespace {

using internal::ply::hostIsLittleEndian;

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
