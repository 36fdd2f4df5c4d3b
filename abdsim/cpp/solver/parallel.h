// Parallel loops for the solver, whose results do not depend on the number of threads.
//
// A small persistent worker pool instead of OpenMP fork/join: the calling thread works too,
// chunks are claimed from a shared counter, and a loop is done when every chunk is done,
// not when every thread has checked in. A worker that the OS has not scheduled (another
// process on the core, common on robot computers) simply takes no share, where an OpenMP
// barrier would wait a scheduler time slice for it on every loop.
//
// Every index must be independent of the others; reductions go through deterministic_sum
// (fixed chunks, summed in order), so results are bit-identical for any thread count.
#pragma once
#include <algorithm>
#include <functional>
#include <vector>

namespace abd {

// Loops over fewer bodies than this run on the calling thread only.
constexpr int kParallelMinBodies = 64;

// Threads a loop may use: `requested` if > 0, else all hardware threads.
int resolve_threads(int requested);

// Runs f(begin, end, slot) over [0, n) in chunks of `chunk` indices on up to `threads`
// threads (the caller included); `slot` in [0, threads) identifies the thread running the
// chunk (for per-thread scratch). Returns when all chunks have run. f must not throw.
void parallel_chunks(int n, int chunk, int threads,
                     const std::function<void(int, int, int)>& f);

// f(i) for i in [0, n), in parallel when n >= min_parallel.
template <typename F>
void parallel_for(int n, int threads, F&& f, int min_parallel = kParallelMinBodies) {
  if (n < min_parallel || threads <= 1) {
    for (int i = 0; i < n; ++i) f(i);
    return;
  }
  parallel_chunks(n, 16, threads, [&](int begin, int end, int) {
    for (int i = begin; i < end; ++i) f(i);
  });
}

// f(i, slot) for i in [0, n): as parallel_for, with the slot of the running thread.
template <typename F>
void parallel_for_slot(int n, int threads, F&& f) {
  if (n < kParallelMinBodies || threads <= 1) {
    for (int i = 0; i < n; ++i) f(i, 0);
    return;
  }
  parallel_chunks(n, 16, threads, [&](int begin, int end, int slot) {
    for (int i = begin; i < end; ++i) f(i, slot);
  });
}

// Σ f(i) for i in [0, n), the same bits for any thread count.
// Indices per chunk of deterministic_sum: a sum over fewer is one chunk, summed in index
// order from 0.
constexpr int kDeterministicChunk = 256;

template <typename F>
double deterministic_sum(int n, int threads, F&& f) {
  constexpr int kChunk = kDeterministicChunk;
  const int chunks = (n + kChunk - 1) / kChunk;
  std::vector<double> partial(std::max(chunks, 1), 0.0);
  parallel_for(
      chunks, threads,
      [&](int c) {
        double s = 0.0;
        for (int i = c * kChunk, end = std::min(n, (c + 1) * kChunk); i < end; ++i) s += f(i);
        partial[c] = s;
      },
      2);
  double s = 0.0;
  for (double p : partial) s += p;
  return s;
}

}  // namespace abd
