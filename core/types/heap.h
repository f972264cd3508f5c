#pragma once

namespace stcalib {

// Makes this process keep the heap memory it frees instead of returning it to the kernel.
//
// A frame's buffers are megabytes each (a sweep's 120k points and their motion-compensated
// copies, an image's float maps), and they are freed when the frame leaves the window. By
// default glibc serves such blocks by mmap and unmaps them on free, or trims the top of the heap
// once 128 KiB are free, so the next frame touches fresh pages and pays a page fault for every
// 4 KiB. Blocks up to 256 MiB now come from the heap (32 MiB where an older glibc caps the
// threshold there), and the heap is trimmed only when 1 GiB is free, at the cost of a slightly
// larger resident memory. All threads share one arena, so that the blocks one thread frees serve
// the other's (peak RSS on 20 KITTI frames 306 -> about 290 MB at the same speed).
// Measured: docs/tuning.md#retain-freed-heap-memory
//
// A process-wide setting: the `stcalib` CLI and the benchmarks call it first thing; a program
// that embeds the library decides for itself. Returns false when the allocator refused (not
// glibc), which changes nothing but speed.
bool RetainFreedHeapMemory();

}  // namespace stcalib
