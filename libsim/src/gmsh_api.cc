#include "gmsh_api.h"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/error.h"

#ifndef TEXTILE_GMSH_LIBRARY
#define TEXTILE_GMSH_LIBRARY ""
#endif
#ifndef TEXTILE_GMSH_LINK_NAME
#define TEXTILE_GMSH_LINK_NAME "libgmsh.so"
#endif

namespace textile::gmsh_api {
namespace {

template <class F>
void Resolve(void* handle, const std::string& file, const char* name, F* f) {
  *f = reinterpret_cast<F>(dlsym(handle, name));
  if (!*f) {
    throw ComputeError("pattern mesh: " + file + " is not a Gmsh library with the C API (no " +
                       name + ")");
  }
}

}  // namespace

Api Open(const std::vector<std::string>& files) {
  std::string tried, why = "no file to try", file;
  void* handle = nullptr;
  for (const std::string& name : files) {
    if (name.empty()) continue;
    handle = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL);
    file = name;
    if (handle) break;
    const char* e = dlerror();
    tried += (tried.empty() ? "" : ", ") + name;
    why = e ? e : "unknown error";
  }
  if (!handle) {
    throw ComputeError("pattern mesh: cannot load Gmsh (tried " + tried + "): " + why +
                       "; install the libgmsh package or set TEXTILE_GMSH to its library file");
  }
  Api api;
  try {
    Resolve(handle, file, "gmshInitialize", &api.initialize);
    Resolve(handle, file, "gmshFinalize", &api.finalize);
    Resolve(handle, file, "gmshFree", &api.free);
    Resolve(handle, file, "gmshOptionSetNumber", &api.option_set_number);
    Resolve(handle, file, "gmshLoggerStart", &api.logger_start);
    Resolve(handle, file, "gmshLoggerStop", &api.logger_stop);
    Resolve(handle, file, "gmshLoggerGetLastError", &api.logger_get_last_error);
    Resolve(handle, file, "gmshModelAdd", &api.model_add);
    Resolve(handle, file, "gmshModelOccAddDisk", &api.occ_add_disk);
    Resolve(handle, file, "gmshModelOccAddPoint", &api.occ_add_point);
    Resolve(handle, file, "gmshModelOccAddLine", &api.occ_add_line);
    Resolve(handle, file, "gmshModelOccAddCurveLoop", &api.occ_add_curve_loop);
    Resolve(handle, file, "gmshModelOccAddPlaneSurface", &api.occ_add_plane_surface);
    Resolve(handle, file, "gmshModelOccFragment", &api.occ_fragment);
    Resolve(handle, file, "gmshModelOccSynchronize", &api.occ_synchronize);
    Resolve(handle, file, "gmshModelMeshSetSizeCallback", &api.mesh_set_size_callback);
    Resolve(handle, file, "gmshModelMeshRemoveSizeCallback", &api.mesh_remove_size_callback);
    Resolve(handle, file, "gmshModelMeshGenerate", &api.mesh_generate);
    Resolve(handle, file, "gmshModelMeshGetNodes", &api.mesh_get_nodes);
    Resolve(handle, file, "gmshModelMeshGetElements", &api.mesh_get_elements);
  } catch (...) {
    dlclose(handle);
    throw;
  }
  return api;  // the handle stays open for the life of the process
}

const Api& Load() {
  static std::mutex mutex;
  static std::optional<Api> api;
  std::lock_guard<std::mutex> lock(mutex);
  if (!api) {
    const char* chosen = std::getenv("TEXTILE_GMSH");
    api = chosen && *chosen ? Open({chosen}) : Open({TEXTILE_GMSH_LIBRARY, TEXTILE_GMSH_LINK_NAME});
  }
  return *api;
}

}  // namespace textile::gmsh_api
