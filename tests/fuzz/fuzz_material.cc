// libFuzzer target: material JSON (textile::ParseMaterialJson) on arbitrary bytes. Anything but
// a Material or an InputError is a bug (a crash, another exception, a sanitizer report).
#include <cstddef>
#include <cstdint>
#include <string>

#include "textile/sim/core/error.h"
#include "textile/sim/law/material.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const textile::Material m = textile::ParseMaterialJson(text, "fuzz");
    // A material that parsed must be usable: its law evaluates to finite numbers, and it
    // survives a round trip.
    const textile::BendingLaw law = m.EffectiveLaw();
    if (!(law.Moment(100.0) > 0.0) || !(law.Stiffness(0.0) > 0.0)) __builtin_trap();
    textile::ParseMaterialJson(textile::MaterialToJson(m).dump(), "fuzz round trip");
  } catch (const textile::InputError&) {
  }
  return 0;
}
