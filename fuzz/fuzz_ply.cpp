// Feeds a PLY file (ascii, binary little or big endian) to readPly and
// readPlyVertexIntProperty.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_common.h"
#include "panmap/io/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = panmap::fuzz::writeScratchFile("mesh.ply", data, size);
  try {
    const panmap::LabelledMesh mesh = panmap::readPly(path);
    mesh.check();  // a mesh the reader accepted must be self-consistent enough to check
  } catch (const std::exception&) {
  }
  // ScanNet's labels.ply `label` property goes through the second reader.
  try {
    panmap::readPlyVertexIntProperty(path, "label");
  } catch (const std::exception&) {
  }
  return 0;
}
