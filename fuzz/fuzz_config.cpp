// Feeds a YAML config file to loadConfig, then builds a Mapper from what it accepted.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_common.h"
#include "panmap/mapper/config_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = panmap::fuzz::writeScratchFile("config.yaml", data, size);
  try {
    panmap::PanmapConfig config = panmap::loadConfig(path);
    panmap::configToYaml(config);
    // A config that loads is handed to the mapper as is (panmap-mapper --config): its checks
    // must refuse whatever the mapper cannot build. One thread keeps each run cheap.
    config.mapper.num_threads = 1;
    panmap::Mapper mapper(config.mapper);
  } catch (const std::exception&) {
  }
  return 0;
}
