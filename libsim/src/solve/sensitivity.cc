#include "textile/sim/solve/sensitivity.h"

#include <Eigen/CholmodSupport>
#include <cmath>

#include "serial_openmp.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/law/material_parameters.h"

namespace textile {

// The relative step of the central difference in p: truncation ~(1e-4)² relative, round-off
// ~1e-16 / 1e-4 of the force scale; both far below the 2 % the sensitivities are held to.
constexpr double kParameterStep = 1e-4;

namespace {

// The part of the cloth's potential a material parameter enters.
int PartOf(const std::string& parameter) {
  if (parameter.rfind("stretch.", 0) == 0) return ClothProblem::kMembranePart;
  if (parameter == "areal_density_gsm") return ClothProblem::kGravityPart;
  return ClothProblem::kBendingPart;  // the laws' constants and β
}

}  // namespace

struct EquilibriumSensitivity::Factor {
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Upper> cholmod;
};

EquilibriumSensitivity::EquilibriumSensitivity(ClothProblem* problem, const Vertices& x,
                                               const Material& material, double max_residual)
    : problem_(problem), x_(x), material_(material), factor_(std::make_unique<Factor>()) {
  if (x.rows() != problem->num_vertices() || x.cols() != 3 || !x.allFinite())
    throw InputError("sensitivity: the state must be finite, one row a vertex of the problem");
  Vertices grad;
  problem->EnergyGradient(x, &grad);
  const double residual = problem->RelativeResidual(grad);
  if (!(residual <= max_residual))
    throw ComputeError("sensitivity: the state is not an equilibrium (relative residual " +
                       NumberText(residual, 3) + " > " + NumberText(max_residual, 3) + ")");
  // SC section 4: K = ∇ₓR, the exact Hessian: a projected one would give another dx.
  const Eigen::SparseMatrix<double>& k = problem->Hessian(x, HessianProjection::kNone);
  factor_->cholmod.cholmod().print = 0;
  // Supernodal LLᵀ: it fails on any non-positive pivot. The automatic choice takes simplicial
  // LDLᵀ on small, sparse matrices, which fails on a zero pivot only and would pass an
  // indefinite K.
  factor_->cholmod.setMode(Eigen::CholmodSupernodalLLt);
  const SerialOpenMp serial;
  factor_->cholmod.compute(k);
  if (factor_->cholmod.info() != Eigen::Success)
    throw ComputeError(
        "sensitivity: the equilibrium's stiffness is not positive definite (a buckling point "
        "or a saddle): the state may jump to another branch, and no sensitivity exists");
}

EquilibriumSensitivity::~EquilibriumSensitivity() = default;

Vertices EquilibriumSensitivity::Solve(const Vertices& residual_change) const {
  const long n = 3 * x_.rows();
  Eigen::VectorXd b(n);
  for (long i = 0; i < x_.rows(); ++i)
    for (int c = 0; c < 3; ++c) b(3 * i + c) = -residual_change(i, c);
  for (int v : problem_->fixed_vertices()) b.segment<3>(3 * v).setZero();
  const SerialOpenMp serial;
  const Eigen::VectorXd d = factor_->cholmod.solve(b);
  if (!d.allFinite()) throw ComputeError("sensitivity: the back-substitution gave NaN");
  Vertices dx(x_.rows(), 3);
  for (long i = 0; i < x_.rows(); ++i)
    for (int c = 0; c < 3; ++c) dx(i, c) = d(3 * i + c);
  return dx;
}

Vertices EquilibriumSensitivity::ResidualDerivative(const std::string& parameter) const {
  const ParameterStep step = DifferenceStep(material_, parameter, kParameterStep);
  const int part = PartOf(parameter);
  return (problem_->MaterialGradient(x_, step.up, part) -
          problem_->MaterialGradient(x_, step.down, part)) /
         step.span;
}

Vertices EquilibriumSensitivity::DisplacementPerUnit(const std::string& parameter) const {
  return Solve(ResidualDerivative(parameter));
}

Vertices EquilibriumSensitivity::Adjoint(const Vertices& quantity_gradient) const {
  if (quantity_gradient.rows() != x_.rows() || quantity_gradient.cols() != 3 ||
      !quantity_gradient.allFinite())
    throw InputError("sensitivity: the quantity's gradient must be finite, one row a vertex");
  return Solve(quantity_gradient);  // -K⁻¹ g, zero on fixed vertices
}

double EquilibriumSensitivity::QuantityDerivativePerUnit(const Vertices& adjoint,
                                                         const std::string& parameter) const {
  if (adjoint.rows() != x_.rows() || adjoint.cols() != 3)
    throw InputError("sensitivity: the adjoint must have one row a vertex");
  const double d = (adjoint.array() * ResidualDerivative(parameter).array()).sum();
  if (!std::isfinite(d))
    throw ComputeError("sensitivity: the derivative for '" + parameter + "' is not a number");
  return d;
}

Vertices EquilibriumSensitivity::RestShapeResidualChange(const Vertices& d_rest, double step,
                                                         const SeamsAt& seams_at,
                                                         int parts) const {
  if (d_rest.rows() != x_.rows() || d_rest.cols() != 3 || !d_rest.allFinite())
    throw InputError("sensitivity: the rest morph must be finite, one row a vertex");
  if (!(step > 0.0) || !std::isfinite(step))
    throw InputError("sensitivity: the rest morph's step must be > 0");
  const auto force_at = [&](double t) {
    TriangleMesh morphed = problem_->rest();
    morphed.vertices += t * d_rest;
    std::vector<Seam> seams;
    if (seams_at) seams = seams_at(t);
    return problem_->MaterialGradient(x_ + t * d_rest, material_, parts, &morphed,
                                      seams_at ? &seams : nullptr);
  };
  Vertices d = (force_at(step) - force_at(-step)) / (2.0 * step);
  if (!d.allFinite())
    throw ComputeError("sensitivity: the rest morph's force change is not a number");
  return d;
}

Vertices EquilibriumSensitivity::Displacement(const std::string& parameter) const {
  const double p = GetMaterialParameter(material_, parameter).si;
  if (p == 0.0) return Vertices::Zero(x_.rows(), 3);
  return p * DisplacementPerUnit(parameter);
}

}  // namespace textile
