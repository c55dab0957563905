// Uses the installed headers and libraries: prints the paper's Fig. 8 law at 1/cm.
#include <cstdio>

#include "textile/sim/bending_law.h"
#include "textile/sim/units.h"

int main() {
  const auto law = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const double m = law.Moment(textile::units::KesCurvatureToSi(1.0));
  std::printf("M(1/cm) = %.6f gf·cm/cm\n", textile::units::SiMomentToKes(m));
  return m > 0.0 ? 0 : 1;
}
