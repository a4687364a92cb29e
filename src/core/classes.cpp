#include "panmap/core/classes.h"

#include <array>
#include <cctype>

namespace panmap {
namespace {

// NYU40 names exactly as in ScanNet's scannetv2-labels.combined.tsv (nyu40class column).
constexpr std::array<const char*, kMaxNyu40Class + 1> kNyu40Names = {
    "unknown",    "wall",    "floor",       "cabinet",        "bed",
    "chair",      "sofa",    "table",       "door",           "window",
    "bookshelf",  "picture", "counter",     "blinds",         "desk",
    "shelves",    "curtain", "dresser",     "pillow",         "mirror",
    "floor mat",  "clothes", "ceiling",     "books",          "refridgerator",
    "television", "paper",   "towel",       "shower curtain", "box",
    "whiteboard", "person",  "night stand", "toilet",         "sink",
    "lamp",       "bathtub", "bag",         "otherstructure", "otherfurniture",
    "otherprop"};

}  // namespace

std::string nyu40Name(int32_t class_id) {
  if (class_id < 1 || class_id > kMaxNyu40Class) return kNyu40Names[0];
  return kNyu40Names[class_id];
}

std::string normaliseName(const std::string& name) {
  std::string out;
  for (char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    }
  }
  return out;
}

int32_t nyu40IdFromName(const std::string& name) {
  const std::string key = normaliseName(name);
  for (int32_t id = 1; id <= kMaxNyu40Class; ++id) {
    if (normaliseName(kNyu40Names[id]) == key) return id;
  }
  // The correct spelling of ScanNet's misspelt class.
  if (key == "refrigerator") return 24;
  return kUnknownClass;
}

bool isStuffClass(int32_t class_id) { return class_id == 1 || class_id == 2 || class_id == 22; }

const std::vector<int32_t>& evaluatedClasses() {
  static const std::vector<int32_t> kClasses = {3,  4,  5,  6,  7,  8,  9,  10, 11,
                                                12, 14, 16, 24, 28, 33, 34, 36, 39};
  return kClasses;
}

}  // namespace panmap
