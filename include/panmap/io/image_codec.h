#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "panmap/core/image.h"

namespace panmap {

/// Largest image the decoders accept, in pixels (2^25, about 33.5 M): the header's size is
/// checked before anything is allocated.
constexpr uint64_t kMaxImagePixels = uint64_t{1} << 25;

/// Bytes of a whole file; throws Error("cannot read <path>") when it cannot be read.
std::vector<uint8_t> readFileBytes(const std::string& path);

/// Writes bytes to a file, replacing it; throws Error naming the path on failure.
void writeFileBytes(const std::string& path, const std::vector<uint8_t>& bytes);

/// JPEG file bytes of a colour image.
/// @param quality 1..100
std::vector<uint8_t> encodeJpeg(const ColorImage& image, int quality = 90);

/// 8-bit RGB PNG file bytes of a colour image.
std::vector<uint8_t> encodePng(const ColorImage& image);

/// 16-bit greyscale PNG file bytes of a depth image (lossless).
/// @param compression zlib level 0..9: 1 (the default) is fastest; files kept on disk (the
///        frame store) trade encoding time for bytes with a higher one
std::vector<uint8_t> encodeDepthPng(const DepthImage& image, int compression = 1);

/// 8-bit RGB PNG of a label image in the COCO panoptic encoding id = R + 256 G + 65536 B.
/// Throws Error for labels outside [0, 2^24).
/// @param compression zlib level 0..9, as for encodeDepthPng()
std::vector<uint8_t> encodeLabelPng(const LabelImage& image, int compression = 1);

/// True when the bytes start with the PNG signature.
bool isPng(const uint8_t* data, size_t size);

/// True when JPEG bytes start with SOI and a marker and end with EOI (a truncated file does not;
/// libjpeg would otherwise decode it with a grey tail and only a warning).
bool isCompleteJpeg(const uint8_t* data, size_t size);

/// Decodes a JPEG or 8-bit PNG into RGB. Throws Error naming `what` when the bytes are not a
/// complete image of that kind.
ColorImage decodeColor(const uint8_t* data, size_t size, const std::string& what);

/// Decodes a 16-bit single-channel PNG. Throws Error naming `what` otherwise (an 8-bit PNG
/// is refused: it cannot hold millimetre depth).
DepthImage decodeDepthPng(const uint8_t* data, size_t size, const std::string& what);

/// Decodes a label PNG: 8-bit RGB in the COCO panoptic encoding, or 8/16-bit greyscale ids.
LabelImage decodeLabelPng(const uint8_t* data, size_t size, const std::string& what);

/// Reads and decodes a colour image file (JPEG or PNG).
ColorImage readColorFile(const std::string& path);

/// Reads and decodes a 16-bit depth PNG file.
DepthImage readDepthFile(const std::string& path);

}  // namespace panmap
