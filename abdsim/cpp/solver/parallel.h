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
#include <array>
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

// Indices per chunk of deterministic_sum(s): a sum over fewer is one chunk, summed in index
// order from 0.
constexpr int kDeterministicChunk = 256;

// Σ f(i) for i in [0, n) of each of the K components of f(i) (a std::array<double, K>), the
// same bits for any thread count: every component is summed in fixed chunks of indices, in
// index order within a chunk, and the chunks' sums in chunk order. One pass over the indices
// for K sums; each comes out as deterministic_sum of that component alone would give it.
template <int K, typename F>
std::array<double, K> deterministic_sums(int n, int threads, F&& f) {
  constexpr int kChunk = kDeterministicChunk;
  const int chunks = std::max((n + kChunk - 1) / kChunk, 1);
  // One chunk's sums, in index order.
  auto chunk_sums = [&](int c) {
    std::array<double, K> s{};
    for (int i = c * kChunk, end = std::min(n, (c + 1) * kChunk); i < end; ++i) {
      const std::array<double, K> v = f(i);
      for (int k = 0; k < K; ++k) s[k] += v[k];
    }
    return s;
  };
  std::array<double, K> total{};
  if (chunks == 1) {  // the same sums in the same order, without the partials' allocation
    const std::array<double, K> s = chunk_sums(0);
    for (int k = 0; k < K; ++k) total[k] += s[k];
    return total;
  }
  std::vector<std::array<double, K>> partial(chunks);
  parallel_for(chunks, threads, [&](int c) { partial[c] = chunk_sums(c); }, 2);
  for (const std::array<double, K>& p : partial)
    for (int k = 0; k < K; ++k) total[k] += p[k];
  return total;
}

// Σ f(i) for i in [0, n), the same bits for any thread count.
template <typename F>
double deterministic_sum(int n, int threads, F&& f) {
  return deterministic_sums<1>(n, threads, [&](int i) { return std::array<double, 1>{f(i)}; })[0];
}

}  // namespace abd
