// The BLAS kernels under CHOLMOD's factorisations (the drape's and the shells' Newton steps).
#pragma once

#include <string>

namespace textile::cli {

// OpenBLAS picks its kernels when it is loaded, from the CPU's family and model. Debian 12's
// OpenBLAS 0.3.21 takes Intel family-6 models 0xC0-0xCF (this machine's virtual "Intel(R)
// Xeon(R) Processor" is model 207, with AVX-512) for a Pentium 4 and runs its SSE3 "Prescott"
// kernels (a fall-through in its model table, fixed in OpenBLAS 0.3.25): a 10k-vertex drape
// solve ran 1.3-1.4× slower, the default drape about 5 % (docs/methods/benchmarks.md, "BLAS kernels").
// Called first in main, before any BLAS call: when the BLAS is OpenBLAS's dynamic-architecture
// build, the user has not chosen (OPENBLAS_CORETYPE unset), it chose "Prescott", and the x86-64
// CPU has AVX-512 or AVX2 + FMA, it re-selects the SkylakeX or Haswell kernels (OpenBLAS's own
// re-initialisation, looked up in the process). Otherwise nothing happens.
void ChooseBlasKernels();

// "OpenBLAS <kernels>", "OpenBLAS <KERNELS> (fixed)" for a build for one architecture, or
// "not OpenBLAS" (textile --version, the benchmarks' machine record).
std::string BlasKernels();

}  // namespace textile::cli
