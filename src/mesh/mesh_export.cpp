#include "panmap/mesh/mesh_export.h"

#include <filesystem>
#include <system_error>
#include <vector>

#include "panmap/core/error.h"

namespace panmap {

namespace {

// ScanNet's NYU40 palette (BenchmarkScripts/util.py, create_color_palette), index = class id.
constexpr uint8_t kNyu40Palette[41][3] = {
    {0, 0, 0},       {174, 199, 232}, {152, 223, 138}, {31, 119, 180},  {255, 187, 120},
    {188, 189, 34},  {140, 86, 75},   {255, 152, 150}, {214, 39, 40},   {197, 176, 213},
    {148, 103, 189}, {196, 156, 148}, {23, 190, 207},  {178, 76, 76},   {247, 182, 210},
    {66, 188, 102},  {219, 219, 141}, {140, 57, 197},  {202, 185, 52},  {51, 176, 203},
    {200, 54, 131},  {92, 193, 61},   {78, 71, 183},   {172, 114, 82},  {255, 127, 14},
    {91, 163, 138},  {153, 98, 156},  {140, 153, 101}, {158, 218, 229}, {100, 125, 154},
    {178, 127, 135}, {120, 185, 128}, {146, 111, 194}, {44, 160, 44},   {112, 128, 144},
    {96, 207, 209},  {227, 119, 194}, {213, 92, 176},  {94, 106, 211},  {82, 84, 163},
    {100, 85, 144}};

// splitmix64's finaliser: neighbouring ids get unrelated colours.
uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// One export: the shared mesh with colours from `palette` of `ids` (black where the mesh has
// no such labels) and all three label properties.
void writeColoured(const std::string& path, const LabelledMesh& mesh,
                   const std::vector<int32_t>& ids, Rgb8 (*palette)(int32_t), PlyFormat format) {
  std::vector<Rgb8> colors(mesh.vertices.size(), palette(0));
  for (size_t i = 0; i < ids.size(); ++i) colors[i] = palette(ids[i]);
  PlyColumns columns;
  columns.vertices = &mesh.vertices;
  columns.faces = &mesh.faces;
  columns.colors = &colors;
  columns.semantic = &mesh.semantic;
  columns.instance = &mesh.instance;
  columns.superpoint = &mesh.superpoint;
  writePly(path, columns, format);  // throws naming the file
}

}  // namespace

Rgb8 semanticColor(int32_t class_id) {
  if (class_id < 0 || class_id > 40) return Rgb8{0, 0, 0};
  const uint8_t* c = kNyu40Palette[class_id];
  return Rgb8{c[0], c[1], c[2]};
}

Rgb8 idColor(int32_t id) {
  if (id == 0) return Rgb8{0, 0, 0};
  const uint64_t h = mix(static_cast<uint32_t>(id));
  // Each channel in [48, 255]: never black, so no id is confused with "none".
  auto channel = [h](int shift) {
    return static_cast<uint8_t>(48 + ((h >> shift) & 0xFF) * (255 - 48) / 255);
  };
  return Rgb8{channel(0), channel(8), channel(16)};
}

void writeLabelledMeshes(const std::string& dir, const LabelledMesh& mesh, PlyFormat format) {
  const std::string problem = mesh.check();
  if (!problem.empty()) throw Error(dir + ": cannot export the mesh: " + problem);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw Error(dir + ": cannot create the output folder" + (ec ? ": " + ec.message() : ""));
  }
  const std::filesystem::path folder(dir);
  writeColoured((folder / kSemanticMeshFile).string(), mesh, mesh.semantic, semanticColor, format);
  writeColoured((folder / kInstanceMeshFile).string(), mesh, mesh.instance, idColor, format);
  writeColoured((folder / kSuperpointMeshFile).string(), mesh, mesh.superpoint, idColor, format);
}

}  // namespace panmap
