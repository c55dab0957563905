#ifndef TEXTILE_SIM_LAW_TEXTILE_RANGE_H_
#define TEXTILE_SIM_LAW_TEXTILE_RANGE_H_

// The range that woven, knitted and nonwoven fabrics, technical textiles and composite
// reinforcements span (docs/methods/materials.md, "Plausibility bounds"). Material files refuse values
// outside it as a likely unit mix-up, and the fits search within it.
//
//   if (b_kes > textile::range::kMaxStiffnessKes) ...  // stiffer than any textile

namespace textile::range {

// Bending stiffness b1, b2 of Pabst eq. 1 [gf·cm]: from limp linings and fine silk (~1e-3)
// through apparel (0.01-1) and technical fabrics (10-1000) to composite prepregs and heavy
// technical textiles (a 1 mm glass/carbon sheet: ~1e4-1e5).
inline constexpr double kMinStiffnessKes = 1e-5;
inline constexpr double kMaxStiffnessKes = 1e5;
// |c1| [gf·cm²]: a law that softens from b1 ~ 1e4 to b2 ~ 1e2 gf·cm at κ0 ~ 1e-3 /cm (a
// technical fabric whose moment is almost constant past a small curvature) has |c1| ~ 5e6.
inline constexpr double kMaxAbsQuadraticKes = 1e8;
// The kink κ0 of eq. 1 [1/cm] no lower than this (a radius of curvature of 1 km): below it c1
// is out of scale with b1 and b2 (the fits keep κ0 ≥ 1e-4 /cm).
inline constexpr double kMinKinkCurvatureKes = 1e-5;
// Areal density [g/m²]: tissue-thin silks (~10) to multi-ply prepregs (~3000), with margin.
inline constexpr double kMinGsm = 1.0;
inline constexpr double kMaxGsm = 1e4;

}  // namespace textile::range

#endif  // TEXTILE_SIM_LAW_TEXTILE_RANGE_H_
