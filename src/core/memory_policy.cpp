#include "panmap/core/memory_policy.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace panmap {

void returnLargeBuffersToTheSystem() {
#ifdef __GLIBC__
  // Setting M_MMAP_THRESHOLD also turns off glibc's dynamic adjustment of it.
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(kLargeBufferBytes));
  mallopt(M_TRIM_THRESHOLD, static_cast<int>(kHeapKeepBytes));
#endif
}

}  // namespace panmap
