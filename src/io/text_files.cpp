#include "panmap/io/text_files.h"

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "panmap/core/error.h"

namespace panmap {

Eigen::MatrixXd readMatrixFile(const std::string& path, int rows, int cols) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read " + path);
  std::vector<double> values;
  std::string token;
  while (in >> token) {
    // strtod, unlike operator>>, accepts "nan" and "-inf" (ScanNet writes -inf poses).
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') {
      throw Error(path + ": '" + token + "' is not a number");
    }
    values.push_back(value);
  }
  if (static_cast<int>(values.size()) != rows * cols) {
    std::ostringstream msg;
    msg << path << ": expected " << rows << "x" << cols << " = " << rows * cols
        << " numbers, found " << values.size();
    throw Error(msg.str());
  }
  Eigen::MatrixXd m(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) m(r, c) = values[static_cast<size_t>(r) * cols + c];
  }
  return m;
}

bool isDirectory(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_directory(path, ec);
}

bool isRegularFile(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace panmap
