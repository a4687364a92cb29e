// Feeds a mask folder (a container: COCO JSON, per-frame JSONs, PNG masks, a label table) to
// CocoPanopticReader in both arrangements and to SemanticMaskReader, and reads every mask.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "file_names.h"
#include "fuzz_common.h"
#include "panmap/core/label_table.h"
#include "panmap/io/coco_panoptic_reader.h"
#include "panmap/io/semantic_mask_reader.h"
#include "panmap/io/text_files.h"

namespace {

// The colour stems the masks of the container can belong to.
const char* const kStems[] = {"frame-000000.color", "0", "frame-000000", "1"};

void readEvery(panmap::MaskReader& reader) {
  for (const char* stem : kStems) {
    if (!reader.has(stem)) continue;
    try {
      reader.read(stem);
    } catch (const std::exception&) {
    }
  }
}

void readAll(const std::string& mask_dir, const std::string& json_path,
             const panmap::LabelTable& table) {
  try {
    panmap::CocoPanopticReader reader(mask_dir, json_path, table);
    readEvery(reader);
  } catch (const std::exception&) {
  }
}

void readSemantic(const std::string& mask_dir, const panmap::LabelTable& table) {
  try {
    panmap::SemanticMaskReader reader(mask_dir, table);
    readEvery(reader);
  } catch (const std::exception&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = panmap::fuzz::freshScratchFolder("coco");
  panmap::fuzz::writeEntries(dir, panmap::fuzz::unpack(data, size), panmap::fuzz::cocoFileNames());
  panmap::LabelTable table = panmap::LabelTable::nyu40Identity();
  if (panmap::isRegularFile(dir + "/labels.tsv")) {
    try {
      table = panmap::LabelTable::load(dir + "/labels.tsv");
    } catch (const std::exception&) {
    }
  }
  const std::string masks = dir + "/masks";
  if (!panmap::isDirectory(masks)) return 0;
  readAll(masks, dir + "/panoptic.json", table);  // one COCO file for the folder
  readAll(masks, "", table);                      // one JSON per PNG
  readSemantic(masks, table);                     // the PNGs as class ids
  return 0;
}
