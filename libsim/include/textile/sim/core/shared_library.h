#ifndef TEXTILE_SIM_CORE_SHARED_LIBRARY_H_
#define TEXTILE_SIM_CORE_SHARED_LIBRARY_H_

// Internal to textile (its loaders of Gmsh and OpenCV's image codecs), not part of the physics
// API. Libraries opened at run time instead of linked: each brings
// dozens of libraries of its own whose relocation would cost every `textile` command at
// start-up, whether it needs them or not (docs/methods/meshing-and-membrane.md, "Start-up").
//
//   std::string file;
//   void* handle = textile::OpenFirstLibrary({"/usr/lib/x/libfoo.so.1", "libfoo.so"},
//                                            "foo", "install libfoo", &file);
//   auto* f = reinterpret_cast<int (*)(int)>(textile::FindSymbol(handle, "foo_twice"));

#include <cstdlib>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace textile {

// Opens the first of `files` (paths or library names; empty ones skipped) that dlopen can load
// (RTLD_NOW | RTLD_LOCAL); *opened (if not null) gets its name. The handle is the caller's to
// close or keep. Throws ComputeError "cannot load <what> (tried a, b): <the last dlerror>;
// <hint>", or "cannot load <what>: no file to try; <hint>" when `files` names none.
void* OpenFirstLibrary(const std::vector<std::string>& files, const std::string& what,
                       const std::string& hint, std::string* opened);

// The address of `name` in the library, or null.
void* FindSymbol(void* handle, const char* name);

void CloseLibrary(void* handle);

// open(files) made once per Api type (thread-safe) and kept: with the file named by the
// environment variable `env` when it is set, else with `defaults`. Throws what open throws;
// after a failure the next call tries again.
template <class Api>
const Api& LoadOnce(const char* env, const std::vector<std::string>& defaults,
                    Api (*open)(const std::vector<std::string>&)) {
  static std::mutex mutex;
  static std::optional<Api> api;
  std::lock_guard<std::mutex> lock(mutex);
  if (!api) {
    const char* chosen = std::getenv(env);
    api = chosen && *chosen ? open({chosen}) : open(defaults);
  }
  return *api;
}

}  // namespace textile

#endif  // TEXTILE_SIM_CORE_SHARED_LIBRARY_H_
