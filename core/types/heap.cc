#include "core/types/heap.h"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace stcalib {

bool RetainFreedHeapMemory() {
#if defined(__GLIBC__)
  // Some per-frame blocks exceed glibc's dynamic threshold's 32 MiB ceiling.
  constexpr int kMmapThresholdBytes = 256 << 20;
  constexpr int kTrimThresholdBytes = 1 << 30;
  const bool mmap_set = mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes) == 1;
  const bool trim_set = mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes) == 1;
  return mmap_set && trim_set;
#else
  return false;
#endif
}

}  // namespace stcalib
