// OpenMP helpers whose results do not depend on the number of threads: work is split into
// fixed chunks and partial results are combined in chunk order.
#pragma once
#include <algorithm>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace abd {

// Loops with less work than this many bodies run on one thread (no fork/join cost).
constexpr int kParallelMinBodies = 64;

inline int resolve_threads(int requested) {
#ifdef _OPENMP
  return requested > 0 ? requested : omp_get_max_threads();
#else
  (void)requested;
  return 1;
#endif
}

// f(i) for i in [0, n), in parallel when n >= min_parallel.
template <typename F>
void parallel_for(int n, int threads, F&& f, int min_parallel = kParallelMinBodies) {
#ifdef _OPENMP
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= min_parallel && threads > 1)
  for (int i = 0; i < n; ++i) f(i);
#else
  (void)threads;
  (void)min_parallel;
  for (int i = 0; i < n; ++i) f(i);
#endif
}

// Σ f(i) for i in [0, n), the same bits for any thread count.
template <typename F>
double deterministic_sum(int n, int threads, F&& f) {
  constexpr int kChunk = 256;
  const int chunks = (n + kChunk - 1) / kChunk;
  if (chunks <= 1) {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += f(i);
    return s;
  }
  std::vector<double> partial(chunks, 0.0);
  parallel_for(
      chunks, threads,
      [&](int c) {
        const int end = std::min(n, (c + 1) * kChunk);
        double s = 0.0;
        for (int i = c * kChunk; i < end; ++i) s += f(i);
        partial[c] = s;
      },
      2);
  double s = 0.0;
  for (double p : partial) s += p;
  return s;
}

}  // namespace abd
