#include "memory_policy.h"

#include <cstdlib>  // defines __GLIBC__ where glibc is the C library

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace tailor::cli {
namespace {

// glibc's default threshold rises to the largest block freed so far (up to 32 MB), after which the
// mapping's per-chunk buffers come from the worker threads' arenas and stay resident there once
// freed: on a 6.2 M-face map that held 75 MB (10 %) at the export's peak. A fixed threshold keeps
// the peak to what is live.
constexpr int kMmapThreshold = 256 * 1024;
constexpr int kTrimThreshold = 1024 * 1024;
// A chunk's largest scratch arrays (up to 131,072 faces per chunk) are a few MB; the whole mesh's
// arrays beyond this are mapped from the kernel as before.
constexpr int kKeptThreshold = 32 * 1024 * 1024;

}  // namespace

void release_large_blocks() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, kMmapThreshold);
  mallopt(M_TRIM_THRESHOLD, kTrimThreshold);
#endif
}

KeepScratch::KeepScratch() {
#if defined(__GLIBC__)
  // The trim threshold stays: a worker thread's heap shrinks when more than 1 MB is free at its
  // top, which malloc_trim does not reach (it releases the free blocks inside the threads' heaps
  // only), so the threads' heaps do not stay grown after the mapping.
  mallopt(M_MMAP_THRESHOLD, kKeptThreshold);
#endif
}

KeepScratch::~KeepScratch() {
#if defined(__GLIBC__)
  release_large_blocks();
  malloc_trim(0);  // every arena's free pages, the worker threads' too
#endif
}

}  // namespace tailor::cli
