#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"

namespace panmap {
namespace test {

/// The shared real-data folder (../shared/data beside the checkout).
inline std::string dataDir(const std::string& sub = "") {
  return std::string(PANMAP_DATA_DIR) + (sub.empty() ? "" : "/" + sub);
}

/// Small fixtures committed under tests/fixtures.
inline std::string fixtureDir(const std::string& sub = "") {
  return std::string(PANMAP_FIXTURE_DIR) + (sub.empty() ? "" : "/" + sub);
}

/// A label table shipped in configs/labels/ (tests/fixtures is two levels below the checkout).
inline std::string shippedLabelTable(const std::string& name) {
  return fixtureDir("../../configs/labels/" + name);
}

/// A built executable of this build tree.
inline std::string binPath(const std::string& name) {
  return std::string(PANMAP_BIN_DIR) + "/" + name;
}

/// Skips the current test when a shared data folder is absent (e.g. a checkout without
/// ../shared); everywhere else the data is there and the test runs.
#define PANMAP_REQUIRE_DATA(sub)                                                          \
  do {                                                                                    \
    if (!std::filesystem::is_directory(::panmap::test::dataDir(sub))) {                   \
      GTEST_SKIP() << "shared data folder " << ::panmap::test::dataDir(sub) << " absent"; \
    }                                                                                     \
  } while (0)

/// A fresh temporary folder, removed with everything in it when this object dies.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "panmap-test-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// The folder, or a path inside it.
  std::string path(const std::string& sub = "") const {
    return sub.empty() ? path_ : path_ + "/" + sub;
  }

 private:
  std::string path_;
};

/// Links the ScanNet export fixture (../shared/data/scannet-export-3) into `dir` with frame 1's
/// pose replaced by the -inf rows ScanNet writes for frames its reconstruction lost.
inline void makeScanNetExportWithInfPose(const TempDir& dir) {
  namespace fs = std::filesystem;
  const std::string src = dataDir("scannet-export-3");
  for (const char* sub : {"color", "depth", "intrinsic"}) {
    fs::create_directory_symlink(src + "/" + sub, dir.path(sub));
  }
  fs::create_symlink(src + "/scene0707_00.txt", dir.path("scene0707_00.txt"));
  fs::create_directory(dir.path("pose"));
  fs::create_symlink(src + "/pose/0.txt", dir.path("pose/0.txt"));
  fs::create_symlink(src + "/pose/2.txt", dir.path("pose/2.txt"));
  std::ofstream(dir.path("pose/1.txt")) << "-inf -inf -inf -inf\n-inf -inf -inf -inf\n"
                                           "-inf -inf -inf -inf\n-inf -inf -inf -inf\n";
}

/// Runs `call` and expects an Error with a one-line message containing every one of `parts`.
inline void expectError(const std::function<void()>& call, const std::vector<std::string>& parts) {
  try {
    call();
    ADD_FAILURE() << "no Error thrown";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
  }
}

/// Result of running a command.
struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// Runs a shell command and captures its output and exit code.
inline CommandResult runCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

/// The whole content of a file (empty when it cannot be read).
inline std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// An LCM message encoded and decoded again (the decode must consume every byte).
template <typename Msg>
Msg throughBytes(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  Msg out;
  EXPECT_EQ(out.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  return out;
}

/// Number of lines in a text.
inline int countLines(const std::string& text) {
  int lines = 0;
  for (char c : text) lines += c == '\n';
  if (!text.empty() && text.back() != '\n') ++lines;
  return lines;
}

}  // namespace test
}  // namespace panmap
