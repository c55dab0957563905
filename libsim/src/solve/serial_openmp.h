#pragma once

// OpenMP regions opened on this thread outside any other region run serially, without the
// runtime, while a SerialOpenMp lives.
//
// Why: CHOLMOD 3 (SuiteSparse 5) opens OpenMP regions of a fixed 4 threads
// (CHOLMOD_OMP_NUM_THREADS, compiled in) for the supernodes of every factorisation. On a
// 2-core machine the wake-ups cost more than the work they share: a 2100-vertex drape (96 Newton
// steps) took 6.2 s wall, 1.7 s of it in the kernel (1.1 million futex calls); with the regions
// inactive (max-active-levels 0), 3.1 s and 0.2 s. An inactive region still makes libgomp build
// a team of one and end it with a barrier whose last thread wakes the waiters by a futex
// system call, waiters or not: a later default Fig. 8 drape (1.9k + 5.3k vertices, about 150
// factorisations) made 2.2 million such calls, about 14 000 a factorisation (most regions'
// `if` clauses are false). So serial_openmp.cc also defines libgomp's entry point for
// `#pragma omp parallel`, GOMP_parallel (the GOMP_4.0 ABI GCC has emitted since 4.9); the
// executable's definition comes first in the dynamic linker's search, so CHOLMOD's calls reach
// it. Inside a SerialOpenMp it calls the region's body once on this thread, as a team of one
// would: outside any region omp_get_num_threads() is 1 and omp_get_thread_num() 0, which is all
// CHOLMOD's regions ask (its only other OpenMP imports).
// Elsewhere, on other threads, and inside a caller's own region (where those would answer for
// the enclosing team), it hands the call to libgomp (the next definition). A program that links
// libtextile_sim.a and calls SolveStatic gets this definition too; its own regions go on to
// libgomp. Measured in docs/methods/benchmarks.md, "OpenMP teams of one".
//
// The max-active-levels setting (a per-thread ICV in libgomp, restored at the end) stays as
// the fallback where the definition does not come first (a shared libtextile_sim loaded after
// libgomp). Without an OpenMP runtime in the process there is nothing to do, and libsim needs
// no OpenMP of its own.

namespace textile {

class SerialOpenMp {
 public:
  SerialOpenMp();
  ~SerialOpenMp();
  SerialOpenMp(const SerialOpenMp&) = delete;
  SerialOpenMp& operator=(const SerialOpenMp&) = delete;

 private:
  int levels_before_ = -1;  // the max-active-levels setting to restore; -1: none was changed
};

}  // namespace textile
