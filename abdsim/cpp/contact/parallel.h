// Parallel per-stencil work, on the solver's worker pool (solver/parallel.h): each stencil's
// result goes into its own slot; sums over stencils are done afterwards, serially and in
// stencil order, so results are bit-identical whatever the number of threads.
//
// Only heavy loops (Hessians with their eigen-decompositions, CCD) run in parallel, and only
// above a size at which the work dwarfs the hand-off. The pool (not OpenMP) keeps a single
// set of worker threads for the solver and the contact code: two pools spinning against each
// other on a small machine made resting-contact steps five times slower.
#pragma once

#include "solver/parallel.h"

namespace abd::contact {
constexpr int kMinParallelHessians = 64;
constexpr int kMinParallelCcd = 1024;

// f(i) for i in [0, n), on up to `threads` threads when `parallel`.
template <class F>
void for_each_stencil(int n, bool parallel, int threads, F&& f) {
  if (parallel && threads > 1) {
    parallel_for(n, threads, f, 1);
  } else {
    for (int i = 0; i < n; ++i) f(i);
  }
}
}  // namespace abd::contact
