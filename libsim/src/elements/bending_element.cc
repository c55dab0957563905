#include "textile/sim/elements/bending_element.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <barrier>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>
#include <utility>

#include "hinge_angle.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using hinge_angle::Position;

// The SIMD kernels below are compiled three times on x86-64 Linux with GCC: for AVX-512, AVX2
// and the baseline, picked at load time (function multiversioning); elsewhere once. No FMA in
// any clone (-ffp-contract=off, libsim/CMakeLists.txt), so all give the same bits.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define TEXTILE_SIMD_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define TEXTILE_SIMD_CLONES
#endif
#if defined(__GNUC__)
#define TEXTILE_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define TEXTILE_ALWAYS_INLINE inline
#endif

// atan2(y, x) in (-π, π] without a library call, so that it vectorises: octant reduction to
// |t| ≤ tan(π/8) (one division), then t + t s P(s), s = t², P a degree-10 Chebyshev fit of
// (atan t - t)/(t s) whose error is 3e-17 (so ≤ 6e-18 relative in atan); the result is within
// ~1 ulp of π of the exact angle. atan2(0, 0) = 0.
TEXTILE_ALWAYS_INLINE double Atan2(double y, double x) {
  constexpr double kP[11] = {-0.01917688711906226,  0.039231658295587189, -0.050854497379402598,
                             0.0585814891280221,    -0.066645114473819475, 0.076921831908260865,
                             -0.090909045781239026, 0.11111111015256361,   -0.14285714284666542,
                             0.19999999999995521,   -0.33333333333333331};
  constexpr double kTanPi8 = 0.41421356237309503, kPi4 = 0.78539816339744828;
  constexpr double kPi2 = 1.5707963267948966, kPi = 3.1415926535897931;
  const double ax = std::abs(x), ay = std::abs(y);
  const double lo = ay < ax ? ay : ax, hi = ay < ax ? ax : ay;
  const bool mid = lo > kTanPi8 * hi;  // atan(lo/hi) = π/4 + atan((lo - hi)/(lo + hi))
  const double num = mid ? lo - hi : lo;
  double den = mid ? lo + hi : hi;
  den = den > 0.0 ? den : 1.0;
  const double t = num / den, s = t * t;
  // Horner, written out (a loop here is not unrolled at -O2 and would stop vectorisation).
  double p = kP[0] * s + kP[1];
  p = p * s + kP[2];
  p = p * s + kP[3];
  p = p * s + kP[4];
  p = p * s + kP[5];
  p = p * s + kP[6];
  p = p * s + kP[7];
  p = p * s + kP[8];
  p = p * s + kP[9];
  p = p * s + kP[10];
  double r = (mid ? kPi4 : 0.0) + (t + t * s * p);
  r = ay > ax ? kPi2 - r : r;
  r = x < 0.0 ? kPi - r : r;
  return std::copysign(r, y);
}

constexpr int kLanes = 8;  // hinges per SIMD block

// Positions of a block of hinges, lane-minor: p[3 i + c][l] = coordinate c of vertex v[i] of
// hinge (first + l).
struct LanePositions {
  alignas(64) double p[12][kLanes];
};

// The moment-curvature law's coefficients, for branch-free evaluation (same expressions as
// BendingLaw, so that the results are the same bits).
struct LawCoefficients {
  double b1, b2, c1, kappa0, moment0, energy0;
  // A spline law's coefficients are not used (BendingElements::hinge_by_hinge_).
  explicit LawCoefficients(const BendingLaw& law)
      : b1(law.b1()),
        b2(law.b2()),
        c1(law.c1()),
        kappa0(law.kappa0()),
        moment0(law.moment0()),
        energy0(law.Energy(law.kappa0())) {}
  TEXTILE_ALWAYS_INLINE double Moment(double kappa) const {
    const double k = std::abs(kappa);
    const double m = k <= kappa0 ? (b1 + c1 * k) * k : moment0 + b2 * k;
    return std::copysign(m, kappa);
  }
  TEXTILE_ALWAYS_INLINE double Stiffness(double kappa) const {
    const double k = std::abs(kappa);
    return k <= kappa0 ? b1 + 2.0 * c1 * k : b2;
  }
  TEXTILE_ALWAYS_INLINE double Energy(double kappa) const {
    const double k = std::abs(kappa);
    return k <= kappa0 ? (0.5 * b1 + c1 * k / 3.0) * k * k
                       : energy0 + moment0 * (k - kappa0) + 0.5 * b2 * (k * k - kappa0 * kappa0);
  }
};

// Inputs of the dihedral kernel for one block of kLanes hinges (rest arrays start at the block).
struct DihedralLanesIn {
  bool pabst;        // else Bridson
  bool anisotropic;  // blend warp and weft with warp_weight
  bool bias;         // and the bias law with bias_weight
  const LawCoefficients* warp;
  const LawCoefficients* weft;
  const LawCoefficients* bias_law;
  const double *rest_angle, *inv_height, *weight, *warp_weight, *bias_weight, *sin_half,
      *cos_half;
};

// Outputs: energy[l] (when asked), dE/dθ times ∂θ/∂x as grad[3 i + c][l] (when asked),
// and for the Hessian dE/dθ, d²E/dθ² and ∂θ/∂x (unscaled) in grad.
struct DihedralLanesOut {
  alignas(64) double energy[kLanes];
  alignas(64) double d_energy[kLanes];
  alignas(64) double d2_energy[kLanes];
  alignas(64) double grad[12][kLanes];
};

// One block of dihedral hinges: bend angle, law, gradient (docs/methods/bending.md). kHessian: grad is
// ∂θ/∂x unscaled and d_energy, d2_energy are filled.
enum class LaneModel { kPabst, kPabstWarpWeft, kPabstWarpWeftBias, kBridson };

// The law's value f(law) for lane l: the warp law's, or the blend of the direction laws with the
// lane's weights (the weft's is 1 - warp - bias).
template <LaneModel kModel, class F>
TEXTILE_ALWAYS_INLINE double LaneLaw(const DihedralLanesIn& in, const LawCoefficients& warp,
                                     const LawCoefficients& weft, const LawCoefficients& bias,
                                     int l, F&& f) {
  const double a = f(warp);
  if constexpr (kModel == LaneModel::kPabstWarpWeft) {
    const double ww = in.warp_weight[l];
    return ww * a + (1.0 - ww) * f(weft);
  } else if constexpr (kModel == LaneModel::kPabstWarpWeftBias) {
    const double ww = in.warp_weight[l], wb = in.bias_weight[l];
    return ww * a + wb * f(bias) + (1.0 - ww - wb) * f(weft);
  } else {
    return a;
  }
}

// Where the kernel reads coordinate c of corner i of lane l: gathered lanes (LanePositions) or
// straight from the positions through the corners' offsets (GatherPositions).
struct GatherPositions {
  const double* x;       // #V×3 positions, row-major
  const int* corner[4];  // offsets 3 v[i] of the block's hinges
  TEXTILE_ALWAYS_INLINE double at(int i, int c, int l) const { return x[corner[i][l] + c]; }
};
TEXTILE_ALWAYS_INLINE double PositionAt(const LanePositions& pos, int i, int c, int l) {
  return pos.p[3 * i + c][l];
}
TEXTILE_ALWAYS_INLINE double PositionAt(const GatherPositions& pos, int i, int c, int l) {
  return pos.at(i, c, l);
}

template <LaneModel kModel, bool kEnergy, bool kGradient, bool kHessian, class Positions>
TEXTILE_ALWAYS_INLINE void DihedralLanesImpl(const DihedralLanesIn& in, const Positions& pos,
                                             DihedralLanesOut* out) {
  // Local copies: loads in the arms of a conditional through a pointer would not if-convert.
  const LawCoefficients warp = *in.warp, weft = *in.weft, bias = *in.bias_law;
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    const double x2x = PositionAt(pos, 2, 0, l), x2y = PositionAt(pos, 2, 1, l),
                 x2z = PositionAt(pos, 2, 2, l);
    const double ex = PositionAt(pos, 3, 0, l) - x2x, ey = PositionAt(pos, 3, 1, l) - x2y,
                 ez = PositionAt(pos, 3, 2, l) - x2z;
    const double a0x = PositionAt(pos, 0, 0, l) - x2x, a0y = PositionAt(pos, 0, 1, l) - x2y,
                 a0z = PositionAt(pos, 0, 2, l) - x2z;
    const double a1x = PositionAt(pos, 1, 0, l) - x2x, a1y = PositionAt(pos, 1, 1, l) - x2y,
                 a1z = PositionAt(pos, 1, 2, l) - x2z;
    // n0 = e × a0, n1 = a1 × e.
    const double n0x = ey * a0z - ez * a0y, n0y = ez * a0x - ex * a0z, n0z = ex * a0y - ey * a0x;
    const double n1x = a1y * ez - a1z * ey, n1y = a1z * ex - a1x * ez, n1z = a1x * ey - a1y * ex;
    const double l2 = ex * ex + ey * ey + ez * ez, len = std::sqrt(l2);
    const double cos_term = n0x * n1x + n0y * n1y + n0z * n1z;
    const double sin_term = len * (n1x * a0x + n1y * a0y + n1z * a0z);
    double energy = 0.0, d_energy, d2_energy = 0.0;
    if constexpr (kModel != LaneModel::kBridson) {
      const double kappa = (Atan2(sin_term, cos_term) - in.rest_angle[l]) * in.inv_height[l];
      const double w = in.weight[l], ih = in.inv_height[l];
      const double m = LaneLaw<kModel>(in, warp, weft, bias, l,
                                       [kappa](const LawCoefficients& c) __attribute__((always_inline)) {
                                         return c.Moment(kappa);
                                       });
      d_energy = w * m * ih;
      if constexpr (kHessian) {
        const double b = LaneLaw<kModel>(
            in, warp, weft, bias, l,
            [kappa](const LawCoefficients& c) __attribute__((always_inline)) {
              return c.Stiffness(kappa);
            });
        d2_energy = w * b * ih * ih;
      }
      if constexpr (kEnergy) {
        const double psi = LaneLaw<kModel>(
            in, warp, weft, bias, l,
            [kappa](const LawCoefficients& c) __attribute__((always_inline)) {
              return c.Energy(kappa);
            });
        energy = w * psi;
      }
    } else {
      // Bridson: half angles from (cos θ, sin θ) without cancellation on either side of 90°.
      const double inv_rn = 1.0 / std::sqrt(cos_term * cos_term + sin_term * sin_term);
      const double c = cos_term * inv_rn, s = sin_term * inv_rn;
      const double q = std::sqrt(0.5 * (1.0 + std::abs(c)));  // cos θ/2 if c ≥ 0, else |sin θ/2|
      const double r = 0.5 * s / q;
      const double sh = c >= 0.0 ? r : std::copysign(q, s);
      const double ch = c >= 0.0 ? q : std::abs(r);
      const double sb = in.sin_half[l], cb = in.cos_half[l], w = in.weight[l];
      d_energy = w * (sh - sb);
      if constexpr (kHessian) d2_energy = w * 0.5 * ch;
      if constexpr (kEnergy) {
        double e = 2.0 * (sh - sb) * (sh + sb) / (cb + ch);  // 2(cos θ̄/2 - cos θ/2)
        // The angle only matters for a bent rest state (sb = 0 otherwise).
        e -= (Atan2(sin_term, cos_term) - in.rest_angle[l]) * sb;
        energy = w * e;
      }
    }
    if constexpr (kEnergy) out->energy[l] = energy;
    if constexpr (kHessian) {
      out->d_energy[l] = d_energy;
      out->d2_energy[l] = d2_energy;
    }
    if constexpr (kGradient || kHessian) {
      // ∂θ/∂x0 = |e| n0/|n0|², ∂θ/∂x1 = |e| n1/|n1|², the edge takes the reactions at the feet.
      const double n0sq = n0x * n0x + n0y * n0y + n0z * n0z;
      const double n1sq = n1x * n1x + n1y * n1y + n1z * n1z;
      const double inv = 1.0 / (n0sq * n1sq), inv_l2 = 1.0 / l2;
      const double scale = kHessian ? 1.0 : d_energy;
      const double c0 = scale * len * n1sq * inv, c1 = scale * len * n0sq * inv;
      const double t0 = (a0x * ex + a0y * ey + a0z * ez) * inv_l2;
      const double t1 = (a1x * ex + a1y * ey + a1z * ez) * inv_l2;
      // (Named scalars, not small arrays: GCC's loop vectoriser takes no arrays in a lane.)
      const double g0x = c0 * n0x, g0y = c0 * n0y, g0z = c0 * n0z;
      const double g1x = c1 * n1x, g1y = c1 * n1y, g1z = c1 * n1z;
      out->grad[0][l] = g0x;
      out->grad[1][l] = g0y;
      out->grad[2][l] = g0z;
      out->grad[3][l] = g1x;
      out->grad[4][l] = g1y;
      out->grad[5][l] = g1z;
      out->grad[6][l] = (t0 - 1.0) * g0x + (t1 - 1.0) * g1x;
      out->grad[7][l] = (t0 - 1.0) * g0y + (t1 - 1.0) * g1y;
      out->grad[8][l] = (t0 - 1.0) * g0z + (t1 - 1.0) * g1z;
      out->grad[9][l] = -t0 * g0x - t1 * g1x;
      out->grad[10][l] = -t0 * g0y - t1 * g1y;
      out->grad[11][l] = -t0 * g0z - t1 * g1z;
    }
  }
}

// The Hessian's inputs of a block of gathered hinges: d_energy, d2_energy and ∂θ/∂x (energy
// and gradient go through DihedralBlocks).
TEXTILE_SIMD_CLONES void HessianInputLanes(const DihedralLanesIn& in, const LanePositions& pos,
                                           DihedralLanesOut* out) {
  if (!in.pabst) {
    DihedralLanesImpl<LaneModel::kBridson, false, false, true>(in, pos, out);
  } else if (in.bias) {
    DihedralLanesImpl<LaneModel::kPabstWarpWeftBias, false, false, true>(in, pos, out);
  } else if (in.anisotropic) {
    DihedralLanesImpl<LaneModel::kPabstWarpWeft, false, false, true>(in, pos, out);
  } else {
    DihedralLanesImpl<LaneModel::kPabst, false, false, true>(in, pos, out);
  }
}

// Packed index of entry (r, c), r ≤ c, of a 12×12 block's upper triangle (row-major).
constexpr int kPackedSize = 78;
constexpr int Packed(int r, int c) { return r * 12 - r * (r - 1) / 2 + (c - r); }

// Packed upper Hessian blocks of a block of hinges, lane-minor: u[k][l] is entry k of hinge l.
struct LaneHessian {
  alignas(64) double u[kPackedSize][kLanes];
};

// A 3-vector of named scalars (no array inside): what GCC's loop vectoriser can take in a lane.
struct V3 {
  double x, y, z;
  template <int I> TEXTILE_ALWAYS_INLINE double at() const {
    if constexpr (I == 0) return x; else if constexpr (I == 1) return y; else return z;
  }
};
TEXTILE_ALWAYS_INLINE V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
TEXTILE_ALWAYS_INLINE V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
TEXTILE_ALWAYS_INLINE V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
TEXTILE_ALWAYS_INLINE V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
TEXTILE_ALWAYS_INLINE V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
TEXTILE_ALWAYS_INLINE double Dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
TEXTILE_ALWAYS_INLINE V3 Cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Entry (A, B) of the cross-product matrix [s]×.
template <int A, int B> TEXTILE_ALWAYS_INLINE double SkewAt(V3 s) {
  if constexpr (A == B) return 0.0;
  else if constexpr (A == 0 && B == 1) return -s.z;
  else if constexpr (A == 0 && B == 2) return s.y;
  else if constexpr (A == 1 && B == 0) return s.z;
  else if constexpr (A == 1 && B == 2) return -s.x;
  else if constexpr (A == 2 && B == 0) return -s.y;
  else return s.x;
}
// f(integral_constant<0>) ... f(integral_constant<N - 1>): loops with compile-time indices, so that
// no small array is left in a lane (GCC's loop vectoriser takes none).
template <int N, class F>
TEXTILE_ALWAYS_INLINE void Unroll(F&& f) {
  [&]<int... I>(std::integer_sequence<int, I...>) __attribute__((always_inline)) { (f(std::integral_constant<int, I>{}), ...); }(std::make_integer_sequence<int, N>{});
}

// Energy and/or gradient of the dihedral hinges begin ≤ h < end, whole: the kernel on blocks of
// kLanes hinges, reading the positions through the corners' offsets (vector gathers, or the
// compiler's emulation of them), then the gradient scattered in hinge order (the same additions
// in the same order as a hinge-by-hinge loop). One function, so that all of it gets the SIMD
// clone's instructions.
struct DihedralBlocksIn {
  DihedralLanesIn rest;  // the rest arrays at hinge 0
  const int* corner[4];  // 3 v[i] of every hinge, padded by kLanes (first hinge's ids)
  const double* x;       // #V×3 positions, row-major
};

template <LaneModel kModel, bool kEnergy, bool kGradient>
TEXTILE_ALWAYS_INLINE double DihedralBlocksImpl(const DihedralBlocksIn& in, long begin, long end,
                                                double* grad, double* hinge_grad) {
  DihedralLanesOut out;
  double energy = 0.0;
  for (long b = begin; b < end; b += kLanes) {
    const int n = static_cast<int>(std::min<long>(kLanes, end - b));
    const GatherPositions pos{in.x,
                              {in.corner[0] + b, in.corner[1] + b, in.corner[2] + b,
                               in.corner[3] + b}};
    const DihedralLanesIn& r = in.rest;
    const DihedralLanesIn lanes{r.pabst,           r.anisotropic,     r.bias,
                                r.warp,            r.weft,            r.bias_law,
                                r.rest_angle + b,  r.inv_height + b,  r.weight + b,
                                r.warp_weight + b, r.bias_weight + b, r.sin_half + b,
                                r.cos_half + b};
    DihedralLanesImpl<kModel, kEnergy, kGradient, false>(lanes, pos, &out);
    if constexpr (kEnergy)
      for (int l = 0; l < n; ++l) energy += out.energy[l];
    if constexpr (kGradient) {
      const auto scatter = [&](int l) __attribute__((always_inline)) {
        Unroll<4>([&](auto ic) __attribute__((always_inline)) {
          constexpr int I = decltype(ic)::value;
          double* g = grad ? grad + in.corner[I][b + l] : hinge_grad + 12 * (b + l) + 3 * I;
          const double gx = out.grad[3 * I][l], gy = out.grad[3 * I + 1][l],
                       gz = out.grad[3 * I + 2][l];
          if (grad) {
            g[0] += gx;
            g[1] += gy;
            g[2] += gz;
          } else {
            g[0] = gx;
            g[1] = gy;
            g[2] = gz;
          }
        });
      };
      if (n == kLanes) {
        Unroll<kLanes>([&](auto lc) __attribute__((always_inline)) { scatter(lc.value); });
      } else {
        for (int l = 0; l < n; ++l) scatter(l);
      }
    }
  }
  return energy;
}

template <LaneModel kModel>
TEXTILE_ALWAYS_INLINE double DihedralBlocksModel(const DihedralBlocksIn& in, long begin, long end,
                                                 bool energy, double* grad, double* hinge_grad) {
  const bool gradient = grad || hinge_grad;
  if (energy && gradient) {
    return DihedralBlocksImpl<kModel, true, true>(in, begin, end, grad, hinge_grad);
  }
  if (gradient) return DihedralBlocksImpl<kModel, false, true>(in, begin, end, grad, hinge_grad);
  return DihedralBlocksImpl<kModel, true, false>(in, begin, end, grad, hinge_grad);
}

// Energy (returned when asked) and gradient of hinges [begin, end): added into grad (#V×3) when
// given, else each hinge's 12-vector written to hinge_grad + 12 h when given, else none.
TEXTILE_SIMD_CLONES double DihedralBlocks(const DihedralBlocksIn& in, long begin, long end,
                                          bool energy, double* grad, double* hinge_grad) {
  if (!in.rest.pabst) {
    return DihedralBlocksModel<LaneModel::kBridson>(in, begin, end, energy, grad, hinge_grad);
  }
  if (in.rest.bias) {
    return DihedralBlocksModel<LaneModel::kPabstWarpWeftBias>(in, begin, end, energy, grad,
                                                              hinge_grad);
  }
  if (in.rest.anisotropic) {
    return DihedralBlocksModel<LaneModel::kPabstWarpWeft>(in, begin, end, energy, grad,
                                                          hinge_grad);
  }
  return DihedralBlocksModel<LaneModel::kPabst>(in, begin, end, energy, grad, hinge_grad);
}

// One triangle's part of ∇²θ in one lane (the formula of hinge_angle::AddTriangleAngleHessian,
// with compile-time indices): vertex blocks (p, q), p ≤ q in hinge order, entries a ≤ b on the
// diagonal. kAdd: the edge blocks add to the other triangle's (written first).
template <int kWing, bool kAdd>
TEXTILE_ALWAYS_INLINE void TriangleLane(V3 w, V3 x2, V3 x3, V3 n, V3 eps0, V3 eps1, V3 eps2, int l, LaneHessian* out) {
  const V3 e = x3 - x2, aw = w - x2, bw = x3 - w;
  const double l2 = Dot(e, e), len = std::sqrt(l2), nsq = Dot(n, n);
  const double inv = 1.0 / (len * nsq), inv_l2 = 1.0 / l2, two_inv_nsq = 2.0 / nsq;
  const double phi0 = l2 * inv, phi1 = -Dot(bw, e) * inv, phi2 = -Dot(aw, e) * inv;
  const V3 gl0 = Cross(n, eps0) * two_inv_nsq;
  const V3 gl1 = Cross(n, eps1) * two_inv_nsq - e * inv_l2;
  const V3 gl2 = Cross(n, eps2) * two_inv_nsq + e * inv_l2;
  auto block = [&](auto pc, auto qc) __attribute__((always_inline)) {
    constexpr int P = decltype(pc)::value, Q = decltype(qc)::value;
    if constexpr (Q >= P) {
      const double phi = P == 0 ? phi0 : P == 1 ? phi1 : phi2;
      const V3 eps = Q == 0 ? eps0 : Q == 1 ? eps1 : eps2;
      const V3 gl = Q == 0 ? gl0 : Q == 1 ? gl1 : gl2;
      V3 gf;  // ∇_q f_p
      if constexpr (P == 0) gf = Q == 1 ? -2.0 * e : 2.0 * e;  // Q == 0 excluded below
      else if constexpr (P == 1) gf = Q == 1 ? bw : -e - bw;
      else gf = -aw;
      V3 d_phi;
      if constexpr (P == 0 && Q == 0) d_phi = -(phi * gl);
      else d_phi = gf * inv - phi * gl;
      constexpr int rp = 3 * (P == 0 ? kWing : P + 1), rq = 3 * (Q == 0 ? kWing : Q + 1);
      Unroll<3>([&](auto ac) __attribute__((always_inline)) {
        constexpr int A = decltype(ac)::value;
        Unroll<3>([&](auto bc) __attribute__((always_inline)) {
          constexpr int B = decltype(bc)::value;
          if constexpr (P != Q || B >= A) {
            const double v = n.at<A>() * d_phi.at<B>() + phi * SkewAt<A, B>(eps);
            double& dst = out->u[Packed(rp + A, rq + B)][l];
            if constexpr (kAdd && P >= 1) dst += v; else dst = v;
          }
        });
      });
    }
  };
  Unroll<3>([&](auto pc) __attribute__((always_inline)) { Unroll<3>([&](auto qc) __attribute__((always_inline)) { block(pc, qc); }); });
}

// u = E' u + E'' ∇θ ∇θᵀ (upper), the wing-wing block (0, 1) having no angle-Hessian part.
template <bool kAngle>
TEXTILE_ALWAYS_INLINE void ScaleAndAddOuter(const DihedralLanesOut& in, int l, LaneHessian* out) {
  [[maybe_unused]] const double de = in.d_energy[l];
  // A ternary, not std::max: that takes the lane value's address, and the loop would not vectorise.
  const double d2_raw = in.d2_energy[l];
  const double d2 = kAngle || d2_raw > 0.0 ? d2_raw : 0.0;
  Unroll<12>([&](auto ac) __attribute__((always_inline)) {
    constexpr int A = decltype(ac)::value;
    Unroll<12>([&](auto bc) __attribute__((always_inline)) {
      constexpr int B = decltype(bc)::value;
      if constexpr (B >= A) {
        double& dst = out->u[Packed(A, B)][l];
        if constexpr (!kAngle || (A < 3 && B >= 3 && B < 6)) {
          dst = d2 * in.grad[A][l] * in.grad[B][l];
        } else {
          dst = dst * de + d2 * in.grad[A][l] * in.grad[B][l];
        }
      }
    });
  });
}

// u = E' ∇²θ + E'' ∇θ ∇θᵀ per lane (kAngle) or max(E'', 0) ∇θ ∇θᵀ (Gauss-Newton), from the
// dihedral kernel's Hessian outputs. Plain loop (restrict, no omp simd: the aggregates V3 would
// become per-lane arrays under OpenMP lowering); -O2 vectorises it.
template <bool kAngle>
TEXTILE_ALWAYS_INLINE void HessianLanesImpl(const LanePositions& __restrict pos,
                                            const DihedralLanesOut& __restrict in,
                                            LaneHessian* __restrict out) {
  for (int l = 0; l < kLanes; ++l) {
    const V3 x0{pos.p[0][l], pos.p[1][l], pos.p[2][l]}, x1{pos.p[3][l], pos.p[4][l], pos.p[5][l]};
    const V3 x2{pos.p[6][l], pos.p[7][l], pos.p[8][l]}, x3{pos.p[9][l], pos.p[10][l], pos.p[11][l]};
    const V3 e = x3 - x2;
    if constexpr (kAngle) {
      TriangleLane<0, false>(x0, x2, x3, Cross(e, x0 - x2), e, x0 - x3, x2 - x0, l, out);
      TriangleLane<1, true>(x1, x2, x3, Cross(x1 - x2, e), -e, x3 - x1, x1 - x2, l, out);
    }
    ScaleAndAddOuter<kAngle>(in, l, out);
  }
}

TEXTILE_SIMD_CLONES void HessianLanes(const LanePositions& pos, const DihedralLanesOut& in,
                                      bool angle_term, LaneHessian* out) {
  if (angle_term) {
    HessianLanesImpl<true>(pos, in, out);
  } else {
    HessianLanesImpl<false>(pos, in, out);
  }
}

// Local entry k = 12 r + c of a hinge's 12×12 block -> its packed upper-triangle entry.
constexpr std::array<int, 144> MakeFullToPacked() {
  std::array<int, 144> m{};
  for (int r = 0; r < 12; ++r)
    for (int c = 0; c < 12; ++c) m[12 * r + c] = r <= c ? Packed(r, c) : Packed(c, r);
  return m;
}
constexpr std::array<int, 144> kFullToPacked = MakeFullToPacked();

// The vertex pairs (i, j), i ≤ j, of a hinge, in the order of BendingHessianSlots::block_slot.
constexpr int kHingePairs = 10;
constexpr std::array<std::array<int, 2>, kHingePairs> kHingePair = {
    {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 1}, {1, 2}, {1, 3}, {2, 2}, {2, 3}, {3, 3}}};

// Vertex block (i, j) of a hinge's 12×12 block, 4 i + j, as packed upper-triangle entries:
// [4 i + j][3 a + b] holds entry (3 i + a, 3 j + b) (the block is symmetric).
constexpr std::array<std::array<int, 9>, 16> MakeBlockToPacked() {
  std::array<std::array<int, 9>, 16> m{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          m[4 * i + j][3 * a + b] = kFullToPacked[12 * (3 * i + a) + 3 * j + b];
  return m;
}
constexpr std::array<std::array<int, 9>, 16> kBlockToPacked = MakeBlockToPacked();

// Eight doubles as one value (GCC's vector extension): one AVX-512 register, two AVX2 ones, or
// four SSE2 ones, depending on the clone.
using Double8 = double __attribute__((vector_size(64)));
using Long8 = long __attribute__((vector_size(64)));

// Entries 3 a + b -> 3 b + a of a 3×3 block's first 8 entries (the 9th, (2, 2), is its own
// transpose). GCC and Clang name the shuffle differently (the fuzz build uses Clang).
TEXTILE_ALWAYS_INLINE void Transpose3x3(Double8* t) {  // by pointer: no vector ABI involved
#if defined(__clang__)
  *t = __builtin_shufflevector(*t, *t, 0, 3, 6, 1, 4, 7, 2, 5);
#else
  *t = __builtin_shuffle(*t, Long8{0, 3, 6, 1, 4, 7, 2, 5});
#endif
}

// Adds the first `count` hinges of a lane block to the 3×3 blocks (block_slot: theirs, 10 a
// hinge), in hinge order: entries 0-7 (3 a + b) of block k at head + 8 k (64-byte aligned: one
// cache line), entry 8 at ninth + k. Per vertex pair the block's first 8 entries are picked
// from the lanes into one vector (transposed by a shuffle when the pair's vertices are in the
// other order) and added with one read-modify-write, the 9th alone: 20 stores a hinge instead
// of 78 scalar read-modify-writes at scattered positions (docs/methods/bending.md, "Where the time
// goes").
TEXTILE_SIMD_CLONES void AddLaneBlocks(const LaneHessian& u, int count, const int* block_slot,
                                       double* head, double* ninth) {
  for (int l = 0; l < count; ++l) {
    const int* slot = block_slot + kHingePairs * l;
    const double* lane = &u.u[0][l];
    Unroll<kHingePairs>([&](auto kc) __attribute__((always_inline)) {
      constexpr int K = decltype(kc)::value;
      constexpr std::array<int, 9> kEntry = kBlockToPacked[4 * kHingePair[K][0] + kHingePair[K][1]];
      const long block = slot[K] >> 1;
      double* dst = static_cast<double*>(__builtin_assume_aligned(head + 8 * block, 64));
      Double8 t = {lane[kLanes * kEntry[0]], lane[kLanes * kEntry[1]], lane[kLanes * kEntry[2]],
                   lane[kLanes * kEntry[3]], lane[kLanes * kEntry[4]], lane[kLanes * kEntry[5]],
                   lane[kLanes * kEntry[6]], lane[kLanes * kEntry[7]]};
      if constexpr (kHingePair[K][0] != kHingePair[K][1]) {
        // Entry 3 a + b -> 3 b + a; the 9th, (2, 2), stays.
        if (slot[K] & 1) Transpose3x3(&t);
      }
      Double8 d;
      std::memcpy(&d, dst, sizeof d);
      d += t;
      std::memcpy(dst, &d, sizeof d);
      ninth[block] += lane[kLanes * kEntry[8]];
    });
  }
}

// values[position[k]] (+)= block_values[source[k]], k < n; position null: the identity.
TEXTILE_SIMD_CLONES void BlockEntriesToValues(const double* __restrict block_values,
                                              const int* source, const int* position, long n,
                                              bool assign, double* __restrict values) {
  if (position) {
    for (long k = 0; k < n; ++k) values[position[k]] += block_values[source[k]];
  } else if (assign) {
#pragma omp simd
    for (long k = 0; k < n; ++k) values[k] = block_values[source[k]];
  } else {
#pragma omp simd
    for (long k = 0; k < n; ++k) values[k] += block_values[source[k]];
  }
}

// Runs f(begin, end) over [0, n) in `threads` contiguous chunks, the first on this thread.
template <class F>
void ParallelChunks(int n, int threads, F&& f) {
  if (threads <= 1 || n < 2 * threads) {
    f(0, n, 0);
    return;
  }
  std::vector<std::jthread> workers;
  workers.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) {
    workers.emplace_back([&f, n, threads, t] {
      f(static_cast<long>(n) * t / threads, static_cast<long>(n) * (t + 1) / threads, t);
    });
  }
  f(0, n / threads, 0);
}

std::string HingeName(int h, const Hinge& hinge) {
  std::ostringstream s;
  s << "bending: hinge " << h << " (vertices " << hinge.v[0] << ", " << hinge.v[1] << "; edge "
    << hinge.v[2] << "-" << hinge.v[3] << ")";
  return s.str();
}

}  // namespace

double HingeBendAngle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  const Vec3 e = x3 - x2, a0 = x0 - x2, a1 = x1 - x2;
  const Vec3 n0 = e.cross(a0), n1 = a1.cross(e);
  return Atan2(e.norm() * n1.dot(a0), n0.dot(n1));
}

std::string BendingModelName(BendingModel model) {
  switch (model) {
    case BendingModel::kPabst:
      return "pabst";
    case BendingModel::kBridson:
      return "bridson";
    case BendingModel::kVolino:
      return "volino";
    case BendingModel::kIsometric:
      return "isometric";
  }
  return "unknown";
}

BendingModel ParseBendingModel(const std::string& name) {
  for (BendingModel m : {BendingModel::kPabst, BendingModel::kBridson, BendingModel::kVolino,
                         BendingModel::kIsometric}) {
    if (BendingModelName(m) == name) return m;
  }
  throw InputError("bending model '" + name +
                   "' is unknown (known: pabst, bridson, volino, isometric)");
}

bool BendingOptions::Check(std::string* why) const {
  std::string reason;
  if (model != BendingModel::kPabst && model != BendingModel::kBridson &&
      model != BendingModel::kVolino && model != BendingModel::kIsometric) {
    reason = "bending options: model is not one of pabst, bridson, volino, isometric";
  } else if (threads < 0) {
    reason = "bending options: threads must be >= 0 (0 = all hardware threads), got " +
             std::to_string(threads);
  }
  if (why) *why = reason;
  return reason.empty();
}

BendingElements::BendingElements(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                                 const Material& material, const BendingOptions& options,
                                 const std::vector<double>& stiffness_multiplier)
    : BendingElements(rest, hinges,
                      DirectionLaws{material.EffectiveLaw(),
                                    material.bending_weft
                                        ? std::optional<BendingLaw>(material.EffectiveWeftLaw())
                                        : std::nullopt,
                                    material.EffectiveBiasLaw()},
                      options, stiffness_multiplier) {}

BendingElements::BendingElements(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                                 const BendingLaw& warp, const std::optional<BendingLaw>& weft,
                                 const BendingOptions& options,
                                 const std::vector<double>& stiffness_multiplier)
    : BendingElements(rest, hinges, DirectionLaws{warp, weft, std::nullopt}, options,
                      stiffness_multiplier) {}

BendingElements::BendingElements(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                                 const DirectionLaws& laws, const BendingOptions& options,
                                 const std::vector<double>& stiffness_multiplier)
    : options_(options),
      warp_(laws.warp),
      weft_(laws.weft ? *laws.weft : laws.warp),
      bias_(laws.bias ? *laws.bias : laws.warp),
      anisotropic_(laws.weft.has_value() || laws.bias.has_value()),
      has_bias_(laws.bias.has_value()),
      num_vertices_(rest.num_vertices()),
      hinges_(hinges) {
  if (std::string why; !options.Check(&why)) throw InputError(why);
  hinge_by_hinge_ = options_.model == BendingModel::kPabst &&
                    (warp_.is_spline() || weft_.is_spline() || bias_.is_spline());
  const int nh = static_cast<int>(hinges.size());
  if (!stiffness_multiplier.empty() && static_cast<int>(stiffness_multiplier.size()) != nh) {
    throw InputError("bending: stiffness multiplier has " +
                     std::to_string(stiffness_multiplier.size()) + " values for " +
                     std::to_string(nh) + " hinges");
  }
  rest_.resize(nh);
  edge_length_.resize(nh);
  multiplier_.assign(nh, 1.0);
  if (options_.model == BendingModel::kBridson) half_angle_.resize(2 * nh);
  const bool linear =
      options_.model == BendingModel::kVolino || options_.model == BendingModel::kIsometric;
  if (linear) linear_.resize(nh);

  for (int h = 0; h < nh; ++h) {
    const Hinge& hinge = hinges[h];
    for (int i = 0; i < 4; ++i) {
      if (hinge.v[i] < 0 || hinge.v[i] >= num_vertices_) {
        throw InputError(HingeName(h, hinge) + ": vertex id " + std::to_string(hinge.v[i]) +
                         " is outside 0.." + std::to_string(num_vertices_ - 1));
      }
      if (!rest.vertices.row(hinge.v[i]).allFinite()) {
        throw InputError(HingeName(h, hinge) + ": rest vertex " + std::to_string(hinge.v[i]) +
                         " has a NaN or infinite coordinate");
      }
    }
    if (!stiffness_multiplier.empty()) {
      const double s = stiffness_multiplier[h];
      if (!std::isfinite(s) || !(s > 0.0)) {
        std::ostringstream m;
        m << HingeName(h, hinge) << ": stiffness multiplier must be a finite number > 0, got " << s;
        throw InputError(m.str());
      }
      multiplier_[h] = s;
    }
    const Vec3 x0 = rest.vertices.row(hinge.v[0]), x1 = rest.vertices.row(hinge.v[1]);
    const Vec3 x2 = rest.vertices.row(hinge.v[2]), x3 = rest.vertices.row(hinge.v[3]);
    const Vec3 e = x3 - x2;
    const double l = e.norm();
    const double h0 = e.cross(x0 - x2).norm() / l, h1 = (x1 - x2).cross(e).norm() / l;
    // Heights far below the edge length make 1/h̄ and the Bridson/IBM weights blow up.
    if (!(l > 0.0) || !(h0 > 1e-8 * l) || !(h1 > 1e-8 * l)) {
      std::ostringstream m;
      m << HingeName(h, hinge) << ": degenerate rest triangle (edge " << l << " m, heights " << h0
        << " m, " << h1 << " m)";
      throw InputError(m.str());
    }
    const double height = 0.5 * (h0 + h1);
    HingeRest& r = rest_[h];
    r.v = hinge.v;
    r.rest_angle = HingeBendAngle(x0, x1, x2, x3);
    r.inv_height = 1.0 / height;
    // cos²φ, φ the bending direction's angle to the warp (x): the curvature runs across the
    // edge, so an edge along the weft (y) bends a warp strip, with the warp law.
    // In the pattern plane: a curved rest edge's z does not count towards either yarn.
    const double in_plane = e.x() * e.x() + e.y() * e.y();
    // An edge with no extent in the plane (a curved rest state) takes the mean of warp and weft.
    const LawWeights lw = !anisotropic_      ? LawWeights{}
                          : in_plane > 0.0 ? DirectionWeights(e.y() * e.y() / in_plane, has_bias_)
                                           : LawWeights{0.5, 0.5, 0.0};
    r.warp_weight = lw.warp;
    r.bias_weight = lw.bias;
    edge_length_[h] = l;
    const double area_weight = l * height;  // A_h = |ē| h̄e = Ā0 + Ā1
    const double b1 = lw.warp * warp_.b1() + lw.weft * weft_.b1() + lw.bias * bias_.b1();
    const double s = multiplier_[h];
    switch (options_.model) {
      case BendingModel::kPabst:
        r.weight = s * area_weight;
        break;
      case BendingModel::kBridson:
        // E = k_h [2(cos θ̄/2 - cos θ/2) - (θ - θ̄) sin θ̄/2] ≈ k_h θ²/4 (flat) = A_h b1 κ²/2.
        r.weight = s * 2.0 * area_weight * b1 / (height * height);
        half_angle_[2 * h] = std::sin(0.5 * r.rest_angle);
        half_angle_[2 * h + 1] = std::cos(0.5 * r.rest_angle);
        break;
      case BendingModel::kVolino: {
        // R = (h1 x0 + h0 x1)/(h0 + h1) - ((1 - s) x2 + s x3): the wing line's crossing with the
        // edge line minus its edge point; |R| ≈ ρ θ with ρ = h0 h1/(h0 + h1).
        const double t0 = (x0 - x2).dot(e) / (l * l), t1 = (x1 - x2).dot(e) / (l * l);
        const double sum = h0 + h1, cross_at = (h1 * t0 + h0 * t1) / sum, rho = h0 * h1 / sum;
        linear_[h].alpha = {h1 / sum, h0 / sum, cross_at - 1.0, -cross_at};
        r.weight = s * area_weight * b1 / (height * height * rho * rho);
        break;
      }
      case BendingModel::kIsometric: {
        // Cotangent weights (Bergou et al. 2006): w·x ≈ |e| θ; Q_e = 3 k/(Ā0 + Ā1) w wᵀ, k = b1/3.
        const auto cot = [](const Vec3& a, const Vec3& b) { return a.dot(b) / a.cross(b).norm(); };
        const double c02 = cot(x3 - x2, x0 - x2), c03 = cot(x2 - x3, x0 - x3);  // triangle 0
        const double c12 = cot(x3 - x2, x1 - x2), c13 = cot(x2 - x3, x1 - x3);  // triangle 1
        linear_[h].alpha = {c02 + c03, c12 + c13, -c03 - c13, -c02 - c12};
        r.weight = s * 3.0 * (b1 / 3.0) / area_weight;
        break;
      }
    }
    if (linear) {
      const auto& al = linear_[h].alpha;
      linear_[h].rest_vector = al[0] * x0 + al[1] * x1 + al[2] * x2 + al[3] * x3;
    }
  }

  if (!linear) {
    // Padded by one SIMD block with a harmless hinge (weight 0), so that blocks never read past.
    const size_t padded = static_cast<size_t>(nh) + kLanes;
    DihedralRest& d = dihedral_;
    d.rest_angle.assign(padded, 0.0);
    d.inv_height.assign(padded, 1.0);
    d.weight.assign(padded, 0.0);
    d.warp_weight.assign(padded, 1.0);
    d.bias_weight.assign(padded, 0.0);
    d.sin_half.assign(padded, 0.0);
    d.cos_half.assign(padded, 1.0);
    for (int i = 0; i < 4; ++i) d.corner[i].assign(padded, nh > 0 ? 3 * rest_[0].v[i] : 0);
    for (int h = 0; h < nh; ++h) {
      d.rest_angle[h] = rest_[h].rest_angle;
      d.inv_height[h] = rest_[h].inv_height;
      d.weight[h] = rest_[h].weight;
      d.warp_weight[h] = rest_[h].warp_weight;
      d.bias_weight[h] = rest_[h].bias_weight;
      for (int i = 0; i < 4; ++i) d.corner[i][h] = 3 * rest_[h].v[i];
      if (options_.model == BendingModel::kBridson) {
        d.sin_half[h] = half_angle_[2 * h];
        d.cos_half[h] = half_angle_[2 * h + 1];
      }
    }
  }

  // Vertex -> (hinge, slot) lists for the threaded gather, in hinge order (deterministic).
  vertex_offsets_.assign(num_vertices_ + 1, 0);
  for (const HingeRest& r : rest_)
    for (int i = 0; i < 4; ++i) ++vertex_offsets_[r.v[i] + 1];
  for (int i = 0; i < num_vertices_; ++i) vertex_offsets_[i + 1] += vertex_offsets_[i];
  vertex_slots_.resize(vertex_offsets_.back());
  std::vector<int> fill(vertex_offsets_.begin(), vertex_offsets_.end() - 1);
  for (int h = 0; h < nh; ++h)
    for (int i = 0; i < 4; ++i) vertex_slots_[fill[rest_[h].v[i]]++] = 4 * h + i;
}

int BendingElements::NumThreads() const {
  const int n = options_.threads > 0 ? options_.threads
                                     : static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(n, 1, kMaxThreads);
}

// The hinge's law value f(law): the warp law's, or the blend of the direction laws (the same
// arithmetic as LaneLaw).
template <class F>
double BendingElements::HingeLaw(const HingeRest& r, F&& f) const {
  const double a = f(warp_);
  if (!anisotropic_) return a;
  const double ww = r.warp_weight, wb = r.bias_weight;
  if (!has_bias_) return ww * a + (1.0 - ww) * f(weft_);
  return ww * a + wb * f(bias_) + (1.0 - ww - wb) * f(weft_);
}
double BendingElements::LawEnergy(const HingeRest& r, double kappa) const {
  return HingeLaw(r, [kappa](const BendingLaw& law) { return law.Energy(kappa); });
}
double BendingElements::LawMoment(const HingeRest& r, double kappa) const {
  return HingeLaw(r, [kappa](const BendingLaw& law) { return law.Moment(kappa); });
}
double BendingElements::LawStiffness(const HingeRest& r, double kappa) const {
  return HingeLaw(r, [kappa](const BendingLaw& law) { return law.Stiffness(kappa); });
}

// Energy of hinge h and, for the dihedral models, dE/dθ and d²E/dθ² (null pointers skip them).
double BendingElements::HingeTerms(const Vertices& x, int h, double* d_energy,
                                   double* d2_energy) const {
  const HingeRest& r = rest_[h];
  if (options_.model == BendingModel::kVolino || options_.model == BendingModel::kIsometric) {
    const auto& al = linear_[h].alpha;
    const Vec3 rv = al[0] * Position(x, r.v[0]) + al[1] * Position(x, r.v[1]) +
                    al[2] * Position(x, r.v[2]) + al[3] * Position(x, r.v[3]) -
                    linear_[h].rest_vector;
    return 0.5 * r.weight * rv.squaredNorm();
  }
  const hinge_angle::AngleTerms t = hinge_angle::AngleTermsAndGradient(x, r.v, nullptr);
  return DihedralTerms(t.cos_term, t.sin_term, h, d_energy, d2_energy, true);
}

// E(θ), E'(θ), E''(θ) of a dihedral model from |n0||n1| (cos θ, sin θ); with want_energy
// false the returned energy is 0 (the gradient path skips Ψ).
double BendingElements::DihedralTerms(double cos_term, double sin_term, int h, double* d_energy,
                                      double* d2_energy, bool want_energy) const {
  const HingeRest& r = rest_[h];
  if (options_.model == BendingModel::kPabst) {
    const double kappa = (Atan2(sin_term, cos_term) - r.rest_angle) * r.inv_height;
    if (d_energy) *d_energy = r.weight * LawMoment(r, kappa) * r.inv_height;
    if (d2_energy) *d2_energy = r.weight * LawStiffness(r, kappa) * r.inv_height * r.inv_height;
    return want_energy ? r.weight * LawEnergy(r, kappa) : 0.0;
  }
  // Bridson: half angles from (cos θ, sin θ) without cancellation on either side of 90°;
  // no atan2 unless the rest state is bent.
  const double inv_rn = 1.0 / std::sqrt(cos_term * cos_term + sin_term * sin_term);
  const double c = cos_term * inv_rn, s = sin_term * inv_rn;
  double sh, ch;
  if (c >= 0.0) {
    ch = std::sqrt(0.5 * (1.0 + c));
    sh = 0.5 * s / ch;
  } else {
    sh = std::copysign(std::sqrt(0.5 * (1.0 - c)), s);
    ch = 0.5 * s / sh;
  }
  const double sb = half_angle_[2 * h], cb = half_angle_[2 * h + 1];
  if (d_energy) *d_energy = r.weight * (sh - sb);
  if (d2_energy) *d2_energy = r.weight * 0.5 * ch;
  if (!want_energy) return 0.0;
  double energy = 2.0 * (sh - sb) * (sh + sb) / (cb + ch);  // 2(cos θ̄/2 - cos θ/2)
  if (sb != 0.0) energy -= (Atan2(sin_term, cos_term) - r.rest_angle) * sb;
  return r.weight * energy;
}

double BendingElements::BendAngle(const Vertices& x, int h) const {
  const hinge_angle::AngleTerms t = hinge_angle::AngleTermsAndGradient(x, rest_[h].v, nullptr);
  return Atan2(t.sin_term, t.cos_term);
}

double BendingElements::HingeCurvature(const Vertices& x, int h) const {
  return (BendAngle(x, h) - rest_[h].rest_angle) * rest_[h].inv_height;
}

double BendingElements::HingeEnergy(const Vertices& x, int h) const {
  return HingeTerms(x, h, nullptr, nullptr);
}

// The hot loop. grad == nullptr: energy only. Otherwise per-hinge 12-vectors are either added
// straight into grad (serial) or written to hinge_gradient_ and gathered per vertex (threads).
template <bool kWithEnergy, bool kWithGradient>
double BendingElements::Evaluate(const Vertices& x, double* grad) const {
  assert(x.rows() == num_vertices_);
  const int nh = num_hinges();
  const int threads = NumThreads();
  const bool direct = threads == 1;
  if (kWithGradient && !direct) hinge_gradient_.resize(12 * static_cast<size_t>(nh));
  std::array<double, kMaxThreads> partial{};
  const BendingModel model = options_.model;

  const bool linear = model == BendingModel::kVolino || model == BendingModel::kIsometric;
  const LawCoefficients warp(warp_), weft(weft_), bias(bias_);

  auto linear_run = [&](long begin, long end, int thread) {
    double energy = 0.0;
    for (long h = begin; h < end; ++h) {
      const HingeRest& r = rest_[h];
      const auto& al = linear_[h].alpha;
      const Vec3 rv = al[0] * Position(x, r.v[0]) + al[1] * Position(x, r.v[1]) +
                      al[2] * Position(x, r.v[2]) + al[3] * Position(x, r.v[3]) -
                      linear_[h].rest_vector;
      if constexpr (kWithEnergy) energy += 0.5 * r.weight * rv.squaredNorm();
      if constexpr (!kWithGradient) continue;
      const Vec3 wr = r.weight * rv;
      if (direct) {
        for (int i = 0; i < 4; ++i) Eigen::Map<Vec3>(grad + 3 * r.v[i]) += al[i] * wr;
      } else {
        double* out = hinge_gradient_.data() + 12 * h;
        for (int i = 0; i < 4; ++i) Eigen::Map<Vec3>(out + 3 * i) = al[i] * wr;
      }
    }
    partial[thread] = energy;
  };

  // Dihedral models: blocks of kLanes hinges, gathered into lanes, evaluated by the SIMD kernel,
  // scattered in hinge order (the same additions in the same order as a hinge-by-hinge loop).
  auto dihedral_run = [&](long begin, long end, int thread) {
    const DihedralLanesIn rest{model == BendingModel::kPabst,
                               anisotropic_,
                               has_bias_,
                               &warp,
                               &weft,
                               &bias,
                               dihedral_.rest_angle.data(),
                               dihedral_.inv_height.data(),
                               dihedral_.weight.data(),
                               dihedral_.warp_weight.data(),
                               dihedral_.bias_weight.data(),
                               dihedral_.sin_half.data(),
                               dihedral_.cos_half.data()};
    const DihedralBlocksIn in{rest,
                              {dihedral_.corner[0].data(), dihedral_.corner[1].data(),
                               dihedral_.corner[2].data(), dihedral_.corner[3].data()},
                              x.data()};
    double* hinge_grad = kWithGradient && !direct ? hinge_gradient_.data() : nullptr;
    partial[thread] = DihedralBlocks(in, begin, end, kWithEnergy,
                                     kWithGradient && direct ? grad : nullptr, hinge_grad);
  };
  // A spline law: each hinge's angle and gradient, and the law through BendingLaw.
  auto hinge_run = [&](long begin, long end, int thread) {
    double energy = 0.0;
    std::array<Vec3, 4> g;
    for (long h = begin; h < end; ++h) {
      const HingeRest& r = rest_[h];
      const hinge_angle::AngleTerms t =
          hinge_angle::AngleTermsAndGradient(x, r.v, kWithGradient ? &g : nullptr);
      double d_energy = 0.0;
      energy += DihedralTerms(t.cos_term, t.sin_term, static_cast<int>(h),
                              kWithGradient ? &d_energy : nullptr, nullptr, kWithEnergy);
      if constexpr (!kWithGradient) continue;
      if (direct) {
        for (int i = 0; i < 4; ++i) Eigen::Map<Vec3>(grad + 3 * r.v[i]) += d_energy * g[i];
      } else {
        double* out = hinge_gradient_.data() + 12 * h;
        for (int i = 0; i < 4; ++i) Eigen::Map<Vec3>(out + 3 * i) = d_energy * g[i];
      }
    }
    partial[thread] = energy;
  };
  auto run = [&](long begin, long end, int thread) {
    if (linear) {
      linear_run(begin, end, thread);
    } else if (hinge_by_hinge_) {
      hinge_run(begin, end, thread);
    } else {
      dihedral_run(begin, end, thread);
    }
  };

  if (!kWithGradient || direct) {
    ParallelChunks(nh, threads, run);
  } else {
    // Hinges, then a per-vertex gather: no two threads write the same vertex.
    ParallelChunks(nh, threads, run);
    ParallelChunks(num_vertices_, threads, [&](long begin, long end, int) {
      for (long v = begin; v < end; ++v) {
        Eigen::Map<Vec3> out(grad + 3 * v);
        for (int k = vertex_offsets_[v]; k < vertex_offsets_[v + 1]; ++k) {
          out += Eigen::Map<const Vec3>(hinge_gradient_.data() + 3 * vertex_slots_[k]);
        }
      }
    });
  }
  double total = 0.0;
  for (double p : partial) total += p;
  return total;
}

double BendingElements::Energy(const Vertices& x) const {
  return Evaluate<true, false>(x, nullptr);
}

void BendingElements::AddGradient(const Vertices& x, Eigen::Ref<Vertices> grad) const {
  Evaluate<false, true>(x, grad.data());
}

double BendingElements::EnergyGradient(const Vertices& x, Eigen::Ref<Vertices> grad) const {
  return Evaluate<true, true>(x, grad.data());
}

void BendingElements::AddHessianTriplets(const Vertices& x,
                                         std::vector<Eigen::Triplet<double>>* triplets,
                                         HessianProjection projection) const {
  AddHessianTriplets(x, triplets, projection, 0, num_hinges());
}

void BendingElements::AddHessianTriplets(const Vertices& x,
                                         std::vector<Eigen::Triplet<double>>* triplets,
                                         HessianProjection projection, int first_hinge,
                                         int end_hinge) const {
  assert(x.rows() == num_vertices_);
  assert(0 <= first_hinge && first_hinge <= end_hinge && end_hinge <= num_hinges());
  const int nh = end_hinge - first_hinge;
  const bool linear =
      options_.model == BendingModel::kVolino || options_.model == BendingModel::kIsometric;
  const size_t per_hinge = linear ? 48 : 144;
  const size_t first = triplets->size();
  const int threads = NumThreads();
  // Serial: append (no zero fill of ~16 bytes × 144 per hinge before overwriting it).
  // Threaded: each hinge owns a fixed slice of a resized vector.
  if (threads == 1) {
    triplets->reserve(first + per_hinge * nh);
  } else {
    triplets->resize(first + per_hinge * nh);
  }

  ParallelChunks(nh, threads, [&](long begin, long end, int) {
    Mat12 block;
    for (long k = begin; k < end; ++k) {
      const long h = first_hinge + k;
      const HingeRest& r = rest_[h];
      auto emit = [&, next = threads == 1 ? nullptr : triplets->data() + first + per_hinge * k](
                      int row, int col, double value) mutable {
        if (next) {
          *next++ = {row, col, value};
        } else {
          triplets->emplace_back(row, col, value);
        }
      };
      if (linear) {
        // Constant Hessian: k α_i α_j I₃ for every vertex pair.
        const auto& al = linear_[h].alpha;
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j)
            for (int c = 0; c < 3; ++c)
              emit(3 * r.v[i] + c, 3 * r.v[j] + c, r.weight * al[i] * al[j]);
        continue;
      }
      DihedralHessianBlock(x, static_cast<int>(h), projection, &block);
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
              emit(3 * r.v[i] + a, 3 * r.v[j] + b, block(3 * i + a, 3 * j + b));
    }
  });
}

// ∇²E = E''(θ) ∇θ ∇θᵀ + E'(θ) ∇²θ of dihedral hinge h, projected as asked.
void BendingElements::DihedralHessianBlock(const Vertices& x, int h, HessianProjection projection,
                                           Mat12* block) const {
  const HingeRest& r = rest_[h];
  std::array<Vec3, 4> g;
  const hinge_angle::AngleTerms t = hinge_angle::AngleTermsAndGradient(x, r.v, &g);
  double d_energy, d2_energy;
  DihedralTerms(t.cos_term, t.sin_term, h, &d_energy, &d2_energy, false);
  Eigen::Matrix<double, 12, 1> gv;
  for (int i = 0; i < 4; ++i) gv.segment<3>(3 * i) = g[i];
  if (projection == HessianProjection::kGaussNewton) {
    block->noalias() = std::max(d2_energy, 0.0) * gv * gv.transpose();
    return;
  }
  block->noalias() = d2_energy * gv * gv.transpose();
  hinge_angle::AddAngleHessian(x, r.v, d_energy, block);
  if (projection == HessianProjection::kEigen) {
    const Eigen::SelfAdjointEigenSolver<Mat12> eigen(*block);
    const auto& values = eigen.eigenvalues();
    if (values.minCoeff() < 0.0) {
      block->noalias() = eigen.eigenvectors() * values.cwiseMax(0.0).asDiagonal() *
                         eigen.eigenvectors().transpose();
    }
  }
}

void BendingElements::HingeHessianUpper(const Vertices& x, int h, HessianProjection projection,
                                        double* u) const {
  const HingeRest& r = rest_[h];
  if (options_.model == BendingModel::kVolino || options_.model == BendingModel::kIsometric) {
    // Constant Hessian: k α_i α_j I₃ for every vertex pair.
    std::fill(u, u + kPackedSize, 0.0);
    const auto& al = linear_[h].alpha;
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j)
        for (int c = 0; c < 3; ++c) u[Packed(3 * i + c, 3 * j + c)] = r.weight * al[i] * al[j];
    return;
  }
  Mat12 block;
  DihedralHessianBlock(x, h, projection, &block);
  for (int a = 0; a < 12; ++a)
    for (int b = a; b < 12; ++b) u[Packed(a, b)] = block(a, b);
}

void BendingElements::HessianBlocks(const Vertices& x, HessianProjection projection, long first,
                                    int count, double* u) const {
  static_assert(kSimdLanes == kLanes);
  auto* lanes = reinterpret_cast<LaneHessian*>(u);
  const bool linear =
      options_.model == BendingModel::kVolino || options_.model == BendingModel::kIsometric;
  if (linear || projection == HessianProjection::kEigen || hinge_by_hinge_) {
    double block[kPackedSize];
    for (int l = 0; l < count; ++l) {
      HingeHessianUpper(x, static_cast<int>(first + l), projection, block);
      for (int k = 0; k < kPackedSize; ++k) lanes->u[k][l] = block[k];
    }
    return;
  }
  LanePositions pos;
  const double* xd = x.data();
  for (int l = 0; l < kLanes; ++l) {
    const HingeRest& r = rest_[first + (l < count ? l : 0)];  // spare lanes repeat the first
    for (int i = 0; i < 4; ++i) {
      const double* p = xd + 3 * r.v[i];
      pos.p[3 * i][l] = p[0];
      pos.p[3 * i + 1][l] = p[1];
      pos.p[3 * i + 2][l] = p[2];
    }
  }
  const LawCoefficients warp(warp_), weft(weft_), bias(bias_);
  const DihedralLanesIn in{options_.model == BendingModel::kPabst,
                           anisotropic_,
                           has_bias_,
                           &warp,
                           &weft,
                           &bias,
                           dihedral_.rest_angle.data() + first,
                           dihedral_.inv_height.data() + first,
                           dihedral_.weight.data() + first,
                           dihedral_.warp_weight.data() + first,
                           dihedral_.bias_weight.data() + first,
                           dihedral_.sin_half.data() + first,
                           dihedral_.cos_half.data() + first};
  DihedralLanesOut out;
  HessianInputLanes(in, pos, &out);
  HessianLanes(pos, out, projection == HessianProjection::kNone, lanes);
}

Eigen::SparseMatrix<double> BendingElements::HessianPattern(bool upper) const {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve((upper ? kPackedSize : 144) * static_cast<size_t>(num_hinges()));
  for (const HingeRest& r : rest_) {
    for (int i = 0; i < 4; ++i)
      for (int j = upper ? i : 0; j < 4; ++j)
        for (int a = 0; a < 3; ++a)
          for (int b = (upper && i == j) ? a : 0; b < 3; ++b) {
            int row = 3 * r.v[i] + a, col = 3 * r.v[j] + b;
            if (upper && row > col) std::swap(row, col);
            entries.emplace_back(row, col, 0.0);
          }
  }
  Eigen::SparseMatrix<double> pattern(3 * num_vertices_, 3 * num_vertices_);
  pattern.setFromTriplets(entries.begin(), entries.end());
  pattern.makeCompressed();
  return pattern;
}

BendingHessianSlots BendingElements::HessianSlots(const Eigen::SparseMatrix<double>& pattern,
                                                  bool upper) const {
  const int n = 3 * num_vertices_;
  if (pattern.rows() != n || pattern.cols() != n) {
    throw InputError("bending: Hessian pattern is " + std::to_string(pattern.rows()) + "×" +
                     std::to_string(pattern.cols()) + ", expected " + std::to_string(n) + "×" +
                     std::to_string(n));
  }
  if (!pattern.isCompressed()) throw InputError("bending: Hessian pattern is not compressed");
  BendingHessianSlots slots;
  slots.upper = upper;
  slots.per_hinge = upper ? kPackedSize : 144;
  slots.nonzeros = pattern.nonZeros();
  const int nh = num_hinges();
  slots.slot.resize(static_cast<size_t>(slots.per_hinge) * nh);
  std::vector<int> source(slots.slot.size());  // packed entry of each slot
  const int* outer = pattern.outerIndexPtr();
  const int* inner = pattern.innerIndexPtr();
  size_t next = 0;
  for (int h = 0; h < nh; ++h) {
    const auto& v = rest_[h].v;
    auto add = [&](int r, int c) {  // local entry (r, c) of the 12×12 block
      int row = 3 * v[r / 3] + r % 3, col = 3 * v[c / 3] + c % 3;
      if (upper && row > col) std::swap(row, col);
      const int* begin = inner + outer[col];
      const int* end = inner + outer[col + 1];
      const int* it = std::lower_bound(begin, end, row);
      if (it == end || *it != row) {
        throw InputError(HingeName(h, hinges_[h]) + ": Hessian pattern lacks entry (" +
                         std::to_string(row) + ", " + std::to_string(col) + ")");
      }
      source[next] = kPackedSize * h + (r <= c ? Packed(r, c) : Packed(c, r));
      slots.slot[next++] = static_cast<int>(it - inner);
    };
    if (upper) {
      for (int r = 0; r < 12; ++r)
        for (int c = r; c < 12; ++c) add(r, c);
    } else {
      for (int r = 0; r < 12; ++r)
        for (int c = 0; c < 12; ++c) add(r, c);
    }
  }
  // Per value position, its sources in hinge order (a counting sort keeps the order).
  slots.source_offsets.assign(slots.nonzeros + 1, 0);
  for (int p : slots.slot) ++slots.source_offsets[p + 1];
  for (long p = 0; p < slots.nonzeros; ++p) slots.source_offsets[p + 1] += slots.source_offsets[p];
  slots.sources.resize(slots.slot.size());
  std::vector<int> fill(slots.source_offsets.begin(), slots.source_offsets.end() - 1);
  for (size_t k = 0; k < slots.slot.size(); ++k) slots.sources[fill[slots.slot[k]]++] = source[k];

  // The 3×3 blocks: every vertex pair va ≤ vb of a hinge once, in the matrix's (column) order.
  std::vector<long> pairs;  // nv vb + va
  pairs.reserve(static_cast<size_t>(kHingePairs) * nh);
  const long nv = num_vertices_;
  for (const HingeRest& r : rest_) {
    for (const auto& [i, j] : kHingePair) {
      pairs.push_back(nv * std::max(r.v[i], r.v[j]) + std::min(r.v[i], r.v[j]));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  if (pairs.size() > static_cast<size_t>(std::numeric_limits<int>::max() / 9)) {  // int entries
    throw InputError("bending: too many vertex pairs for the Hessian slots");
  }
  slots.block_slot.resize(static_cast<size_t>(kHingePairs) * nh);
  for (int h = 0; h < nh; ++h) {
    const auto& v = rest_[h].v;
    for (int k = 0; k < kHingePairs; ++k) {
      auto [i, j] = kHingePair[k];
      if (v[i] > v[j]) std::swap(i, j);
      const long key = nv * v[j] + v[i];
      const long block = std::lower_bound(pairs.begin(), pairs.end(), key) - pairs.begin();
      slots.block_slot[static_cast<size_t>(kHingePairs) * h + k] =
          static_cast<int>(2 * block + (i != kHingePair[k][0]));
    }
  }
  const long nb = static_cast<long>(pairs.size());
  slots.block_values.assign(9 * nb + 8, 0.0);  // 8 spare for the alignment (FillHessianValues)
  // Where each block entry goes (found above for every hinge's entries, so none is missing).
  std::vector<std::pair<int, int>> targets;  // (value position, block entry)
  targets.reserve((upper ? 6 : 9) * pairs.size() + (upper ? 0 : 9 * pairs.size()));
  auto position = [&](int row, int col) {
    const int* begin = inner + outer[col];
    const int* end = inner + outer[col + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) - inner);
  };
  for (size_t block = 0; block < pairs.size(); ++block) {
    const int va = static_cast<int>(pairs[block] % nv), vb = static_cast<int>(pairs[block] / nv);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const long e = 3 * a + b;
        const int entry = static_cast<int>(e < 8 ? 8 * block + e : 8 * nb + block);
        if (va != vb || !upper || a <= b) {
          targets.emplace_back(position(3 * va + a, 3 * vb + b), entry);
        }
        if (va != vb && !upper) targets.emplace_back(position(3 * vb + b, 3 * va + a), entry);
      }
  }
  std::sort(targets.begin(), targets.end());
  slots.value_position.resize(targets.size());
  slots.value_source.resize(targets.size());
  for (size_t k = 0; k < targets.size(); ++k) {
    slots.value_position[k] = targets[k].first;
    slots.value_source[k] = targets[k].second;
  }
  slots.covers_all = static_cast<long>(targets.size()) == slots.nonzeros;
  return slots;
}

void BendingElements::AddHessianValues(const Vertices& x, HessianProjection projection,
                                       const BendingHessianSlots& slots, double* values) const {
  FillHessianValues(x, projection, slots, false, values);
}

void BendingElements::FillHessianValues(const Vertices& x, HessianProjection projection,
                                        const BendingHessianSlots& slots, bool overwrite,
                                        double* values) const {
  assert(x.rows() == num_vertices_);
  const int nh = num_hinges();
  if (slots.slot.size() != static_cast<size_t>(slots.per_hinge) * nh ||
      slots.source_offsets.size() != static_cast<size_t>(slots.nonzeros) + 1 ||
      slots.block_slot.size() != static_cast<size_t>(kHingePairs) * nh ||
      slots.value_source.size() != slots.value_position.size() ||
      slots.block_values.size() % 9 != 8) {
    throw InputError("bending: Hessian slots were made for other elements (" +
                     std::to_string(slots.slot.size()) + " slots for " + std::to_string(nh) +
                     " hinges)");
  }
  if (overwrite && !slots.covers_all) {
    std::fill(values, values + slots.nonzeros, 0.0);
    overwrite = false;
  }
  const int threads = NumThreads();
  if (threads == 1) {
    // Hinge blocks into the 3×3 vertex-pair blocks (each entry 0 + its hinges' in hinge order),
    // then those into the matrix.
    const long nb = static_cast<long>(slots.block_values.size() - 8) / 9;
    void* raw = slots.block_values.data();
    size_t space = slots.block_values.size() * sizeof(double);
    double* block_values =
        static_cast<double*>(std::align(64, 9 * nb * sizeof(double), raw, space));
    std::fill(block_values, block_values + 9 * nb, 0.0);
    LaneHessian u;
    for (long b = 0; b < nh; b += kLanes) {
      const int n = static_cast<int>(std::min<long>(kLanes, nh - b));
      HessianBlocks(x, projection, b, n, &u.u[0][0]);
      AddLaneBlocks(u, n, slots.block_slot.data() + kHingePairs * b, block_values,
                    block_values + 8 * nb);
    }
    BlockEntriesToValues(block_values, slots.value_source.data(),
                         slots.covers_all ? nullptr : slots.value_position.data(),
                         static_cast<long>(slots.value_source.size()), overwrite, values);
    return;
  }
  // Threads: blocks into a per-hinge buffer (blocks of kLanes hinges from the start, as in the
  // serial loop, so that every hinge gets the same bits), then a per-position gather in hinge
  // order from 0, added to the value (the serial additions in the serial order).
  hinge_hessian_.resize(static_cast<size_t>(kPackedSize) * nh);
  const int num_blocks = (nh + kLanes - 1) / kLanes;
  ParallelChunks(num_blocks, threads, [&](long begin, long end, int) {
    LaneHessian u;
    for (long blk = begin; blk < end; ++blk) {
      const long b = blk * kLanes;
      const int n = static_cast<int>(std::min<long>(kLanes, nh - b));
      HessianBlocks(x, projection, b, n, &u.u[0][0]);
      for (int l = 0; l < n; ++l)
        for (int k = 0; k < kPackedSize; ++k) hinge_hessian_[kPackedSize * (b + l) + k] = u.u[k][l];
    }
  });
  ParallelChunks(static_cast<int>(slots.nonzeros), threads, [&](long begin, long end, int) {
    const double* u = hinge_hessian_.data();
    for (long p = begin; p < end; ++p) {
      if (slots.source_offsets[p] == slots.source_offsets[p + 1]) continue;
      double v = 0.0;
      for (int k = slots.source_offsets[p]; k < slots.source_offsets[p + 1]; ++k)
        v += u[slots.sources[k]];
      if (overwrite) {
        values[p] = v;
      } else {
        values[p] += v;
      }
    }
  });
}

void BendingElements::SetHessian(const Vertices& x, HessianProjection projection,
                                 const BendingHessianSlots& slots,
                                 Eigen::SparseMatrix<double>* hessian) const {
  if (hessian->nonZeros() != slots.nonzeros || !hessian->isCompressed()) {
    throw InputError("bending: SetHessian needs the compressed matrix the slots were made for");
  }
  // 0 + s = s for the sums s (never -0: they start from +0), so the values need no zeroing
  // when the slots cover them all.
  FillHessianValues(x, projection, slots, true, hessian->valuePtr());
}

}  // namespace textile
