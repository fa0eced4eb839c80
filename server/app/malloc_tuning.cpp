#include "server/app/malloc_tuning.hpp"

#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace rr::server::app {

const char* tune_malloc_for_frames() {
#if defined(__GLIBC__)
    constexpr int kMmapThreshold = 4 * 1024 * 1024;
    constexpr int kTrimThreshold = 16 * 1024 * 1024;
    // Setting either fixes both in glibc (the dynamic mmap threshold is turned off), so an operator's
    // environment variable for one means we set neither and leave their choice whole.
    if (std::getenv("MALLOC_MMAP_THRESHOLD_") || std::getenv("MALLOC_TRIM_THRESHOLD_")) return "";
    if (mallopt(M_MMAP_THRESHOLD, kMmapThreshold) != 1 || mallopt(M_TRIM_THRESHOLD, kTrimThreshold) != 1) return "";
    return "malloc: mmap threshold 4 MiB, trim threshold 16 MiB (frame buffers stay mapped)";
#else
    return "";
#endif
}

}  // namespace rr::server::app
