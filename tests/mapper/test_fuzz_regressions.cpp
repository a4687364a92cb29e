// Inputs on which fuzz/fuzz_map_file and fuzz/fuzz_config once failed
// (tests/fixtures/fuzz_regressions/), replayed the way the targets feed them.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "panmap/core/binary_io.h"
#include "panmap/mapper/config_file.h"
#include "panmap/mapper/mapper.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// A fuzz_map_file input with an odd first byte is a payload: the target adds Mapper::save's
// header (magic, version 5, size) and CRC-32. Writes the file Mapper::load then reads.
std::string writeMapFileOfFuzzInput(const std::string& input, const std::string& out) {
  EXPECT_FALSE(input.empty());
  EXPECT_EQ(static_cast<uint8_t>(input[0]) & 1, 1);
  const auto* payload = reinterpret_cast<const uint8_t*>(input.data()) + 1;
  const uint64_t size = input.size() - 1;
  BinaryWriter file;
  file.putBytes("PANMAP\0\0", 8);
  file.put<uint32_t>(5);
  file.put<uint64_t>(size);
  file.putBytes(payload, size);
  file.put<uint32_t>(static_cast<uint32_t>(crc32(0L, payload, static_cast<uInt>(size))));
  std::ofstream(out, std::ios::binary)
      .write(reinterpret_cast<const char*>(file.bytes().data()),
             static_cast<std::streamsize>(file.bytes().size()));
  return out;
}

std::string fuzzInput(const std::string& fixture) {
  return test::fileBytes(test::fixtureDir("fuzz_regressions/" + fixture));
}

TEST(MapFileFuzzRegressions, EmptyParentArrayIsACleanError) {
  // A mutated one-frame map whose super-point parent array is empty: the loader passed the
  // empty vector's data() (null) to memcpy for 0 bytes, undefined behaviour (UBSan), before
  // the super-point state refused the array.
  test::TempDir dir;
  const std::string path = writeMapFileOfFuzzInput(fuzzInput("map_file/empty_parents_null_memcpy"),
                                                   dir.path("map.panmap"));
  test::expectError([&] { Mapper::load(path); }, {"bad parent array"});
}

TEST(MapFileFuzzRegressions, BlockIndexOutOfRangeIsACleanError) {
  // A one-frame map whose block index was mutated to 536870911: voxel coordinates (index * 8)
  // overflowed int, and indices past 21 bits alias other blocks.
  test::TempDir dir;
  const std::string path = writeMapFileOfFuzzInput(fuzzInput("map_file/block_index_out_of_range"),
                                                   dir.path("map.panmap"));
  test::expectError([&] { Mapper::load(path); }, {path, "block index", "out of range"});
}

TEST(MapFileFuzzRegressions, SavedMapsStillLoad) {
  test::TempDir dir;
  MapperConfig config;
  config.num_threads = 1;
  Mapper mapper(config);
  mapper.save(dir.path("empty.panmap"));
  std::unique_ptr<Mapper> back;
  ASSERT_NO_THROW(back = Mapper::load(dir.path("empty.panmap")));
  EXPECT_EQ(back->framesIntegrated(), 0);
}

TEST(MapFileFuzzRegressions, BinaryReaderReadsZeroBytesIntoNull) {
  const uint8_t data[1] = {7};
  BinaryReader reader(data, 0, "empty");
  EXPECT_NO_THROW(reader.getBytes(nullptr, 0));
  EXPECT_EQ(reader.remaining(), 0u);
  test::expectError([&] { reader.get<uint8_t>(); }, {"empty", "truncated"});
}

TEST(MapFileFuzzRegressions, CutPayloadIsACleanError) {
  // The same map with half its payload (and a matching checksum): Error naming the file.
  test::TempDir dir;
  std::string input = fuzzInput("map_file/empty_parents_null_memcpy");
  input.resize(input.size() / 2);
  const std::string path = writeMapFileOfFuzzInput(input, dir.path("cut.panmap"));
  test::expectError([&] { Mapper::load(path); }, {path});
}

TEST(ConfigFuzzRegressions, RootMappingNotAtColumnZeroIsRefused) {
  // OpenCV's YAML reader never returned on this file (root mapping at column 1 ending at a
  // line "ma--..."); the shape check refuses it before OpenCV reads it.
  const std::string path = test::fixtureDir("fuzz_regressions/config/opencv_yaml_endless_loop");
  test::expectError([&] { loadConfig(path); }, {path, "section name at column 0"});
  test::TempDir dir;
  const std::string minimal = dir.path("minimal.yaml");
  std::ofstream(minimal) << "%YAML:1.0\n m: 1\nma-- 3\n";
  test::expectError([&] { loadConfig(minimal); }, {minimal + ":2", "column 0"});
}

TEST(ConfigFuzzRegressions, ControlCharactersAreRefused) {
  // NUL bytes on the header line made OpenCV's reader (which measures lines with strlen) end
  // the root mapping early and loop the same way.
  const std::string path = test::fixtureDir("fuzz_regressions/config/nul_byte_endless_loop");
  test::expectError([&] { loadConfig(path); }, {path + ":3", "control character"});
  test::TempDir dir;
  const std::string nul = dir.path("nul.yaml");
  std::ofstream(nul, std::ios::binary) << std::string("%YAML:1.0\0\nmap:\n", 16);
  test::expectError([&] { loadConfig(nul); }, {nul + ":1", "control character 0 at column 10"});
}

TEST(ConfigFuzzRegressions, DocumentEndAndTextAfterSeparatorAreRefused) {
  // Both end OpenCV's root collection early, which is what made it loop.
  test::TempDir dir;
  const std::string end = dir.path("end.yaml");
  std::ofstream(end) << "%YAML:1.0\n---\nmap:\n   voxel_size_m: 0.02\n...\n-x\n";
  test::expectError([&] { loadConfig(end); }, {end + ":5", "'...'"});
  const std::string flow = dir.path("flow.yaml");
  std::ofstream(flow) << "%YAML:1.0\n--- {map: {voxel_size_m: 0.02}}\nabc-\n";
  test::expectError([&] { loadConfig(flow); }, {flow + ":2", "'---'"});
  // Comments, blank lines and a commented separator before the first section are fine.
  const std::string ok = dir.path("ok.yaml");
  std::ofstream(ok)
      << "%YAML:1.0\n\n   # indented comment\n--- # doc\nmap:\n   voxel_size_m: 0.02\n";
  EXPECT_FLOAT_EQ(loadConfig(ok).mapper.map.voxel_size_m, 0.02f);
}

}  // namespace
}  // namespace panmap
