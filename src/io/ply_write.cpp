#include "panmap/io/ply.h"

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"
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
  auto column = [](const auto& values) { return values.empty() ? nullptr : &values; };
  PlyColumns columns;
  columns.vertices = &mesh.vertices;
  columns.faces = &mesh.faces;
  columns.colors = column(mesh.colors);
  columns.semantic = column(mesh.semantic);
  columns.instance = column(mesh.instance);
  columns.superpoint = column(mesh.superpoint);
  writePly(path, columns, format);
}

void writePly(const std::string& path, const PlyColumns& columns, PlyFormat format) {
  if (!columns.vertices) throw Error(path + ": cannot write a mesh without vertices");
  const size_t n = columns.vertices->size();
  const std::vector<Eigen::Vector3i> no_faces;
  const std::vector<Eigen::Vector3i>& faces = columns.faces ? *columns.faces : no_faces;
  if (columns.colors && columns.colors->size() != n) {
    throw Error(path +
                ": cannot write an inconsistent mesh: " + std::to_string(columns.colors->size()) +
                " colours for " + std::to_string(n) + " vertices");
  }
  const std::vector<int32_t>* labels[3] = {columns.semantic, columns.instance, columns.superpoint};
  const char* label_names[3] = {"semantic", "instance", "superpoint"};
  for (int k = 0; k < 3; ++k) {
    if (labels[k] && !labels[k]->empty() && labels[k]->size() != n) {
      throw Error(path +
                  ": cannot write an inconsistent mesh: " + std::to_string(labels[k]->size()) +
                  " " + label_names[k] + " labels for " + std::to_string(n) + " vertices");
    }
  }
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (faces[f][k] < 0 || static_cast<size_t>(faces[f][k]) >= n) {
        throw Error(path + ": cannot write an inconsistent mesh: face " + std::to_string(f) +
                    " uses vertex " + std::to_string(faces[f][k]) + " of " + std::to_string(n));
      }
    }
  }
  const bool colours = columns.colors != nullptr;
  // The value of label column k at vertex v (0 for a column given empty).
  auto label = [&](int k, size_t v) { return labels[k]->empty() ? 0 : (*labels[k])[v]; };

  std::string header = "ply\nformat ";
  header += format == PlyFormat::kAscii ? "ascii 1.0\n" : "binary_little_endian 1.0\n";
  header += "comment written by panmap\n";
  header += "element vertex " + std::to_string(n) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  if (colours) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  for (int k = 0; k < 3; ++k) {
    if (labels[k]) header += std::string("property int ") + label_names[k] + "\n";
  }
  header += "element face " + std::to_string(faces.size()) + "\n";
  header += "property list uchar int vertex_indices\nend_header\n";

  // Through a partial file renamed over PATH at the end: a viewer or planner reading the mesh
  // while the mapper rewrites it sees the old one or the whole new one, never a cut-off file.
  try {
    AtomicFileWriter out(path);
    auto write = [&out](const char* data, size_t size) {
      out.append(reinterpret_cast<const uint8_t*>(data), size);
    };
    write(header.data(), header.size());
    // Streamed in chunks: a building's mesh is 380 MB of PLY per file.
    constexpr size_t kChunkBytes = size_t{1} << 20;
    if (format == PlyFormat::kBinaryLittleEndian) {
      size_t vertex_bytes = 12 + (colours ? 3 : 0);
      for (int k = 0; k < 3; ++k) vertex_bytes += labels[k] ? 4 : 0;
      constexpr size_t kFaceBytes = 13;
      std::vector<char> buffer(kChunkBytes);
      const size_t vertices_per_chunk = kChunkBytes / vertex_bytes;
      for (size_t first = 0; first < n; first += vertices_per_chunk) {
        const size_t end = std::min(n, first + vertices_per_chunk);
        LittleEndianWriter w(buffer.data());
        for (size_t v = first; v < end; ++v) {
          const Eigen::Vector3f& p = (*columns.vertices)[v];
          w.put(p.x());
          w.put(p.y());
          w.put(p.z());
          if (colours) {
            const Rgb8 c = (*columns.colors)[v];
            w.put(c.r);
            w.put(c.g);
            w.put(c.b);
          }
          for (int k = 0; k < 3; ++k) {
            if (labels[k]) w.put(label(k, v));
          }
        }
        write(buffer.data(), (end - first) * vertex_bytes);
      }
      const size_t faces_per_chunk = kChunkBytes / kFaceBytes;
      for (size_t first = 0; first < faces.size(); first += faces_per_chunk) {
        const size_t end = std::min(faces.size(), first + faces_per_chunk);
        LittleEndianWriter w(buffer.data());
        for (size_t f = first; f < end; ++f) {
          w.put(static_cast<uint8_t>(3));
          for (int k = 0; k < 3; ++k) w.put(static_cast<int32_t>(faces[f][k]));
        }
        write(buffer.data(), (end - first) * kFaceBytes);
      }
    } else {
      std::string body;
      body.reserve(kChunkBytes + 256);
      auto flushIfFull = [&] {
        if (body.size() < kChunkBytes) return;
        write(body.data(), body.size());
        body.clear();
      };
      for (size_t v = 0; v < n; ++v) {
        // to_chars(float) gives the shortest text that reads back to the same float.
        for (int k = 0; k < 3; ++k) {
          if (k > 0) body += ' ';
          appendNumber(&body, (*columns.vertices)[v][k]);
        }
        if (colours) {
          const Rgb8 c = (*columns.colors)[v];
          for (const uint8_t channel : {c.r, c.g, c.b}) {
            body += ' ';
            appendNumber(&body, static_cast<int>(channel));
          }
        }
        for (int k = 0; k < 3; ++k) {
          if (!labels[k]) continue;
          body += ' ';
          appendNumber(&body, label(k, v));
        }
        body += '\n';
        flushIfFull();
      }
      for (const Eigen::Vector3i& f : faces) {
        body += '3';
        for (int k = 0; k < 3; ++k) {
          body += ' ';
          appendNumber(&body, f[k]);
        }
        body += '\n';
        flushIfFull();
      }
      write(body.data(), body.size());
    }
    out.commit();
  } catch (const Error& e) {
    throw Error("cannot write " + path + ": " + e.what());
  }
}

}  // namespace panmap
