#include "panmap/io/text_files.h"

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "panmap/core/error.h"

namespace panmap {

std::vector<NumberLine> readNumberLines(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read " + path);
  std::vector<NumberLine> out;
  std::string text, token;
  int number = 0;
  while (std::getline(in, text)) {
    ++number;
    const size_t first = text.find_first_not_of(" \t\r");
    if (first == std::string::npos || text[first] == '#') continue;
    NumberLine line;
    line.line = number;
    std::istringstream tokens(text);
    while (tokens >> token) {
      // strtod, unlike operator>>, accepts "nan" and "-inf" (ScanNet writes -inf poses).
      char* end = nullptr;
      errno = 0;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0') {
        // The two ways a spreadsheet or pandas export fails here, named.
        std::string hint;
        if (token.find(',') != std::string::npos) {
          hint = " (values separated by commas: panmap reads them separated by spaces or tabs)";
        } else if (out.empty() && line.values.empty()) {
          hint = " (a header line? start it with '#')";
        }
        throw Error(path + ":" + std::to_string(number) + ": '" + token + "' is not a number" +
                    hint);
      }
      line.values.push_back(value);
    }
    out.push_back(std::move(line));
  }
  return out;
}

std::vector<double> readNumbers(const std::string& path) {
  std::vector<double> values;
  for (const NumberLine& line : readNumberLines(path)) {
    values.insert(values.end(), line.values.begin(), line.values.end());
  }
  return values;
}

Eigen::MatrixXd readMatrixFile(const std::string& path, int rows, int cols) {
  const std::vector<double> values = readNumbers(path);
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

Eigen::Vector4d readIntrinsicsFile(const std::string& path) {
  const std::vector<double> v = readNumbers(path);
  Eigen::Vector4d k;
  if (v.size() == 9 || v.size() == 16) {
    const size_t n = v.size() == 9 ? 3 : 4;  // K sits in the top-left 3x3 of either
    k << v[0], v[n + 1], v[2], v[n + 2];
    if (v[1] != 0.0 || v[n] != 0.0 || v[2 * n] != 0.0 || v[2 * n + 1] != 0.0 ||
        v[2 * n + 2] != 1.0) {
      throw Error(path + ": not a pinhole matrix (expected [fx 0 cx; 0 fy cy; 0 0 1])");
    }
  } else if (v.size() == 4) {
    k << v[0], v[1], v[2], v[3];
  } else {
    throw Error(path + ": expected a 3x3 or 4x4 intrinsics matrix or 'fx fy cx cy', found " +
                std::to_string(v.size()) + " numbers");
  }
  if (!(k(0) > 0.0 && k(1) > 0.0 && k.allFinite())) {
    throw Error(path + ": focal lengths must be positive and finite");
  }
  return k;
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
