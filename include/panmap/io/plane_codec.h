#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "panmap/core/image.h"

namespace panmap {

/// Lossless codec for the frame store's depth and label images: a 16-byte header (magic
/// "PMZP", pixel type, width, height, little-endian) and the raw little-endian pixels as one
/// zstd frame with its content checksum. On 7-Scenes depth and super-point labels, level 5
/// gives smaller files than PNG at zlib level 6 and decodes about four times as fast
/// (docs/LOOP_CLOSURE.md): a repair decodes the whole store, so decoding speed is what counts.

/// Default zstd level of encodePlane(): below it the files outgrow the PNGs', above it encoding
/// slows (docs/LOOP_CLOSURE.md).
constexpr int kDefaultPlaneLevel = 5;

/// Encodes a depth image (16-bit units) losslessly.
/// @param level zstd level 1..19; Error outside
std::vector<uint8_t> encodePlane(const DepthImage& image, int level = kDefaultPlaneLevel);

/// Encodes a label image (every int32, negative ones included) losslessly; in 8 or 16 bits
/// per pixel when every label fits (smaller files).
/// @param level zstd level 1..19; Error outside
std::vector<uint8_t> encodePlane(const LabelImage& image, int level = kDefaultPlaneLevel);

/// True when the bytes start with the plane codec's magic (not a PNG or JPEG).
bool isPlane(const uint8_t* data, size_t size);

/// Decodes a depth plane. Throws Error naming `what` when the bytes are not a complete depth
/// plane: wrong magic or pixel type, a size above kMaxImagePixels, a cut or corrupt zstd frame,
/// or a frame holding other than width x height pixels.
DepthImage decodeDepthPlane(const uint8_t* data, size_t size, const std::string& what);

/// Decodes a label plane; errors as decodeDepthPlane().
LabelImage decodeLabelPlane(const uint8_t* data, size_t size, const std::string& what);

}  // namespace panmap
