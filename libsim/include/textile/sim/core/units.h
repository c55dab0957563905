#ifndef TEXTILE_SIM_CORE_UNITS_H_
#define TEXTILE_SIM_CORE_UNITS_H_

// Units at the edges. Everything inside textile is SI (m, kg, N, s, rad); people read and
// write lab units. The bending law is per unit width: M in N·m/m = N, κ in 1/m, b in N·m,
// c1 in N·m². KES units (Kawabata KES-FB2): M in gf·cm/cm, κ in 1/cm, b in gf·cm
// ("gf·cm²/cm"), c1 in gf·cm². See docs/spec/physics.md, "Units".
//
//   double b1_si = textile::units::KesStiffnessToSi(0.1);   // 9.80665e-6 N·m
//   double rho = textile::units::GsmToSi(200.0);           // 0.2 kg/m²

namespace textile::units {

inline constexpr double kGravity = 9.80665;           // standard gravity [m/s²]
inline constexpr double kGramForce = 9.80665e-3;      // 1 gf [N]
inline constexpr double kGfCm = 9.80665e-5;           // 1 gf·cm [N·m]
inline constexpr double kGfCm2 = 9.80665e-7;          // 1 gf·cm² [N·m²]
inline constexpr double kMgCm = 1e-8;                 // 1 mg·cm [kg·m]

// Lengths.
constexpr double MmToM(double mm) { return mm * 1e-3; }
constexpr double MToMm(double m) { return m * 1e3; }

// Areal density: g/m² ("gsm") <-> kg/m².
constexpr double GsmToSi(double gsm) { return gsm * 1e-3; }
constexpr double SiToGsm(double kg_per_m2) { return kg_per_m2 * 1e3; }

// Curvature: 1/cm <-> 1/m.
constexpr double KesCurvatureToSi(double per_cm) { return per_cm * 100.0; }
constexpr double SiCurvatureToKes(double per_m) { return per_m / 100.0; }

// Moment per unit width: gf·cm/cm (= gf) <-> N·m/m (= N).
constexpr double KesMomentToSi(double gf_cm_per_cm) { return gf_cm_per_cm * kGramForce; }
constexpr double SiMomentToKes(double n) { return n / kGramForce; }

// Bending stiffness per unit width (b1, b2, B): gf·cm <-> N·m.
constexpr double KesStiffnessToSi(double gf_cm) { return gf_cm * kGfCm; }
constexpr double SiStiffnessToKes(double n_m) { return n_m / kGfCm; }

// Quadratic coefficient c1: gf·cm² <-> N·m².
constexpr double KesQuadraticToSi(double gf_cm2) { return gf_cm2 * kGfCm2; }
constexpr double SiQuadraticToKes(double n_m2) { return n_m2 / kGfCm2; }

// Flexural rigidity G = ρ g c³ per unit width [N·m] in the units labs print.
constexpr double SiRigidityToMicroNm(double n_m) { return n_m * 1e6; }
constexpr double SiRigidityToMgCm(double n_m) { return n_m / kGravity / kMgCm; }
constexpr double SiRigidityToGfCm(double n_m) { return n_m / kGfCm; }

}  // namespace textile::units

#endif  // TEXTILE_SIM_CORE_UNITS_H_
