// libFuzzer target: rig JSON (textile::ParseRigJson) on arbitrary bytes. Anything but a Rig or
// an InputError is a bug (a crash, another exception, a sanitizer report).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "textile/photo/rig.h"
#include "textile/sim/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const textile::Rig rig = textile::ParseRigJson(text, "fuzz");
    // A rig that parsed maps points without crashing (NaN beyond the horizon is allowed), its
    // map is finite, and it survives a round trip through the file format.
    if (!rig.plane_from_image.allFinite()) __builtin_trap();
    const Eigen::Vector2d p = rig.PlaneFromImage({10.0, 20.0});
    (void)p;
    (void)rig.MmPerPxAt({10.0, 20.0});
    const textile::Rig again = textile::ParseRigJson(textile::RigToJson(rig), "fuzz round trip");
    if (again.plain_scale != rig.plain_scale || again.lens.has_value() != rig.lens.has_value() ||
        again.image_size.has_value() != rig.image_size.has_value()) {
      __builtin_trap();
    }
    // What extract does with a rig before using it on a photo: throws InputError or passes.
    try {
      rig.CheckForImage(640, 480, "fuzz.png");
    } catch (const textile::InputError&) {
    }
  } catch (const textile::InputError&) {
  }
  return 0;
}
