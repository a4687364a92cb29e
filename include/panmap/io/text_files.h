#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace panmap {

/// Reads a rows x cols matrix of whitespace-separated numbers ("nan", "inf", "-inf" accepted:
/// callers decide what a non-finite entry means). Throws Error naming the file when it is
/// missing or holds a different number of values.
Eigen::MatrixXd readMatrixFile(const std::string& path, int rows, int cols);

/// One line of numbers and its 1-based line number in the file.
struct NumberLine {
  int line = 0;
  std::vector<double> values;
};

/// Reads the whitespace-separated numbers of a text file line by line, skipping empty lines and
/// '#' comment lines ("nan", "inf", "-inf" accepted). Throws Error naming the file, the line and
/// the first token that is not a number.
std::vector<NumberLine> readNumberLines(const std::string& path);

/// Every number of a text file (readNumberLines, flattened).
std::vector<double> readNumbers(const std::string& path);

/// Reads pinhole intrinsics fx, fy, cx, cy from a file holding a 3x3 K, a 4x4 matrix with K
/// in its top-left corner, or the four numbers "fx fy cx cy". Throws Error naming the file
/// and what it found otherwise.
Eigen::Vector4d readIntrinsicsFile(const std::string& path);

/// True when the path exists and is a directory.
bool isDirectory(const std::string& path);

/// True when the path exists and is a regular file.
bool isRegularFile(const std::string& path);

}  // namespace panmap
