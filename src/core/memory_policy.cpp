#include "panmap/core/memory_policy.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#ifdef __GLIBC__
#include <gnu/libc-version.h>
#include <malloc.h>
#endif

namespace panmap {
namespace {

constexpr char kHugeTlbTunable[] = "glibc.malloc.hugetlb";

}  // namespace

bool cLibraryCanAskForHugePages() {
#ifdef __GLIBC__
  int major = 0, minor = 0;
  if (std::sscanf(gnu_get_libc_version(), "%d.%d", &major, &minor) != 2) return false;
  return major > 2 || (major == 2 && minor >= 35);
#else
  return false;
#endif
}

void returnLargeBuffersToTheSystem() {
#ifdef __GLIBC__
  // Setting M_MMAP_THRESHOLD also turns off glibc's dynamic adjustment of it.
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(kLargeBufferBytes));
  mallopt(M_TRIM_THRESHOLD, static_cast<int>(kHeapKeepBytes));
#endif
}

std::string bracketedMode(const std::string& line) {
  const size_t open = line.find('[');
  const size_t close = line.find(']', open == std::string::npos ? 0 : open);
  if (open == std::string::npos || close == std::string::npos) return "";
  return line.substr(open + 1, close - open - 1);
}

std::string transparentHugePageMode() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  if (!in || !std::getline(in, line)) return "";
  return bracketedMode(line);
}

std::string tunablesWithHugePages(const char* current) {
  const std::string setting = std::string(kHugeTlbTunable) + "=1";
  if (current == nullptr || *current == '\0') return setting;
  if (std::strstr(current, kHugeTlbTunable) != nullptr) return "";
  return std::string(current) + ":" + setting;
}

bool heapUsesHugePages() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables == nullptr || !cLibraryCanAskForHugePages()) return false;
  const std::string all(tunables);
  const bool asked = all.find(std::string(kHugeTlbTunable) + "=1") != std::string::npos ||
                     all.find(std::string(kHugeTlbTunable) + "=2") != std::string::npos;
  const std::string mode = transparentHugePageMode();
  return asked && !mode.empty() && mode != "never";
}

void restartWithHugePageHeap(char** argv) {
  if (argv == nullptr || argv[0] == nullptr) return;
  const char* opt = std::getenv("PANMAP_HUGE_PAGES");
  if (opt != nullptr && std::strcmp(opt, "0") == 0) return;
  // "always": the kernel already backs large heap ranges with huge pages; "never": it will
  // not, so running again would gain nothing.
  if (!cLibraryCanAskForHugePages() || transparentHugePageMode() != "madvise") return;
  const char* current = std::getenv("GLIBC_TUNABLES");
  const std::string tunables = tunablesWithHugePages(current);
  if (tunables.empty()) return;
  const std::string previous = current != nullptr ? current : "";
  const bool had_previous = current != nullptr;
  if (setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
  std::fflush(nullptr);
  execv("/proc/self/exe", argv);
  // Still here: the exec failed (no /proc, say). Carry on as started.
  if (had_previous) {
    setenv("GLIBC_TUNABLES", previous.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

void applyMemoryPolicy(char** argv) {
  restartWithHugePageHeap(argv);
  returnLargeBuffersToTheSystem();
}

}  // namespace panmap
