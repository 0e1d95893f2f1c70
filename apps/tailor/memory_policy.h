// How the tailor command asks glibc's allocator for memory: large blocks straight from and back to
// the kernel, so that the peak is what is live, except while the mapping runs.
#pragma once

namespace tailor::cli {

//! Blocks over 256 KB are mapped from the kernel and handed back when freed (once, at start-up).
void release_large_blocks();

//! While one lives, freed blocks of up to 32 MB stay in the allocator for the next request; when it
//! goes, what is free is handed back and release_large_blocks' rule holds again. For the chunked
//! mapping, which allocates and frees the same scratch for every chunk: handed back each time, the
//! pages of every chunk's scratch are faulted in again. Not nested: the inner one's end would
//! restore the rule while the outer one lives.
class KeepScratch {
 public:
  KeepScratch();
  ~KeepScratch();
  KeepScratch(const KeepScratch&) = delete;
  KeepScratch& operator=(const KeepScratch&) = delete;
};

}  // namespace tailor::cli
