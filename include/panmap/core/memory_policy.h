#pragma once

#include <cstddef>
#include <string>

namespace panmap {

/// Buffers at least this large are mapped from the system and returned to it when freed.
constexpr size_t kLargeBufferBytes = size_t{4} << 20;
/// Free memory the heap keeps at its top for the next frame rather than handing it back.
constexpr size_t kHeapKeepBytes = size_t{32} << 20;

/// Makes the process hand large buffers (graph messages, map snapshots) back to the system
/// when they are freed, and keep the memory of per-frame buffers for the next frame. glibc
/// raises its mmap threshold to the size of the first large block freed, after which later
/// ones come from the heap and stay resident: in a live run 15 graph requests added 110 MiB
/// that was never used again, 30-50 MiB with this policy. Fixing the threshold at
/// kLargeBufferBytes keeps per-frame images (below it) in the heap and lets the rare large
/// buffers go. Fixing it also fixes glibc's trim threshold at 128 kB, so every frame's freed
/// images were handed back and faulted in again: 700-1,000 page faults a frame decoding a
/// log's colour, depth and masks, a fifth to a third of panmap-mapper's CPU time on this
/// project's 2-core VM (docs/STATUS.md, 2026-12-05); the heap keeps kHeapKeepBytes free at
/// its top instead. A no-op where the C library is not glibc. Call once, early in main().
void returnLargeBuffersToTheSystem();

/// The kernel's transparent huge page mode, the bracketed word of
/// /sys/kernel/mm/transparent_hugepage/enabled ("always", "madvise" or "never"), or "" when
/// the file is missing or says none.
std::string transparentHugePageMode();

/// The bracketed word of a transparent_hugepage/enabled line ("always [madvise] never" ->
/// "madvise"), "" when there is none.
std::string bracketedMode(const std::string& line);

/// GLIBC_TUNABLES with glibc.malloc.hugetlb=1 added to `current` (null or "" when unset), or
/// "" when `current` already sets glibc.malloc.hugetlb: a value the user chose stands.
std::string tunablesWithHugePages(const char* current);

/// Whether the C library can put its heap on transparent huge pages when asked (glibc 2.35
/// added glibc.malloc.hugetlb; older versions and other C libraries ignore it).
bool cLibraryCanAskForHugePages();

/// Whether this process's heap asks the kernel for transparent huge pages: GLIBC_TUNABLES
/// sets glibc.malloc.hugetlb to 1 or 2 and the kernel's mode is not "never".
bool heapUsesHugePages();

/// Runs this program again (execv of /proc/self/exe, same pid and arguments) with glibc's
/// heap on transparent huge pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1), where the kernel
/// gives them only to memory that asks ("madvise" mode) and glibc (>= 2.35) can ask. A
/// page fault costs several microseconds in a virtual machine: on this project's 2-core VM
/// the building's final optimisation touched 12,197 fresh 4 kB pages and took 416 ms, with
/// the heap on 2 MB pages 498 fresh pages and 266 ms, and the building's per-frame p95 went
/// from 29.8 to 22.6 ms at the same resident memory (docs/STATUS.md, 2026-12-07). Returns without
/// doing anything when PANMAP_HUGE_PAGES=0, when GLIBC_TUNABLES already sets the option, in any
/// other mode or C library, and when the exec fails (the environment as it was). Call early
/// in main(), before any thread starts, file opens or output: what ran before it runs twice.
void restartWithHugePageHeap(char** argv);

/// The memory policy of panmap-mapper and panmap-optimizer, and of the tools and benchmarks
/// that measure or share their costs: restartWithHugePageHeap(argv), then
/// returnLargeBuffersToTheSystem().
void applyMemoryPolicy(char** argv);

}  // namespace panmap
