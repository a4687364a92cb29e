// Feeds a dataset folder (a container of files of every layout) to openDataset with the
// automatic layout and reads every frame.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "file_names.h"
#include "fuzz_common.h"
#include "panmap/io/dataset_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = panmap::fuzz::freshScratchFolder("dataset");
  panmap::fuzz::writeEntries(dir, panmap::fuzz::unpack(data, size),
                             panmap::fuzz::datasetFileNames());
  try {
    const auto reader = panmap::openDataset(dir, panmap::DatasetOptions{});
    reader->layoutName();
    reader->unmatchedFrames();
    // Tools skip a bad frame and go on (panmap-import --skip-bad-frames), so every frame is
    // read even after one failed.
    for (size_t i = 0; i < reader->size(); ++i) {
      try {
        const panmap::DatasetFrame frame = reader->read(i);
        panmap::LabelImage labels(frame.color_source_width, frame.color_source_height, 1);
        panmap::registerLabelsToDepth(labels, frame, "fuzz");
      } catch (const std::exception&) {
      }
    }
  } catch (const std::exception&) {
  }
  return 0;
}
