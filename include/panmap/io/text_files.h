#pragma once

#include <string>

#include <Eigen/Core>

namespace panmap {

/// Reads a rows x cols matrix of whitespace-separated numbers ("nan", "inf", "-inf" accepted:
/// callers decide what a non-finite entry means). Throws Error naming the file when it is
/// missing or holds a different number of values.
Eigen::MatrixXd readMatrixFile(const std::string& path, int rows, int cols);

/// True when the path exists and is a directory.
bool isDirectory(const std::string& path);

/// True when the path exists and is a regular file.
bool isRegularFile(const std::string& path);

}  // namespace panmap
