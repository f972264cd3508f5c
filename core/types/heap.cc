#include "core/types/heap.h"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace stcalib {

bool RetainFreedHeapMemory() {
#if defined(__GLIBC__)
  // 256 MiB keeps every per-frame block on the heap; an older glibc refuses a fixed threshold
  // above its dynamic threshold's 32 MiB ceiling, which is the fallback (about as fast on KITTI's
  // tracking frames; measured: docs/tuning.md#retain-freed-heap-memory).
  constexpr int kMmapThresholdBytes = 256 << 20;
  constexpr int kFallbackMmapThresholdBytes = 32 << 20;
  constexpr int kTrimThresholdBytes = 1 << 30;
  if (mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes) != 1 &&
      mallopt(M_MMAP_THRESHOLD, kFallbackMmapThresholdBytes) != 1) {
    // A fixed trim threshold would also fix the mmap threshold at its 128 KiB default.
    return false;
  }
  // One arena for every thread: what the frame loader's thread frees (a frame leaving the window)
  // serves the calibrating thread's next blocks too, so the two threads' peaks do not add up.
  mallopt(M_ARENA_MAX, 1);
  return mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes) == 1;
#else
  return false;
#endif
}

}  // namespace stcalib
