#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "panmap/io/dataset_reader.h"

namespace panmap {
namespace internal {

std::unique_ptr<DatasetReader> makeSevenScenesReader(const std::string& dir,
                                                     const DatasetOptions& options);
std::unique_ptr<DatasetReader> makeScanNetReader(const std::string& dir,
                                                 const DatasetOptions& options);
std::unique_ptr<DatasetReader> makeTumReader(const std::string& dir, const DatasetOptions& options);

/// Reads a 4x4 camera-to-world pose file. Sets `problem` (file and reason) and returns
/// nothing when the file is missing or the matrix is not a rigid transform.
std::optional<Eigen::Isometry3d> readPoseFile(const std::string& path, double tolerance,
                                              std::string* problem);

/// Regular files in a folder whose names match a regex; the first capture group must be a
/// frame number. Sorted by that number.
std::vector<std::pair<long long, std::string>> listNumberedFiles(const std::string& dir,
                                                                 const std::string& pattern);

/// utime of frame `number` of a sequence recorded at rate_hz starting at utime 0.
int64_t frameUtime(long long number, double rate_hz);

/// The file name without folder and last extension.
std::string fileStem(const std::string& path);

/// Checks that a decoded image has the size the sequence expects; throws Error otherwise.
void checkImageSize(const std::string& path, const char* kind, int width, int height,
                    int expected_width, int expected_height);

}  // namespace internal
}  // namespace panmap
