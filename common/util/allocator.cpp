// Allocator settings (see allocator.h).
#include "common/util/allocator.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace pr {

void retainFreedMemory() {
#if defined(__GLIBC__)
  // Fixed values also switch off glibc's dynamic adjustment of both thresholds.
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace pr
