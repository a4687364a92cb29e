// Feeds one text file to every text reader: intrinsics / pose matrices (readMatrixFile 3x3
// and 4x4), intrinsics files in any form, pose lists (TUM, a matrix per line, stacked 4x4), TUM
// trajectories, segmenter label tables and ScanNet's label table and benchmark instance files.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_common.h"
#include "panmap/core/label_table.h"
#include "panmap/io/pose_list.h"
#include "panmap/io/scannet_ground_truth.h"
#include "panmap/io/text_files.h"
#include "panmap/io/tum_trajectory.h"

namespace {

template <typename F>
void expectCleanFailure(F&& f) {
  try {
    f();
  } catch (const std::exception&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The readers are cheap next to the file write, so all of them read each input.
  const std::string path = panmap::fuzz::writeScratchFile("file.txt", data, size);
  expectCleanFailure([&] { panmap::readMatrixFile(path, 3, 3); });
  expectCleanFailure([&] { panmap::readMatrixFile(path, 4, 4); });
  expectCleanFailure([&] { panmap::readIntrinsicsFile(path); });
  expectCleanFailure([&] { panmap::readPoseList(path, 1e-3); });
  expectCleanFailure([&] { panmap::readTumTrajectory(path); });
  expectCleanFailure([&] { panmap::LabelTable::load(path); });
  expectCleanFailure([&] {
    const panmap::ScanNetLabelTable table = panmap::ScanNetLabelTable::load(path);
    table.nyu40FromRawCategory("chair");
    table.nyu40FromScanNetId(1);
  });
  expectCleanFailure([&] { panmap::readScanNetInstanceFile(path); });
  return 0;
}
