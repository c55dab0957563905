#include "serial_openmp.h"

#include <dlfcn.h>

namespace textile {
namespace {

thread_local int serial_depth = 0;  // SerialOpenMp objects alive on this thread

struct LevelsApi {
  void (*set)(int) = nullptr;
  int (*get)() = nullptr;
};

const LevelsApi& Levels() {
  static const LevelsApi api = [] {
    LevelsApi a;
    a.set = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
    a.get = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
    if (a.set == nullptr || a.get == nullptr) a = LevelsApi{};
    return a;
  }();
  return api;
}

}  // namespace

SerialOpenMp::SerialOpenMp() {
  ++serial_depth;
  const LevelsApi& api = Levels();
  if (api.set == nullptr) return;
  levels_before_ = api.get();
  api.set(0);
}

SerialOpenMp::~SerialOpenMp() {
  --serial_depth;
  if (levels_before_ >= 0) Levels().set(levels_before_);
}

}  // namespace textile

// libgomp's entry point for `#pragma omp parallel` (serial_openmp.h says why it is here).
extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags) {
  using Entry = void (*)(void (*)(void*), void*, unsigned, unsigned);
  static const Entry next = reinterpret_cast<Entry>(dlsym(RTLD_NEXT, "GOMP_parallel"));
  static const auto level = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_level"));
  // Only outside every region: inside one, omp_get_num_threads() would be the enclosing team's,
  // and the body would do only its share of the work; libgomp's inactive team of one is right.
  if (next == nullptr || (textile::serial_depth > 0 && (level == nullptr || level() == 0))) {
    fn(data);  // a team of one: this thread, outside any region
    return;
  }
  next(fn, data, num_threads, flags);
}
