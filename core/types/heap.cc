#include "core/types/heap.h"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace stcalib {

bool RetainFreedHeapMemory() {
#if defined(__GLIBC__)
  // Some per-frame blocks exceed glibc's dynamic threshold's 32 MiB ceiling; an older glibc
  // refuses a fixed threshold above that ceiling, so it is the fallback.
  constexpr int kMmapThresholdBytes = 256 << 20;
  constexpr int kFallbackMmapThresholdBytes = 32 << 20;
  constexpr int kTrimThresholdBytes = 1 << 30;
  if (mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes) != 1 &&
      mallopt(M_MMAP_THRESHOLD, kFallbackMmapThresholdBytes) != 1) {
    // A fixed trim threshold would also fix the mmap threshold at its 128 KiB default.
    return false;
  }
  return mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes) == 1;
#else
  return false;
#endif
}

}  // namespace stcalib
