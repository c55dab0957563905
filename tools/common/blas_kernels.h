// The BLAS kernels under CHOLMOD's factorisations (the drape's and the shells' Newton steps).
#pragma once

#include <string>

namespace textile::cli {

// OpenBLAS picks its kernels when it is loaded, from the CPU's model number, and gives a model
// it does not know its generic SSE3 ("Prescott") kernels even when the CPU has AVX2 or AVX-512.
// On the project's machine (a virtual machine's "Intel(R) Xeon(R) Processor" with AVX-512) the
// drape's Newton steps took 1.3-1.9× longer so (docs/benchmarks.md, "BLAS kernels"). Called at
// the start of main, before any BLAS call: when the BLAS is OpenBLAS, the user has not chosen
// (OPENBLAS_CORETYPE unset), and its kernels predate AVX2 although the CPU has AVX-512 or
// AVX2 + FMA, it re-selects the SkylakeX or Haswell kernels (OpenBLAS's own re-initialisation,
// looked up in the process; nothing happens when any piece is missing).
void ChooseBlasKernels();

// "OpenBLAS <kernels>" or "not OpenBLAS" (the benchmarks' machine record).
std::string BlasKernels();

}  // namespace textile::cli
