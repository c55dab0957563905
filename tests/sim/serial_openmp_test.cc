#include "solve/serial_openmp.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <atomic>

namespace textile {
namespace {

// *largest = max(*largest, value), from any thread.
void RaiseTo(std::atomic<int>* largest, int value) {
  int seen = largest->load();
  while (value > seen && !largest->compare_exchange_weak(seen, value)) {
  }
}

// CHOLMOD opens its OpenMP regions with libgomp's GOMP_parallel. While a SerialOpenMp lives, a
// region (called the way CHOLMOD calls it, through the process's symbol) runs its body once on
// this thread without making a team, so nothing wakes other threads and no barrier ends it;
// otherwise the call reaches libgomp, which runs a team of the threads asked for.
TEST(SerialOpenMp, RegionsRunWithoutATeamWhileSerial) {
  using Body = void (*)(void*);
  auto parallel = reinterpret_cast<void (*)(Body, void*, unsigned, unsigned)>(
      dlsym(RTLD_DEFAULT, "GOMP_parallel"));
  auto level = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_level"));
  ASSERT_NE(parallel, nullptr);
  struct Seen {
    int (*level)();
    std::atomic<int> calls{0};
    std::atomic<int> deepest{-1};
  } seen{level};
  const Body body = [](void* data) {
    auto* s = static_cast<Seen*>(data);
    ++s->calls;
    RaiseTo(&s->deepest, s->level != nullptr ? s->level() : 0);
  };
  {
    const SerialOpenMp serial;
    parallel(body, &seen, 4, 0);
  }
  EXPECT_EQ(seen.calls.load(), 1);
  EXPECT_EQ(seen.deepest.load(), 0);  // not inside any region, not even an inactive one
  if (level == nullptr) GTEST_SKIP() << "no OpenMP runtime in this process";
  seen.calls = 0;
  seen.deepest = -1;
  // The guard is gone: libgomp's team, of two unless OMP_THREAD_LIMIT or OMP_DYNAMIC give fewer.
  parallel(body, &seen, 2, 0);
  EXPECT_GE(seen.calls.load(), 1);
  EXPECT_LE(seen.calls.load(), 2);
  EXPECT_EQ(seen.deepest.load(), 1);
}

// Inside a caller's own OpenMP team, a serial region still runs every iteration on each thread:
// the body sees a team of one (libgomp's inactive region), not the enclosing team, whose size
// would make CHOLMOD's statically scheduled loops do only this thread's share.
struct NestedRun {
  void (*parallel)(void (*)(void*), void*, unsigned, unsigned);
  int (*num_threads)();
  std::atomic<int> outer{0};
  std::atomic<int> inner{0};
  std::atomic<int> widest{0};  // the largest team size an inner body saw
};

void InnerBody(void* data) {
  auto* run = static_cast<NestedRun*>(data);
  ++run->inner;
  RaiseTo(&run->widest, run->num_threads());
}

void OuterBody(void* data) {
  auto* run = static_cast<NestedRun*>(data);
  ++run->outer;
  const SerialOpenMp serial;
  run->parallel(InnerBody, data, 4, 0);
}

TEST(SerialOpenMp, RegionsInsideACallersTeamSeeATeamOfOne) {
  NestedRun run;
  run.parallel = reinterpret_cast<void (*)(void (*)(void*), void*, unsigned, unsigned)>(
      dlsym(RTLD_DEFAULT, "GOMP_parallel"));
  run.num_threads = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_num_threads"));
  if (run.parallel == nullptr || run.num_threads == nullptr)
    GTEST_SKIP() << "no OpenMP runtime in this process";
  run.parallel(OuterBody, &run, 2, 0);
  EXPECT_EQ(run.inner.load(), run.outer.load());  // one inner region per outer thread
  EXPECT_EQ(run.widest.load(), 1);                // each a team of one
  // With a team of one the direct call would see one thread too: nothing was checked.
  if (run.outer.load() < 2)
    GTEST_SKIP()
        << "libgomp gave a team of one (OMP_THREAD_LIMIT, OMP_DYNAMIC or OMP_MAX_ACTIVE_LEVELS)";
}

}  // namespace
}  // namespace textile
