#include "textile/sim/bending_element.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <barrier>
#include <cassert>
#include <cmath>
#include <sstream>
#include <thread>

#include "textile/sim/error.h"

namespace textile {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat12 = Eigen::Matrix<double, 12, 12>;

inline Mat3 Skew(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

inline Eigen::Map<const Vec3> Row(const Vertices& x, int i) {
  return Eigen::Map<const Vec3>(x.data() + 3 * i);
}

// Geometry of one hinge at positions x: everything the gradient of θ needs (docs/bending.md,
// "Gradient of the bend angle"). n0 = e × a0 and n1 = a1 × e are the unnormalised normals of
// (x0, x2, x3) and (x1, x3, x2); |n_k| = |e| h_k.
struct HingeGeometry {
  Vec3 e, a0, a1, n0, n1;
  double l2, l, cos_term, sin_term;  // |n0||n1| cos θ, |n0||n1| sin θ
  void Compute(const Vertices& x, const std::array<int, 4>& v) {
    const auto x2 = Row(x, v[2]);
    e = Row(x, v[3]) - x2;
    a0 = Row(x, v[0]) - x2;
    a1 = Row(x, v[1]) - x2;
    n0 = e.cross(a0);
    n1 = a1.cross(e);
    l2 = e.squaredNorm();
    l = std::sqrt(l2);
    cos_term = n0.dot(n1);
    sin_term = l * n1.dot(a0);  // (n1 × n0)·e/|e| = |e| (a1 × e)·a0
  }
  double Angle() const { return std::atan2(sin_term, cos_term); }
  // ∂θ/∂x_i for the four vertices: g0 = |e| n0/|n0|², g1 = |e| n1/|n1|², the edge vertices take
  // the reactions at the wings' feet t0, t1 (Bridson et al. 2003's u_i).
  void Gradient(std::array<Vec3, 4>* g) const {
    const double n0sq = n0.squaredNorm(), n1sq = n1.squaredNorm();
    const double inv = 1.0 / (n0sq * n1sq);
    const double inv_l2 = 1.0 / l2;
    (*g)[0] = n0 * (l * n1sq * inv);
    (*g)[1] = n1 * (l * n0sq * inv);
    const double t0 = a0.dot(e) * inv_l2, t1 = a1.dot(e) * inv_l2;
    (*g)[2] = (t0 - 1.0) * (*g)[0] + (t1 - 1.0) * (*g)[1];
    (*g)[3] = -t0 * (*g)[0] - t1 * (*g)[1];
  }
};

// One triangle's part of ∇²θ (docs/bending.md, "Hessian of the bend angle"). The triangle's
// contribution to ∂θ/∂x_p is φ_p N with φ_p = f_p/(|e| |N|²), N its unnormalised normal and
// f = {|e|², -(x3 - w)·e, -(w - x2)·e} for p = {wing, x2, x3}; eps[p] is the edge opposite
// p in the triangle's counter-clockwise order, so that ∂N/∂x_p = [eps_p]×.
void AddTriangleAngleHessian(const Vec3& w, const Vec3& x2, const Vec3& x3, const Vec3& n,
                             const std::array<Vec3, 3>& eps, int wing, double scale, Mat12* h) {
  const Vec3 e = x3 - x2, aw = w - x2, bw = x3 - w;
  const double l2 = e.squaredNorm(), l = std::sqrt(l2), nsq = n.squaredNorm();
  const double inv = 1.0 / (l * nsq);
  const double phi[3] = {l2 * inv, -bw.dot(e) * inv, -aw.dot(e) * inv};
  // ∇_q f_p, rows p, columns q (both in the order wing, x2, x3).
  const Vec3 zero = Vec3::Zero();
  const Vec3 grad_f[3][3] = {{zero, -2.0 * e, 2.0 * e}, {e, bw, -e - bw}, {-e, e + aw, -aw}};
  const Vec3 grad_log_l[3] = {zero, -e / l2, e / l2};
  Vec3 two_u[3];  // 2 ∇λ_q = ∇_q log |N|²
  Mat3 skew[3];
  for (int q = 0; q < 3; ++q) {
    two_u[q] = n.cross(eps[q]) * (2.0 / nsq);
    skew[q] = Skew(eps[q]);
  }
  const int index[3] = {wing, 2, 3};
  for (int p = 0; p < 3; ++p) {
    for (int q = 0; q < 3; ++q) {
      const Vec3 d_phi = grad_f[p][q] * inv - phi[p] * (grad_log_l[q] + two_u[q]);
      h->block<3, 3>(3 * index[p], 3 * index[q]) +=
          scale * (n * d_phi.transpose() + phi[p] * skew[q]);
    }
  }
}

// ∇²θ of hinge (x0, x1, x2, x3), times scale, added to h.
void AddAngleHessian(const Vertices& x, const std::array<int, 4>& v, double scale, Mat12* h) {
  const Vec3 x0 = Row(x, v[0]), x1 = Row(x, v[1]), x2 = Row(x, v[2]), x3 = Row(x, v[3]);
  const Vec3 e = x3 - x2;
  // Triangle (x0, x2, x3) and triangle (x1, x3, x2).
  AddTriangleAngleHessian(x0, x2, x3, e.cross(x0 - x2), {e, x0 - x3, x2 - x0}, 0, scale, h);
  AddTriangleAngleHessian(x1, x2, x3, (x1 - x2).cross(e), {-e, x3 - x1, x1 - x2}, 1, scale, h);
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
  return std::atan2(e.norm() * n1.dot(a0), n0.dot(n1));
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
    : BendingElements(rest, hinges, material.EffectiveLaw(),
                      material.bending_weft ? std::optional<BendingLaw>(material.EffectiveWeftLaw())
                                            : std::nullopt,
                      options, stiffness_multiplier) {}

BendingElements::BendingElements(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                                 const BendingLaw& warp, const std::optional<BendingLaw>& weft,
                                 const BendingOptions& options,
                                 const std::vector<double>& stiffness_multiplier)
    : options_(options),
      warp_(warp),
      weft_(weft ? *weft : warp),
      anisotropic_(weft.has_value()),
      num_vertices_(rest.num_vertices()),
      hinges_(hinges) {
  if (std::string why; !options.Check(&why)) throw InputError(why);
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
    r.warp_weight = anisotropic_ ? e.x() * e.x() / (l * l) : 1.0;  // cos²φ, φ from the x axis
    edge_length_[h] = l;
    const double area_weight = l * height;  // A_h = |ē| h̄e = Ā0 + Ā1
    const double b1 = r.warp_weight * warp_.b1() + (1.0 - r.warp_weight) * weft_.b1();
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

double BendingElements::LawEnergy(const HingeRest& r, double kappa) const {
  if (!anisotropic_) return warp_.Energy(kappa);
  return r.warp_weight * warp_.Energy(kappa) + (1.0 - r.warp_weight) * weft_.Energy(kappa);
}
double BendingElements::LawMoment(const HingeRest& r, double kappa) const {
  if (!anisotropic_) return warp_.Moment(kappa);
  return r.warp_weight * warp_.Moment(kappa) + (1.0 - r.warp_weight) * weft_.Moment(kappa);
}
double BendingElements::LawStiffness(const HingeRest& r, double kappa) const {
  if (!anisotropic_) return warp_.Stiffness(kappa);
  return r.warp_weight * warp_.Stiffness(kappa) + (1.0 - r.warp_weight) * weft_.Stiffness(kappa);
}

// Energy of hinge h and, for the dihedral models, dE/dθ and d²E/dθ² (null pointers skip them).
double BendingElements::HingeTerms(const Vertices& x, int h, double* d_energy,
                                   double* d2_energy) const {
  const HingeRest& r = rest_[h];
  if (options_.model == BendingModel::kVolino || options_.model == BendingModel::kIsometric) {
    const auto& al = linear_[h].alpha;
    const Vec3 rv = al[0] * Row(x, r.v[0]) + al[1] * Row(x, r.v[1]) + al[2] * Row(x, r.v[2]) +
                    al[3] * Row(x, r.v[3]) - linear_[h].rest_vector;
    return 0.5 * r.weight * rv.squaredNorm();
  }
  HingeGeometry g;
  g.Compute(x, r.v);
  return DihedralTerms(g.cos_term, g.sin_term, h, d_energy, d2_energy, true);
}

// E(θ), E'(θ), E''(θ) of a dihedral model from |n0||n1| (cos θ, sin θ); with want_energy
// false the returned energy is 0 (the gradient path skips Ψ).
double BendingElements::DihedralTerms(double cos_term, double sin_term, int h, double* d_energy,
                                      double* d2_energy, bool want_energy) const {
  const HingeRest& r = rest_[h];
  if (options_.model == BendingModel::kPabst) {
    const double kappa = (std::atan2(sin_term, cos_term) - r.rest_angle) * r.inv_height;
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
  if (sb != 0.0) energy -= (std::atan2(sin_term, cos_term) - r.rest_angle) * sb;
  return r.weight * energy;
}

double BendingElements::BendAngle(const Vertices& x, int h) const {
  HingeGeometry g;
  g.Compute(x, rest_[h].v);
  return g.Angle();
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

  auto run = [&](long begin, long end, int thread) {
    double energy = 0.0;
    for (long h = begin; h < end; ++h) {
      const HingeRest& r = rest_[h];
      std::array<Vec3, 4> g;
      if (model == BendingModel::kVolino || model == BendingModel::kIsometric) {
        const auto& al = linear_[h].alpha;
        const Vec3 rv = al[0] * Row(x, r.v[0]) + al[1] * Row(x, r.v[1]) + al[2] * Row(x, r.v[2]) +
                        al[3] * Row(x, r.v[3]) - linear_[h].rest_vector;
        if constexpr (kWithEnergy) energy += 0.5 * r.weight * rv.squaredNorm();
        if constexpr (!kWithGradient) continue;
        const Vec3 wr = r.weight * rv;
        for (int i = 0; i < 4; ++i) g[i] = al[i] * wr;
      } else {
        HingeGeometry geo;
        geo.Compute(x, r.v);
        double d_energy;
        energy += DihedralTerms(geo.cos_term, geo.sin_term, static_cast<int>(h),
                                kWithGradient ? &d_energy : nullptr, nullptr, kWithEnergy);
        if constexpr (!kWithGradient) continue;
        geo.Gradient(&g);
        for (int i = 0; i < 4; ++i) g[i] *= d_energy;
      }
      if (direct) {
        for (int i = 0; i < 4; ++i) Eigen::Map<Vec3>(grad + 3 * r.v[i]) += g[i];
      } else {
        double* out = hinge_gradient_.data() + 12 * h;
        for (int i = 0; i < 4; ++i) Eigen::Map<Vec3>(out + 3 * i) = g[i];
      }
    }
    partial[thread] = energy;
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
    Eigen::SelfAdjointEigenSolver<Mat12> eigen;
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
      double d_energy, d2_energy;
      HingeGeometry geo;
      geo.Compute(x, r.v);
      DihedralTerms(geo.cos_term, geo.sin_term, static_cast<int>(h), &d_energy, &d2_energy, false);
      std::array<Vec3, 4> g;
      geo.Gradient(&g);
      Eigen::Matrix<double, 12, 1> gv;
      for (int i = 0; i < 4; ++i) gv.segment<3>(3 * i) = g[i];
      // ∇²E = E''(θ) ∇θ ∇θᵀ + E'(θ) ∇²θ.
      if (projection == HessianProjection::kGaussNewton) {
        block.noalias() = std::max(d2_energy, 0.0) * gv * gv.transpose();
      } else {
        block.noalias() = d2_energy * gv * gv.transpose();
        AddAngleHessian(x, r.v, d_energy, &block);
      }
      if (projection == HessianProjection::kEigen) {
        eigen.compute(block);
        const auto& values = eigen.eigenvalues();
        if (values.minCoeff() < 0.0) {
          block.noalias() = eigen.eigenvectors() * values.cwiseMax(0.0).asDiagonal() *
                            eigen.eigenvectors().transpose();
        }
      }
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
              emit(3 * r.v[i] + a, 3 * r.v[j] + b, block(3 * i + a, 3 * j + b));
    }
  });
}

}  // namespace textile
