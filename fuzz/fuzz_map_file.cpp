// Feeds a map file to Mapper::load (panmap-mapper --resume), then meshes and graphs what it
// accepted.
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <vector>

#include "fuzz_common.h"
#include "panmap/mapper/mapper.h"

namespace {

// The header Mapper::save writes: magic, version, payload size, payload, CRC-32.
std::vector<uint8_t> wrapPayload(const uint8_t* payload, size_t size) {
  std::vector<uint8_t> file = {'P', 'A', 'N', 'M', 'A', 'P', 0, 0};
  const uint32_t version = 6;  // the current one (src/mapper/map_file.cpp kVersion)
  const uint64_t n = size;
  const uint32_t crc = static_cast<uint32_t>(crc32(0L, payload, static_cast<uInt>(size)));
  const auto append = [&file](const void* p, size_t k) {
    const auto* b = static_cast<const uint8_t*>(p);
    file.insert(file.end(), b, b + k);
  };
  append(&version, sizeof(version));
  append(&n, sizeof(n));
  append(payload, size);
  append(&crc, sizeof(crc));
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  // First byte odd: the rest is a payload and gets a valid header and checksum (otherwise
  // the CRC-32 stops nearly every mutation before the parser). Even: the bytes are the file.
  std::vector<uint8_t> file =
      (data[0] & 1) ? wrapPayload(data + 1, size - 1) : std::vector<uint8_t>(data + 1, data + size);
  const std::string path = panmap::fuzz::writeScratchFile("map.panmap", file.data(), file.size());
  try {
    std::unique_ptr<panmap::Mapper> mapper = panmap::Mapper::load(path);
    // A resumed map is meshed and graphed by panmap-mapper: the loaded voxels and super-point
    // state must hold together. (Saving again is left out: a writer, and half the run time.)
    mapper->extractMesh();
    mapper->graph();
  } catch (const std::exception&) {
  }
  return 0;
}
