// Deterministic data parallelism for per-element passes whose results are summed: [0, n) is cut
// into fixed chunks (their bounds do not depend on the thread count), each chunk's partial result
// is kept apart, and the caller reduces them in chunk order. A floating-point sum is then the same
// bit for bit on one thread or eight.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace tailor::internal {

//! Elements per chunk: large enough that a chunk's bookkeeping is noise, small enough that two
//! threads get balanced work on a 100k-element input.
inline constexpr size_t kParallelChunk = size_t{1} << 15;

//! Threads worth starting for n elements: one per `per_thread` elements, at most the cores and 8,
//! at least 1; `requested` > 0 overrides (at most 64).
inline size_t parallel_threads(size_t n, size_t requested, size_t per_thread = 100000) {
  if (requested != 0) return std::min<size_t>(requested, 64);
  const size_t cores = std::max<size_t>(std::thread::hardware_concurrency(), 1);
  return std::clamp<size_t>(std::min(cores, n / per_thread), 1, 8);
}

//! Parts of a for_each_part pass over n elements: parallel_threads, but none of fewer than
//! `min_per_part` elements (a part's fixed cost, a table or a histogram, would outweigh its share).
inline size_t parallel_parts(size_t n, size_t requested, size_t min_per_part = size_t{1} << 16) {
  return std::min(parallel_threads(n, requested), std::max<size_t>(1, n / min_per_part));
}

//! Number of chunks of `chunk` elements for n elements.
inline size_t chunk_count(size_t n, size_t chunk = kParallelChunk) { return (n + chunk - 1) / chunk; }

//! Calls body(begin, end, chunk) for every chunk of [0, n) (`chunk_size` elements; the last one
//! shorter), on up to `threads` threads (each takes
//! the next chunk not yet taken; fewer when the system refuses a thread). body must only write
//! state owned by its chunk or its elements. An exception from body (any thread) is rethrown here
//! once every thread has stopped.
template <class Body>
void for_each_chunk(size_t n, size_t threads, Body body, size_t chunk_size = kParallelChunk) {
  const size_t chunks = chunk_count(n, chunk_size);
  threads = std::clamp<size_t>(threads, 1, std::max<size_t>(chunks, 1));
  std::atomic<size_t> next{0};
  std::exception_ptr failure;  // the first exception of any thread, rethrown on the calling one
  std::mutex failure_mutex;
  auto run = [&] {
    try {
      for (size_t c; (c = next.fetch_add(1)) < chunks;) body(c * chunk_size, std::min(n, (c + 1) * chunk_size), c);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next.store(chunks);  // the others stop after their current chunk
    }
  };
  std::vector<std::thread> workers;
  try {
    workers.reserve(threads - 1);
    for (size_t t = 1; t < threads; ++t) workers.emplace_back(run);
  } catch (...) {  // no thread to be had: the calling thread does the rest
  }
  run();
  for (std::thread& w : workers) w.join();
  if (failure) std::rethrow_exception(failure);
}

//! Calls body(part, begin, end) for `parts` contiguous ranges of [0, n), one thread each (fewer when
//! the system refuses a thread). For passes whose per-part results are merged in part order or by
//! order-free reductions (counts, min, max), so the result is the same for any count.
template <class Body>
void for_each_part(size_t n, size_t parts, Body body) {
  for_each_chunk(
      parts, parts, [&](size_t t, size_t, size_t) { body(t, n * t / parts, n * (t + 1) / parts); }, 1);
}

//! Runs beside() on a second thread while main() runs on the calling one, when `threaded` and a
//! thread can be had; else main() then beside(). For two independent jobs (they must not write
//! what the other reads). An exception from either is rethrown here once both have stopped.
template <class Beside, class Main>
void run_beside(bool threaded, Beside beside, Main main) {
  std::exception_ptr failure;
  std::thread helper;
  if (threaded) {
    try {
      helper = std::thread([&] {
        try {
          beside();
        } catch (...) {
          failure = std::current_exception();
        }
      });
    } catch (...) {  // no thread to be had: run inline below
    }
  }
  try {
    main();
  } catch (...) {
    if (helper.joinable()) helper.join();
    throw;
  }
  if (!helper.joinable()) return beside();
  helper.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace tailor::internal
