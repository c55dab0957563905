#include "common/blas_kernels.h"

#include <dlfcn.h>

#include <cstdlib>
#include <string_view>

namespace textile::cli {
namespace {

using CoreName = char* (*)();
using Hook = void (*)();

template <typename F>
F Find(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_DEFAULT, name));
}

// OpenBLAS's x86-64 kernels with AVX2 (or better); any other is an older generation.
bool HasAvx2Kernels(std::string_view core) {
  for (std::string_view k : {"Haswell", "Zen", "SkylakeX", "Cooperlake", "SapphireRapids"})
    if (core == k) return true;
  return false;
}

}  // namespace

void ChooseBlasKernels() {
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return;  // the user's choice
  const auto core_name = Find<CoreName>("openblas_get_corename");
  const auto quit = Find<Hook>("gotoblas_dynamic_quit");
  const auto init = Find<Hook>("gotoblas_dynamic_init");
  if (core_name == nullptr || quit == nullptr || init == nullptr) return;  // not OpenBLAS's dynamic build
  if (HasAvx2Kernels(core_name())) return;
  __builtin_cpu_init();
  const char* better = nullptr;
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512vl")) {
    better = "SkylakeX";
  } else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    better = "Haswell";
  }
  if (better == nullptr) return;
  // gotoblas_dynamic_init reads OPENBLAS_CORETYPE and initialises that kernel table; quit only
  // forgets the current one. No BLAS call has run yet, so no buffer holds the old blocking.
  setenv("OPENBLAS_CORETYPE", better, 0);
  quit();
  init();
}

std::string BlasKernels() {
  const auto core_name = Find<CoreName>("openblas_get_corename");
  return core_name != nullptr ? std::string("OpenBLAS ") + core_name() : "not OpenBLAS";
}

}  // namespace textile::cli
