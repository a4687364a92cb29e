#include <cstdint>
#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>
#include <sys/resource.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "panmap/core/memory_policy.h"

// The policy is glibc's mallopt: other C libraries and sanitisers' allocators ignore it.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PANMAP_OTHER_ALLOCATOR 1
#endif
#endif
#if !defined(__GLIBC__) || defined(__SANITIZE_ADDRESS__)
#define PANMAP_OTHER_ALLOCATOR 1
#endif

namespace panmap {
namespace {

long minorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// Keeps the compiler from eliding an allocation it can see is never used elsewhere.
void* escape(void* p) {
  asm volatile("" : : "g"(p) : "memory");
  return p;
}

// One frame's worth of images: allocated, written through and freed in reverse order, as a
// frame's decoded colour, depth and masks are.
void frameOfBuffers() {
  constexpr size_t kBytes = size_t{1200} << 10;  // a 640x480 image of 4-byte pixels
  void* buffers[3];
  for (void*& buffer : buffers) {
    buffer = escape(std::malloc(kBytes));
    std::memset(buffer, 1, kBytes);
    escape(buffer);
  }
  for (int k = 2; k >= 0; --k) std::free(buffers[k]);
}

// Per-frame images below kLargeBufferBytes stay in the heap from frame to frame: with the
// policy fixing only the mmap threshold, glibc's trim threshold stays at 128 kB and every
// frame's 3.5 MB were handed back and faulted in again (868 faults a frame here).
TEST(MemoryPolicy, PerFrameBuffersAreNotFaultedInAgainEveryFrame) {
#ifdef PANMAP_OTHER_ALLOCATOR
  GTEST_SKIP() << "the policy is glibc's mallopt";
#endif
  returnLargeBuffersToTheSystem();
  frameOfBuffers();  // the heap grows once
  const long before = minorFaults();
  constexpr int kFrames = 20;
  for (int k = 0; k < kFrames; ++k) frameOfBuffers();
  const long faults = minorFaults() - before;
  // 3 x 300 pages a frame if they were returned: 18,000 over the loop.
  EXPECT_LT(faults, 300) << faults << " page faults over " << kFrames << " frames";
}

// Buffers at least kLargeBufferBytes are still mapped from the system on their own, so that
// freeing one hands it back.
TEST(MemoryPolicy, LargeBuffersStillGoBackToTheSystem) {
#ifdef PANMAP_OTHER_ALLOCATOR
  GTEST_SKIP() << "the policy is glibc's mallopt";
#else
  returnLargeBuffersToTheSystem();
  const size_t mapped_before = mallinfo2().hblkhd;
  void* big = escape(std::malloc(kLargeBufferBytes));
  EXPECT_GE(mallinfo2().hblkhd, mapped_before + kLargeBufferBytes);
  std::free(escape(big));
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before);
  // Just below the threshold: from the heap.
  void* image = escape(std::malloc(kLargeBufferBytes - 4096));
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before);
  std::free(escape(image));
#endif
}

TEST(MemoryPolicy, BracketedModeIsTheKernelsChoice) {
  EXPECT_EQ(bracketedMode("always [madvise] never"), "madvise");
  EXPECT_EQ(bracketedMode("[always] madvise never"), "always");
  EXPECT_EQ(bracketedMode("always madvise [never]"), "never");
  EXPECT_EQ(bracketedMode("always madvise never"), "");
  EXPECT_EQ(bracketedMode(""), "");
}

// The option joins what the user set; an explicit choice of the option itself stands.
TEST(MemoryPolicy, TunablesGainTheHugePageOptionUnlessItIsSet) {
  EXPECT_EQ(tunablesWithHugePages(nullptr), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunablesWithHugePages(""), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunablesWithHugePages("glibc.malloc.tcache_count=0"),
            "glibc.malloc.tcache_count=0:glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunablesWithHugePages("glibc.malloc.hugetlb=0"), "");
  EXPECT_EQ(tunablesWithHugePages("glibc.malloc.check=0:glibc.malloc.hugetlb=2"), "");
}

}  // namespace
}  // namespace panmap
