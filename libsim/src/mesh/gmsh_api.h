#ifndef TEXTILE_SIM_SRC_GMSH_API_H_
#define TEXTILE_SIM_SRC_GMSH_API_H_

// Gmsh's C API (gmshc.h), loaded on first use with dlopen instead of linked: libgmsh brings
// about 50 libraries of its own (OpenCASCADE, FLTK, X11, OpenGL, ...) whose relocation cost
// every textile command 0.2-0.3 s at start-up, meshing or not (docs/methods/meshing-and-membrane.md, "Start-up").
// Only pattern_mesh.cc meshes; it holds GmshMutex while it uses Gmsh.
//
//   const textile::gmsh_api::Api& gmsh = textile::gmsh_api::Load();  // throws ComputeError
//   int ierr = 0;
//   gmsh.initialize(0, nullptr, 0, &ierr);

#include <gmshc.h>

#include <string>
#include <vector>

namespace textile::gmsh_api {

// The functions pattern_mesh.cc calls, with gmshc.h's signatures.
struct Api {
  decltype(&::gmshInitialize) initialize;
  decltype(&::gmshFinalize) finalize;
  decltype(&::gmshFree) free;
  decltype(&::gmshOptionSetNumber) option_set_number;
  decltype(&::gmshLoggerStart) logger_start;
  decltype(&::gmshLoggerStop) logger_stop;
  decltype(&::gmshLoggerGetLastError) logger_get_last_error;
  decltype(&::gmshModelAdd) model_add;
  decltype(&::gmshModelOccAddDisk) occ_add_disk;
  decltype(&::gmshModelOccAddPoint) occ_add_point;
  decltype(&::gmshModelOccAddLine) occ_add_line;
  decltype(&::gmshModelOccAddCurveLoop) occ_add_curve_loop;
  decltype(&::gmshModelOccAddPlaneSurface) occ_add_plane_surface;
  decltype(&::gmshModelOccFragment) occ_fragment;
  decltype(&::gmshModelOccSynchronize) occ_synchronize;
  decltype(&::gmshModelMeshSetSizeCallback) mesh_set_size_callback;
  decltype(&::gmshModelMeshRemoveSizeCallback) mesh_remove_size_callback;
  decltype(&::gmshModelMeshGenerate) mesh_generate;
  decltype(&::gmshModelMeshGetNodes) mesh_get_nodes;
  decltype(&::gmshModelMeshGetElements) mesh_get_elements;
};

// Opens the first of `files` (paths or library names) that dlopen can load and resolves every
// function. Throws ComputeError naming what was tried and dlerror() when none loads or a
// function is missing.
Api Open(const std::vector<std::string>& files);

// The library, loaded once (thread-safe): the file named by the environment variable
// TEXTILE_GMSH when set, else the file found at build time, else the development link's name
// (libgmsh.so). Throws as Open; after a failure the next call tries again.
const Api& Load();

}  // namespace textile::gmsh_api

#endif  // TEXTILE_SIM_SRC_GMSH_API_H_
