// Gmsh is loaded at run time (libsim/src/mesh/gmsh_api.h): what the loader says when the library is
// missing or is not Gmsh, and that the installed one has every function the mesher calls.

#include "mesh/gmsh_api.h"

#include <gtest/gtest.h>

#include <string>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

std::string OpenError(const std::vector<std::string>& files) {
  try {
    gmsh_api::Open(files);
  } catch (const ComputeError& e) {
    return e.what();
  }
  return "";
}

TEST(GmshApi, TheInstalledLibraryHasEveryFunctionTheMesherCalls) {
  const gmsh_api::Api& api = gmsh_api::Load();
  EXPECT_NE(api.initialize, nullptr);
  EXPECT_NE(api.occ_fragment, nullptr);
  EXPECT_NE(api.mesh_get_elements, nullptr);
  EXPECT_NE(api.free, nullptr);
}

TEST(GmshApi, AMissingLibraryIsAClearError) {
  const std::string why = OpenError({"/nonexistent/libgmsh.so.9", "libgmsh-not-there.so"});
  EXPECT_NE(why.find("cannot load Gmsh (tried /nonexistent/libgmsh.so.9, libgmsh-not-there.so)"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("TEXTILE_GMSH"), std::string::npos) << why;
  EXPECT_NE(OpenError({}).find("no file to try"), std::string::npos);
}

TEST(GmshApi, ALibraryThatIsNotGmshIsRefusedByName) {
  const std::string why = OpenError({"libm.so.6"});
  EXPECT_NE(why.find("libm.so.6 is not a Gmsh library with the C API (no gmshInitialize)"),
            std::string::npos)
      << why;
}

TEST(GmshApi, TheFirstFileThatLoadsIsUsed) {
  const gmsh_api::Api& installed = gmsh_api::Load();
  const gmsh_api::Api api = gmsh_api::Open({"/nonexistent/libgmsh.so.9", "libgmsh.so"});
  // The same library, already loaded: dlopen hands back the same functions.
  EXPECT_EQ(api.initialize, installed.initialize);
}

}  // namespace
}  // namespace textile
