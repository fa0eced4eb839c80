// glibc malloc settings for the gateway's frame-sized buffers (issue 44, docs/benchmarks.md "Recording
// while serving").
#pragma once

namespace rr::server::app {

/// Keeps freed buffers of up to 4 MiB inside malloc's arenas instead of returning them to the kernel,
/// so that the next camera frame's buffer (640x480 RGB = 921,600 bytes) reuses pages already mapped
/// rather than faulting ~225 fresh pages in. Sets, once and before any thread starts:
///   - M_MMAP_THRESHOLD = 4 MiB: blocks below it come from the arenas (fixed; glibc's default of
///     128 KiB rises only after the first such block is freed);
///   - M_TRIM_THRESHOLD = 16 MiB: an arena keeps up to 16 MiB free at its top (default: twice the
///     mmap threshold, i.e. ~1.8 MiB once frames have been seen: with a recording holding frames
///     ~50 ms longer the free top exceeds it and is released with madvise, then faulted in again).
/// Cost: up to 16 MiB of freed memory per malloc arena may stay resident (measured: the gateway's RSS
/// within a few MiB of the untuned one on the camera row). A value the operator set through glibc's
/// environment variables (MALLOC_MMAP_THRESHOLD_, MALLOC_TRIM_THRESHOLD_) is kept: this does nothing
/// for that setting. Does nothing on a C library other than glibc. Returns a one-line description of
/// what was set, for the log ("" if nothing).
const char* tune_malloc_for_frames();

}  // namespace rr::server::app
