#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/ply.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::expectError;

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Values chosen to break lossy float printing and narrow integer types.
LabelledMesh awkwardMesh() {
  LabelledMesh mesh;
  mesh.vertices = {{0.1f, -1e-7f, 3.4e38f},
                   {1.0f / 3.0f, 123456.789f, -0.0f},
                   {1e-45f, -2.5f, 7.0f},
                   {std::numeric_limits<float>::lowest(), 16777217.0f, 0.3f}};
  mesh.colors = {{0, 0, 0}, {255, 255, 255}, {1, 128, 254}, {17, 0, 200}};
  mesh.semantic = {0, 40, std::numeric_limits<int32_t>::max(), -1};
  mesh.instance = {std::numeric_limits<int32_t>::min(), 1, 70000, 0};
  mesh.superpoint = {5, 65536, 0, 123456789};
  mesh.faces = {{0, 1, 2}, {2, 3, 0}, {3, 1, 2}};
  return mesh;
}

void expectSameMesh(const LabelledMesh& a, const LabelledMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      // Bitwise: -0.0f must stay -0.0f.
      uint32_t bits_a = 0;
      uint32_t bits_b = 0;
      std::memcpy(&bits_a, &a.vertices[i][k], 4);
      std::memcpy(&bits_b, &b.vertices[i][k], 4);
      EXPECT_EQ(bits_a, bits_b) << "vertex " << i << " axis " << k;
    }
  }
  EXPECT_EQ(a.colors, b.colors);
  EXPECT_EQ(a.semantic, b.semantic);
  EXPECT_EQ(a.instance, b.instance);
  EXPECT_EQ(a.superpoint, b.superpoint);
  EXPECT_EQ(a.faces, b.faces);
}

TEST(PlyRoundTrip, BinaryAllPropertiesExact) {
  test::TempDir dir;
  const LabelledMesh mesh = awkwardMesh();
  writePly(dir.path("m.ply"), mesh);
  const std::string bytes = readFile(dir.path("m.ply"));
  // 4 vertices x (12 + 3 + 12) bytes and 3 faces x 13 bytes after the header.
  EXPECT_EQ(bytes.size() - (bytes.find("end_header\n") + 11), 4u * 27 + 3u * 13);
  EXPECT_NE(bytes.find("format binary_little_endian 1.0\n"), std::string::npos);
  expectSameMesh(readPly(dir.path("m.ply")), mesh);
}

TEST(PlyRoundTrip, AsciiAllPropertiesExact) {
  test::TempDir dir;
  const LabelledMesh mesh = awkwardMesh();
  writePly(dir.path("m.ply"), mesh, PlyFormat::kAscii);
  const std::string text = readFile(dir.path("m.ply"));
  EXPECT_NE(text.find("format ascii 1.0\n"), std::string::npos);
  EXPECT_NE(text.find("\n3 0 1 2\n3 2 3 0\n3 3 1 2\n"), std::string::npos);
  expectSameMesh(readPly(dir.path("m.ply")), mesh);
}

TEST(PlyRoundTrip, WritesOnlyArraysPresent) {
  test::TempDir dir;
  LabelledMesh mesh;
  mesh.vertices = {{1, 2, 3}, {4, 5, 6}};
  mesh.instance = {7, 0};
  for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    writePly(dir.path("m.ply"), mesh, format);
    const std::string text = readFile(dir.path("m.ply"));
    EXPECT_EQ(text.find("red"), std::string::npos);
    EXPECT_EQ(text.find("semantic"), std::string::npos);
    EXPECT_EQ(text.find("superpoint"), std::string::npos);
    EXPECT_NE(text.find("property int instance\nelement face 0\n"), std::string::npos);
    const LabelledMesh back = readPly(dir.path("m.ply"));
    expectSameMesh(back, mesh);
    EXPECT_TRUE(back.colors.empty());
    EXPECT_TRUE(back.semantic.empty());
  }
}

// A hand-written file: an element before the vertices, vertex properties panmap skips
// (double nx, alpha, a list, ScanNet's `label`), every integer alias for the labels, an edge
// element with a list between vertices and faces, faces with extra scalar and list
// properties around `vertex_index`, a quad and a pentagon, and an element after the faces.
const char kHandAscii[] =
    "ply\n"
    "format ascii 1.0\n"
    "comment hand-written fixture\n"
    "obj_info skip me\n"
    "element camera 1\n"
    "property float32 view_px\n"
    "property list uint8 int32 junk\n"
    "element vertex 6\n"
    "property float x\n"
    "property double y\n"
    "property float32 z\n"
    "property double nx\n"
    "property uchar red\n"
    "property uint8 green\n"
    "property uchar blue\n"
    "property uchar alpha\n"
    "property list uchar float texture\n"
    "property int label\n"
    "property short semantic\n"
    "property ushort instance\n"
    "property char superpoint\n"
    "element edge 2\n"
    "property int vertex1\n"
    "property int vertex2\n"
    "property list ushort double weights\n"
    "element face 2\n"
    "property uchar flags\n"
    "property list uchar float texcoord\n"
    "property list uchar uint vertex_index\n"
    "property int material\n"
    "element material 1\n"
    "property list uchar uchar name\n"
    "end_header\n"
    "3.5 3 7 8 9\n"
    "0 0 0 0.5 10 20 30 255 2 0.5 0.25 999 5 1 -3\n"
    "1 0 0 0.5 11 21 31 255 0 999 5 1 -3\n"
    "1 1 0 0.5 12 22 32 128 1 7 7 -7 65535 127\n"
    "0 1 0 0.5 13 23 33 0 0 999 40 2 -128\n"
    "2 0.1 0.25 0.5 14 24 34 0 0 999 0 0 0\n"
    "-1.5 0.5 1e-3 0.5 15 25 35 0 0 999 1 3 9\n"
    "0 1 2 0.5 0.25\n"
    "2 3 0\n"
    "1 2 0.5 0.5 4 0 1 2 3 7\n"
    "0 0 5 1 4 5 3 2 9\n"
    "3 65 66 67\n";

TEST(PlyAscii, HandWrittenQuadAndSkippedElements) {
  test::TempDir dir;
  writeFile(dir.path("hand.ply"), kHandAscii);
  const LabelledMesh mesh = readPly(dir.path("hand.ply"));
  ASSERT_EQ(mesh.numVertices(), 6u);
  EXPECT_EQ(mesh.vertices[0], Eigen::Vector3f(0, 0, 0));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3f(1, 1, 0));
  EXPECT_EQ(mesh.vertices[4], Eigen::Vector3f(2, static_cast<float>(0.1), 0.25f));
  EXPECT_EQ(mesh.vertices[5], Eigen::Vector3f(-1.5f, 0.5f, 0.001f));
  ASSERT_EQ(mesh.colors.size(), 6u);
  EXPECT_EQ(mesh.colors[0], (Rgb8{10, 20, 30}));
  EXPECT_EQ(mesh.colors[5], (Rgb8{15, 25, 35}));
  EXPECT_EQ(mesh.semantic, (std::vector<int32_t>{5, 5, -7, 40, 0, 1}));
  EXPECT_EQ(mesh.instance, (std::vector<int32_t>{1, 1, 65535, 2, 0, 3}));
  EXPECT_EQ(mesh.superpoint, (std::vector<int32_t>{-3, -3, 127, -128, 0, 9}));
  // Quad 0 1 2 3 -> (0 1 2) (0 2 3); pentagon 1 4 5 3 2 -> (1 4 5) (1 5 3) (1 3 2).
  const std::vector<Eigen::Vector3i> faces = {
      {0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 3}, {1, 3, 2}};
  EXPECT_EQ(mesh.faces, faces);
  // `label` is not taken for semantic, but can be read by name.
  EXPECT_EQ(readPlyVertexIntProperty(dir.path("hand.ply"), "label"),
            (std::vector<int32_t>{999, 999, 7, 999, 999, 999}));
  expectError([&] { readPlyVertexIntProperty(dir.path("hand.ply"), "nx"); },
              {"hand.ply", "nx must be of an integer type"});
  expectError([&] { readPlyVertexIntProperty(dir.path("hand.ply"), "missing"); },
              {"hand.ply", "no property missing"});
}

// Appends the big-endian bytes of a value: U is the unsigned integer type of its size.
template <typename U, typename T>
void putBigEndian(std::string* out, T value) {
  static_assert(sizeof(U) == sizeof(T), "size mismatch");
  U bits = 0;
  std::memcpy(&bits, &value, sizeof(T));
  for (int shift = 8 * (static_cast<int>(sizeof(U)) - 1); shift >= 0; shift -= 8) {
    out->push_back(static_cast<char>((bits >> shift) & 0xFF));
  }
}

TEST(PlyBigEndian, HandWrittenBytes) {
  // The helper against bytes written out by hand: 1.0f = 0x3F800000, -7 = 0xFFF9.
  std::string check;
  putBigEndian<uint32_t>(&check, 1.0f);
  putBigEndian<uint16_t>(&check, static_cast<int16_t>(-7));
  EXPECT_EQ(check, std::string("\x3F\x80\x00\x00\xFF\xF9", 6));

  std::string bytes =
      "ply\n"
      "format binary_big_endian 1.0\n"
      "element vertex 3\n"
      "property double x\n"
      "property float y\n"
      "property float z\n"
      "property uchar red\n"
      "property uchar green\n"
      "property uchar blue\n"
      "property int16 semantic\n"
      "property uint instance\n"
      "property int superpoint\n"
      "property list uchar short skipme\n"
      "element extra 2\n"
      "property ushort a\n"
      "property list int uint16 b\n"
      "element face 1\n"
      "property list uint8 uint32 vertex_indices\n"
      "end_header\n";
  // Vertex 0, with the x and y bytes spelt out: 1.25 = 0x3FF4000000000000, -2.5f = 0xC0200000.
  bytes += std::string("\x3F\xF4\x00\x00\x00\x00\x00\x00", 8);
  bytes += std::string("\xC0\x20\x00\x00", 4);
  putBigEndian<uint32_t>(&bytes, 0.001f);
  bytes += std::string("\x01\x02\x03", 3);
  putBigEndian<uint16_t>(&bytes, static_cast<int16_t>(-7));
  putBigEndian<uint32_t>(&bytes, static_cast<uint32_t>(70000));
  putBigEndian<uint32_t>(&bytes, static_cast<int32_t>(-123456));
  bytes += '\x03';
  for (const int16_t s : {-1, 2, 300}) putBigEndian<uint16_t>(&bytes, s);
  // Vertices 1 and 2.
  putBigEndian<uint64_t>(&bytes, 0.1);
  putBigEndian<uint32_t>(&bytes, 3.0f);
  putBigEndian<uint32_t>(&bytes, -0.5f);
  bytes += std::string("\xFF\x00\x80", 3);
  putBigEndian<uint16_t>(&bytes, static_cast<int16_t>(40));
  putBigEndian<uint32_t>(&bytes, static_cast<uint32_t>(1));
  putBigEndian<uint32_t>(&bytes, static_cast<int32_t>(0));
  bytes += '\x00';
  putBigEndian<uint64_t>(&bytes, -4.0);
  putBigEndian<uint32_t>(&bytes, 0.0f);
  putBigEndian<uint32_t>(&bytes, 1e10f);
  bytes += std::string("\x09\x08\x07", 3);
  putBigEndian<uint16_t>(&bytes, static_cast<int16_t>(0));
  putBigEndian<uint32_t>(&bytes, static_cast<uint32_t>(2147483647));
  putBigEndian<uint32_t>(&bytes, static_cast<int32_t>(65536));
  bytes += '\x01';
  putBigEndian<uint16_t>(&bytes, static_cast<int16_t>(5));
  // Element extra: (0xBEEF, [1, 2]) and (1, []).
  putBigEndian<uint16_t>(&bytes, static_cast<uint16_t>(0xBEEF));
  putBigEndian<uint32_t>(&bytes, static_cast<int32_t>(2));
  putBigEndian<uint16_t>(&bytes, static_cast<uint16_t>(1));
  putBigEndian<uint16_t>(&bytes, static_cast<uint16_t>(2));
  putBigEndian<uint16_t>(&bytes, static_cast<uint16_t>(1));
  putBigEndian<uint32_t>(&bytes, static_cast<int32_t>(0));
  // One face 2 0 1.
  bytes += '\x03';
  for (const uint32_t i : {2u, 0u, 1u}) putBigEndian<uint32_t>(&bytes, i);

  test::TempDir dir;
  writeFile(dir.path("be.ply"), bytes);
  const LabelledMesh mesh = readPly(dir.path("be.ply"));
  ASSERT_EQ(mesh.numVertices(), 3u);
  EXPECT_EQ(mesh.vertices[0], Eigen::Vector3f(1.25f, -2.5f, 0.001f));
  EXPECT_EQ(mesh.vertices[1], Eigen::Vector3f(static_cast<float>(0.1), 3.0f, -0.5f));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3f(-4.0f, 0.0f, 1e10f));
  EXPECT_EQ(mesh.colors, (std::vector<Rgb8>{{1, 2, 3}, {255, 0, 128}, {9, 8, 7}}));
  EXPECT_EQ(mesh.semantic, (std::vector<int32_t>{-7, 40, 0}));
  EXPECT_EQ(mesh.instance, (std::vector<int32_t>{70000, 1, 2147483647}));
  EXPECT_EQ(mesh.superpoint, (std::vector<int32_t>{-123456, 0, 65536}));
  EXPECT_EQ(mesh.faces, (std::vector<Eigen::Vector3i>{{2, 0, 1}}));

  // One byte fewer: the face's last index is cut.
  writeFile(dir.path("be_cut.ply"), bytes.substr(0, bytes.size() - 1));
  expectError([&] { readPly(dir.path("be_cut.ply")); },
              {"be_cut.ply", "truncated binary data in element face row 0 of 1"});
}

TEST(PlyErrors, TruncatedBinaryNamesTheFile) {
  test::TempDir dir;
  writePly(dir.path("whole.ply"), awkwardMesh());
  const std::string bytes = readFile(dir.path("whole.ply"));
  writeFile(dir.path("cut.ply"), bytes.substr(0, bytes.size() - 5));
  expectError([&] { readPly(dir.path("cut.ply")); },
              {"cut.ply", "truncated binary data in element face row 2 of 3"});
  // Cut inside the vertices (vertex 1 of 27-byte rows starts at byte 27).
  const size_t body = bytes.find("end_header\n") + 11;
  writeFile(dir.path("cut2.ply"), bytes.substr(0, body + 30));
  expectError([&] { readPly(dir.path("cut2.ply")); },
              {"cut2.ply", "truncated binary data in element vertex row 1 of 4"});
  writeFile(dir.path("long.ply"), bytes + "xy");
  expectError([&] { readPly(dir.path("long.ply")); },
              {"long.ply", "2 bytes after the last element"});
}

const char kTriangleHeader[] =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(PlyErrors, BadIndexNamesTheFile) {
  test::TempDir dir;
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
  writeFile(dir.path("bad_index.ply"), std::string(kTriangleHeader) + vertices + "3 0 1 5\n");
  expectError([&] { readPly(dir.path("bad_index.ply")); },
              {"bad_index.ply", "face 0 refers to vertex 5 of 3"});
  writeFile(dir.path("negative.ply"), std::string(kTriangleHeader) + vertices + "3 0 -1 2\n");
  expectError([&] { readPly(dir.path("negative.ply")); },
              {"negative.ply", "face 0 refers to vertex -1 of 3"});
  writeFile(dir.path("line.ply"), std::string(kTriangleHeader) + vertices + "2 0 1\n");
  expectError([&] { readPly(dir.path("line.ply")); }, {"line.ply", "face 0 has 2 corners"});
  // The well-formed file reads.
  writeFile(dir.path("good.ply"), std::string(kTriangleHeader) + vertices + "3 0 1 2\n");
  EXPECT_EQ(readPly(dir.path("good.ply")).faces, (std::vector<Eigen::Vector3i>{{0, 1, 2}}));
}

TEST(PlyErrors, TruncatedOrBadAsciiNamesTheFile) {
  test::TempDir dir;
  writeFile(dir.path("short.ply"), std::string(kTriangleHeader) + "0 0 0\n1 0 0\n");
  expectError([&] { readPly(dir.path("short.ply")); },
              {"short.ply", "truncated ascii data in element vertex row 2 of 3"});
  writeFile(dir.path("word.ply"), std::string(kTriangleHeader) + "0 0 0\n1 zero 0\n0 1 0\n");
  expectError([&] { readPly(dir.path("word.ply")); },
              {"word.ply", "bad ascii value 'zero' in element vertex row 1 of 3"});
  writeFile(dir.path("count.ply"),
            std::string(kTriangleHeader) + "0 0 0\n1 0 0\n0 1 0\n256 0 1 2\n");
  expectError([&] { readPly(dir.path("count.ply")); }, {"count.ply", "bad ascii value '256'"});
  writeFile(dir.path("extra.ply"),
            std::string(kTriangleHeader) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n4\n");
  expectError([&] { readPly(dir.path("extra.ply")); },
              {"extra.ply", "unexpected data after the last element"});
}

TEST(PlyErrors, BadHeaderNamesTheFile) {
  test::TempDir dir;
  expectError([&] { readPly(dir.path("absent.ply")); }, {"cannot read", "absent.ply"});
  writeFile(dir.path("magic.ply"), "solid cube\nfacet normal 0 0 1\n");
  expectError([&] { readPly(dir.path("magic.ply")); }, {"magic.ply", "not a PLY file"});
  writeFile(dir.path("empty.ply"), "");
  expectError([&] { readPly(dir.path("empty.ply")); }, {"empty.ply", "not a PLY file"});
  writeFile(dir.path("format.ply"), "ply\nformat binary_middle_endian 1.0\nend_header\n");
  expectError([&] { readPly(dir.path("format.ply")); },
              {"format.ply", "header line 2", "unsupported PLY format 'binary_middle_endian'"});
  writeFile(dir.path("type.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float16 x\nend_header\n0\n");
  expectError([&] { readPly(dir.path("type.ply")); },
              {"type.ply", "header line 4", "unknown type 'float16'"});
  writeFile(dir.path("typo.ply"), "ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n");
  expectError([&] { readPly(dir.path("typo.ply")); },
              {"typo.ply", "header line 3", "unexpected 'elemnt'"});
  writeFile(dir.path("count.ply"), "ply\nformat ascii 1.0\nelement vertex -1\nend_header\n");
  expectError([&] { readPly(dir.path("count.ply")); },
              {"count.ply", "expected 'element <name> <count>'"});
  writeFile(dir.path("noend.ply"), "ply\nformat ascii 1.0\nelement vertex 0\n");
  expectError([&] { readPly(dir.path("noend.ply")); }, {"noend.ply", "no end_header"});
  writeFile(dir.path("noz.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            "end_header\n1 2\n");
  expectError([&] { readPly(dir.path("noz.ply")); }, {"noz.ply", "no property z"});
  writeFile(dir.path("intx.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\n"
            "property float z\nend_header\n1 2 3\n");
  expectError([&] { readPly(dir.path("intx.ply")); }, {"intx.ply", "x must be float or double"});
  writeFile(dir.path("huge.ply"),
            "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n0123456789ab");
  expectError([&] { readPly(dir.path("huge.ply")); },
              {"huge.ply", "1000000000 vertices declared, 12 bytes left"});
}

TEST(PlyErrors, InconsistentMeshIsNotWritten) {
  test::TempDir dir;
  LabelledMesh mesh = awkwardMesh();
  mesh.semantic.pop_back();
  expectError([&] { writePly(dir.path("out.ply"), mesh); },
              {"out.ply", "semantic has a different length than vertices"});
  expectError([&] { writePly(dir.path("no/such/dir/out.ply"), awkwardMesh()); },
              {"cannot write", "no/such/dir/out.ply"});
}

// Meshes larger than the writer's 1 MiB chunks (100k vertices: 2.7 MB binary, 4+ MB ascii)
// come back exact in both formats, chunk edges included.
TEST(PlyRoundTrip, MeshesLargerThanAChunkAreExact) {
  test::TempDir dir;
  LabelledMesh mesh;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    mesh.vertices.emplace_back(i * 0.001f, -i / 3.0f, 1.0f / (i + 1));
    mesh.colors.push_back(Rgb8{static_cast<uint8_t>(i), static_cast<uint8_t>(i >> 8), 7});
    mesh.semantic.push_back(i % 41);
    mesh.instance.push_back(-i);
    mesh.superpoint.push_back(i * 977);
    if (i >= 2) mesh.faces.emplace_back(i - 2, i - 1, i);
  }
  for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    writePly(dir.path("big.ply"), mesh, format);
    expectSameMesh(readPly(dir.path("big.ply")), mesh);
  }
}

// writePly(PlyColumns) shares one mesh between files: colours given apart, a label column
// given empty is written as zeros, a null one not at all.
TEST(PlyColumns, ColumnsAreWrittenAsGivenAndChecked) {
  test::TempDir dir;
  const LabelledMesh mesh = awkwardMesh();
  const std::vector<Rgb8> colors = {{9, 8, 7}, {6, 5, 4}, {3, 2, 1}, {0, 0, 0}};
  const std::vector<int32_t> none;
  PlyColumns columns;
  columns.vertices = &mesh.vertices;
  columns.faces = &mesh.faces;
  columns.colors = &colors;
  columns.semantic = &mesh.semantic;
  columns.instance = &none;
  for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    writePly(dir.path("c.ply"), columns, format);
    const LabelledMesh back = readPly(dir.path("c.ply"));
    LabelledMesh expected = mesh;
    expected.colors = colors;
    expected.instance.assign(mesh.vertices.size(), 0);
    expected.superpoint.clear();
    expectSameMesh(back, expected);
  }
  const std::vector<Rgb8> short_colors(3);
  columns.colors = &short_colors;
  expectError([&] { writePly(dir.path("c.ply"), columns); }, {"c.ply", "3 colours for 4"});
  columns.colors = &colors;
  const std::vector<Eigen::Vector3i> bad_faces = {{0, 1, 4}};
  columns.faces = &bad_faces;
  expectError([&] { writePly(dir.path("c.ply"), columns); }, {"c.ply", "face 0 uses vertex 4"});
  columns.faces = nullptr;
  writePly(dir.path("c.ply"), columns);
  EXPECT_TRUE(readPly(dir.path("c.ply")).faces.empty());
}

}  // namespace
}  // namespace panmap
