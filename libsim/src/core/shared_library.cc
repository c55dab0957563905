#include "textile/sim/core/shared_library.h"

#include <dlfcn.h>

#include <string>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {

void* OpenFirstLibrary(const std::vector<std::string>& files, const std::string& what,
                       const std::string& hint, std::string* opened) {
  std::string tried, why = "no file to try";
  for (const std::string& name : files) {
    if (name.empty()) continue;
    if (void* handle = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL)) {
      if (opened) *opened = name;
      return handle;
    }
    const char* e = dlerror();
    tried += (tried.empty() ? "" : ", ") + name;
    why = e ? e : "unknown error";
  }
  if (tried.empty()) throw ComputeError("cannot load " + what + ": no file to try; " + hint);
  throw ComputeError("cannot load " + what + " (tried " + tried + "): " + why + "; " + hint);
}

void* FindSymbol(void* handle, const char* name) { return dlsym(handle, name); }

void CloseLibrary(void* handle) {
  if (handle) dlclose(handle);
}

}  // namespace textile
