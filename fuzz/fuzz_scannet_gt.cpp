// Feeds a ScanNet scene's ground truth (a container: vh_clean_2 PLY, aggregation JSON, segs
// JSON, label table, labels PLY) to loadScanNetGroundTruth and readScanNetLabelsPly.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "file_names.h"
#include "fuzz_common.h"
#include "panmap/io/scannet_ground_truth.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = panmap::fuzz::freshScratchFolder("scannet_gt");
  const auto& names = panmap::fuzz::scannetGtFileNames();
  panmap::fuzz::writeEntries(dir, panmap::fuzz::unpack(data, size), names);
  try {
    const panmap::ScanNetLabelTable table = panmap::ScanNetLabelTable::load(dir + "/" + names[3]);
    try {
      panmap::loadScanNetGroundTruth(dir + "/" + names[0], dir + "/" + names[1],
                                     dir + "/" + names[2], table);
    } catch (const std::exception&) {
    }
    panmap::readScanNetLabelsPly(dir + "/" + names[4], table);
  } catch (const std::exception&) {
  }
  return 0;
}
