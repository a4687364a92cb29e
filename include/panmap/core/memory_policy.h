#pragma once

#include <cstddef>

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

}  // namespace panmap
