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

// The kernels for the CPU's vector units, or null when OpenBLAS's choice stands.
const char* BetterKernels() {
#if defined(__x86_64__)
  __builtin_cpu_init();
  // GCC's checks include the OS's support for the registers (XGETBV).
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512vl"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
#endif
  return nullptr;
}

}  // namespace

void ChooseBlasKernels() {
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return;  // the user's choice
  const auto core_name = Find<CoreName>("openblas_get_corename");
  const auto quit = Find<Hook>("gotoblas_dynamic_quit");
  const auto init = Find<Hook>("gotoblas_dynamic_init");
  if (core_name == nullptr || quit == nullptr || init == nullptr) return;  // not a dynamic build
  if (std::string_view(core_name()) != "Prescott") return;
  const char* better = BetterKernels();
  if (better == nullptr) return;  // a real Pentium 4 class CPU
  // gotoblas_dynamic_init reads OPENBLAS_CORETYPE and sets up that kernel table (block sizes
  // only); quit only forgets the current one. No BLAS call has run yet, so no buffer exists.
  setenv("OPENBLAS_CORETYPE", better, 0);
  quit();
  init();
}

std::string BlasKernels() {
  const auto core_name = Find<CoreName>("openblas_get_corename");
  if (core_name == nullptr) return "not OpenBLAS";
  std::string s = std::string("OpenBLAS ") + core_name();
  if (Find<Hook>("gotoblas_dynamic_init") == nullptr) s += " (fixed)";
  return s;
}

}  // namespace textile::cli
