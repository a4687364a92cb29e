// Feeds image file bytes (JPEG / PNG / zstd planes) to the colour, depth and label decoders,
// in memory.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "panmap/io/image_codec.h"
#include "panmap/io/plane_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The same bytes go to all five decoders: each refuses other kinds with an Error, and a
  // file that one decoder accepts is exactly what the others must refuse cleanly.
  try {
    panmap::isCompleteJpeg(data, size);
    panmap::decodeColor(data, size, "fuzz");
  } catch (const std::exception&) {
  }
  try {
    panmap::decodeDepthPng(data, size, "fuzz");
  } catch (const std::exception&) {
  }
  try {
    panmap::decodeLabelPng(data, size, "fuzz");
  } catch (const std::exception&) {
  }
  try {
    panmap::decodeDepthPlane(data, size, "fuzz");
  } catch (const std::exception&) {
  }
  try {
    panmap::decodeLabelPlane(data, size, "fuzz");
  } catch (const std::exception&) {
  }
  return 0;
}
