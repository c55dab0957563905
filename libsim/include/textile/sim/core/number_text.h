#ifndef TEXTILE_SIM_CORE_NUMBER_TEXT_H_
#define TEXTILE_SIM_CORE_NUMBER_TEXT_H_

// Numbers in messages and notes, written one way everywhere.
//
//   NumberText(0.123456789)     -> "0.123457"   (printf %.6g)
//   NumberText(1234.5, 3)       -> "1.23e+03"
//   NumberText(NaN)             -> "nan";  NumberText(-inf) -> "-inf"

#include <string>

namespace textile {

// `value` with `significant` significant digits, as printf's %.*g; "nan", "inf", "-inf" for
// the non-finite. For messages: JSON results keep full precision.
std::string NumberText(double value, int significant = 6);

}  // namespace textile

#endif  // TEXTILE_SIM_CORE_NUMBER_TEXT_H_
