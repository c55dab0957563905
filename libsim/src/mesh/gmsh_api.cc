#include "gmsh_api.h"

#include <string>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/shared_library.h"

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
  *f = reinterpret_cast<F>(FindSymbol(handle, name));
  if (!*f) {
    throw ComputeError("pattern mesh: " + file + " is not a Gmsh library with the C API (no " +
                       name + ")");
  }
}

}  // namespace

Api Open(const std::vector<std::string>& files) {
  std::string file;
  void* handle = nullptr;
  try {
    handle = OpenFirstLibrary(files, "Gmsh",
                              "install the libgmsh package or set TEXTILE_GMSH to its library file",
                              &file);
  } catch (const ComputeError& e) {
    throw ComputeError(std::string("pattern mesh: ") + e.what());
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
    CloseLibrary(handle);
    throw;
  }
  return api;  // the handle stays open for the life of the process
}

const Api& Load() {
  return LoadOnce<Api>("TEXTILE_GMSH", {TEXTILE_GMSH_LIBRARY, TEXTILE_GMSH_LINK_NAME}, &Open);
}

}  // namespace textile::gmsh_api
