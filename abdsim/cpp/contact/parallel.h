// Optional OpenMP for per-stencil work. Loops using it write each stencil's result into its
// own slot; sums over stencils are done afterwards, serially and in stencil order, so results
// are bit-identical whatever the number of threads.
#pragma once

#ifdef _OPENMP
#define ABD_PARALLEL_FOR _Pragma("omp parallel for schedule(static)")
#else
#define ABD_PARALLEL_FOR
#endif
