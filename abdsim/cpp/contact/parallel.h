// Optional OpenMP for per-stencil work. Loops using it write each stencil's result into its
// own slot; sums over stencils are done afterwards, serially and in stencil order, so results
// are bit-identical whatever the number of threads.
//
// Only heavy loops (Hessians with their eigen-decompositions, CCD) run in parallel, and only
// above a size at which the work dwarfs a fork/join: on a busy machine a parallel region over
// light work costs far more than it saves (measured: 25x slower gradients on 2 loaded cores).
// Dynamic scheduling keeps a descheduled thread from holding up the others.
#pragma once

#define ABD_PRAGMA(x) _Pragma(#x)
#ifdef _OPENMP
#define ABD_PARALLEL_FOR_IF(condition) ABD_PRAGMA(omp parallel for schedule(dynamic, 32) if(condition))
#else
#define ABD_PARALLEL_FOR_IF(condition)
#endif

namespace abd::contact {
constexpr int kMinParallelHessians = 64;
constexpr int kMinParallelCcd = 1024;
}  // namespace abd::contact
