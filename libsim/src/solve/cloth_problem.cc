#include "textile/sim/solve/cloth_problem.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "textile/sim/core/error.h"

namespace textile {

// Lagged slip: the part of a node's weight it may pull past μ f_n even with no normal force.
constexpr double kSlipFloor = 1e-4;
// Friction potential: the lagged μ f̄_n and tangent plane follow the state after a Newton step
// only where they are more than kLagTolerance off (relative; in the unit normal), and the k-th
// update of a node goes 1 / (1 + k / kLagRelaxation) of the way. Set to the state's own after
// every step, they made Newton chase a potential that moved with it: it cycled between two
// states, f̄_n flipping by 0.1-0.3 % (15 mm mesh, seed 3); with the tolerance alone one run in
// 14 still cycled (μ = 3 or μ = 1, depending on whether the plane followed), with the
// relaxation none. 8 instead of 32 took up to twice the steps: what an update leaves off holds
// convergence up (UpdateAnchors), and smaller steps leave more (docs/methods/drapemeter.md, "Limits").
constexpr double kLagTolerance = 0.01;
constexpr double kLagRelaxation = 32.0;

namespace {

std::optional<BendingLaw> WeftLaw(const Material& m, double scale) {
  if (!m.bending_weft) return std::nullopt;
  return m.EffectiveWeftLaw().Scaled(scale);
}

std::vector<double> Multipliers(const TriangleMesh& rest, const std::vector<Hinge>& hinges,
                                const std::vector<Seam>& seams) {
  if (seams.empty()) return {};
  return HingeSeamMultipliers(rest, hinges, seams);
}

const TriangleMesh& Checked(const TriangleMesh& mesh) {
  CheckMesh(mesh);
  return mesh;
}

const ClothOptions& Checked(const ClothOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(why);
  return options;
}

}  // namespace

bool ClothOptions::Check(std::string* why) const {
  if (!bending.Check(why)) return false;
  if (discretization != BendingDiscretization::kHinge &&
      discretization != BendingDiscretization::kTensor) {
    *why = "bending discretization is neither hinge nor tensor";
    return false;
  }
  if (!contact.Check(why)) return false;
  if (!gravity.allFinite()) {
    *why = "gravity must be finite";
    return false;
  }
  if (!(bending_scale > 0.0) || !std::isfinite(bending_scale)) {
    *why = "bending_scale must be > 0 and finite";
    return false;
  }
  return true;
}

ClothProblem::ClothProblem(const TriangleMesh& rest, const Material& material,
                           const std::vector<Seam>& seams, const ClothOptions& options)
    : rest_(Checked(rest)),
      options_(Checked(options)),
      seams_(seams),
      masses_(LumpedMasses(rest, material.areal_density, seams)),
      membrane_(rest, material, options.membrane),
      hinges_(BuildHinges(rest)),
      is_fixed_(rest.num_vertices(), 0),
      anchors_(rest.num_vertices()) {
  const double g = options_.gravity.norm();
  // Without gravity the penalty still needs a scale: use standard gravity's.
  const double g_scale = g > 0.0 ? g : 9.80665;
  penalty_ = masses_ * (g_scale / options_.contact.sink_under_own_weight);
  tangential_stiffness_ = options_.contact.tangential_ratio * material.MembraneModulus();
  // Only the chosen discretisation is built; both take the hinges and their seam multipliers.
  multipliers_ = Multipliers(rest_, hinges_, seams);
  if (options_.discretization == BendingDiscretization::kTensor) {
    tensor_.emplace(TensorElements(material, rest_, multipliers_));
  } else {
    bending_.emplace(HingeElements(material, rest_, multipliers_));
  }
  BuildPattern();
}

DirectionLaws ClothProblem::BendingLaws(const Material& material) const {
  std::optional<BendingLaw> bias = material.EffectiveBiasLaw();
  if (bias) bias = bias->Scaled(options_.bending_scale);
  return {material.EffectiveLaw().Scaled(options_.bending_scale),
          WeftLaw(material, options_.bending_scale), bias};
}

BendingElements ClothProblem::HingeElements(const Material& material, const TriangleMesh& rest,
                                            const std::vector<double>& multipliers) const {
  return BendingElements(rest, hinges_, BendingLaws(material), options_.bending, multipliers);
}

TensorBending ClothProblem::TensorElements(const Material& material, const TriangleMesh& rest,
                                           const std::vector<double>& multipliers) const {
  // docs/methods/materials.md, "Warp, weft and bias": the twist term a bias law fixes can
  // make the tensor energy non-convex, so these elements take warp and weft only.
  if (material.bending_bias) {
    throw InputError(
        "bending_bias: the curvature-tensor bending takes warp and weft laws only; use the "
        "hinge discretisation for a material with a measured bias law");
  }
  const DirectionLaws laws = BendingLaws(material);
  return TensorBending(rest, hinges_, laws.warp, laws.weft, multipliers);
}

Vertices ClothProblem::MaterialGradient(const Vertices& x, const Material& other, int parts,
                                        const TriangleMesh* rest,
                                        const std::vector<Seam>* seams) const {
  if (seams && seams->size() != seams_.size())
    throw InputError("material gradient: other seams must be the problem's, moved");
  if (rest && (rest->num_vertices() != rest_.num_vertices() ||
               rest->triangles.rows() != rest_.triangles.rows() ||
               rest->triangles != rest_.triangles))
    throw InputError("material gradient: another rest mesh must have the problem's vertices and "
                     "triangles");
  const TriangleMesh& on = rest ? Checked(*rest) : rest_;
  const std::vector<Seam>& lines = seams ? *seams : seams_;
  const bool moved = rest || seams;
  std::vector<double> moved_multipliers;  // the seams' bands found on the other rest mesh
  if (moved && (parts & kBendingPart)) moved_multipliers = Multipliers(on, hinges_, lines);
  const std::vector<double>& multipliers = moved ? moved_multipliers : multipliers_;
  Vertices grad = Vertices::Zero(x.rows(), 3);
  if (parts & kMembranePart) MembraneElements(on, other, options_.membrane).AddGradient(x, grad);
  if ((parts & kBendingPart) && tensor_)
    TensorElements(other, on, multipliers).EnergyGradient(x, grad);
  if ((parts & kBendingPart) && !tensor_)
    HingeElements(other, on, multipliers).AddGradient(x, grad);
  if (parts & kGravityPart) {
    const Eigen::VectorXd masses = LumpedMasses(on, other.areal_density, lines);
    for (int i = 0; i < num_vertices(); ++i)
      grad.row(i) -= masses(i) * options_.gravity.transpose();
  }
  for (int v : fixed_) grad.row(v).setZero();
  return grad;
}

int ClothProblem::num_bending_elements() const {
  return tensor_ ? tensor_->num_elements() : bending_->num_hinges();
}

void ClothProblem::BendingTriplets(const Vertices& x, HessianProjection projection, int first,
                                   int end) {
  if (tensor_) {
    tensor_->AddHessianTriplets(x, &triplets_, projection, first, end);
  } else {
    bending_->AddHessianTriplets(x, &triplets_, projection, first, end);
  }
}

// Elements are assembled in chunks of this many triangles or hinges, so the triplet buffer stays
// a few MB however large the mesh (a 100k-triangle sheet would otherwise need ~0.5 GB of it).
constexpr int kAssemblyChunk = 4096;

void ClothProblem::BuildPattern() {
  const int nv = num_vertices();
  const int n = 3 * nv;
  // Vertex-level pattern: every pair of vertices sharing a triangle or a hinge, and the diagonal
  // (contact and anchor blocks). Each pair becomes a dense 3×3 block.
  std::vector<Eigen::Triplet<double>> pairs;
  pairs.reserve(9 * static_cast<size_t>(rest_.num_triangles()) + 16 * hinges_.size() + nv);
  for (int f = 0; f < rest_.num_triangles(); ++f)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) pairs.emplace_back(rest_.triangles(f, a), rest_.triangles(f, b), 1.0);
  for (const Hinge& h : hinges_)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) pairs.emplace_back(h.v[a], h.v[b], 1.0);
  if (tensor_) {  // a triangle's element couples its three wings too
    for (int t = 0; t < tensor_->num_triangles(); ++t)
      for (int a : tensor_->patch(t))
        for (int b : tensor_->patch(t)) pairs.emplace_back(a, b, 1.0);
  }
  for (int i = 0; i < nv; ++i) pairs.emplace_back(i, i, 1.0);
  Eigen::SparseMatrix<double> vertex_pattern(nv, nv);
  vertex_pattern.setFromTriplets(pairs.begin(), pairs.end());
  pairs = {};
  Eigen::VectorXi column_sizes(n);
  for (int j = 0; j < nv; ++j) {
    const int count = 3 * (vertex_pattern.outerIndexPtr()[j + 1] - vertex_pattern.outerIndexPtr()[j]);
    column_sizes.segment<3>(3 * j).setConstant(count);
  }
  hessian_.resize(n, n);
  hessian_.reserve(column_sizes);
  for (int j = 0; j < nv; ++j)
    for (int c = 0; c < 3; ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(vertex_pattern, j); it; ++it)
        for (int r = 0; r < 3; ++r) hessian_.insert(3 * static_cast<int>(it.row()) + r, 3 * j + c) = 0.0;
  hessian_.makeCompressed();
  const int* outer = hessian_.outerIndexPtr();
  const int* inner = hessian_.innerIndexPtr();
  auto slot = [&](int row, int col) {
    const int* begin = inner + outer[col];
    const int* end = inner + outer[col + 1];
    const int* it = std::lower_bound(begin, end, row);
    assert(it != end && *it == row);
    return static_cast<int>(it - inner);
  };
  // Slots of every element entry, in the order the elements emit them.
  triplet_slot_.clear();
  const Vertices& x = rest_.vertices;
  for (int f = 0; f < rest_.num_triangles(); f += kAssemblyChunk) {
    triplets_.clear();
    membrane_.AddHessianTriplets(x, &triplets_, false, f, std::min(f + kAssemblyChunk, rest_.num_triangles()));
    for (const auto& t : triplets_) triplet_slot_.push_back(slot(t.row(), t.col()));
  }
  if (tensor_) {
    for (int h = 0; h < num_bending_elements(); h += kAssemblyChunk) {
      triplets_.clear();
      BendingTriplets(x, HessianProjection::kNone, h, std::min(h + kAssemblyChunk, num_bending_elements()));
      for (const auto& t : triplets_) triplet_slot_.push_back(slot(t.row(), t.col()));
    }
  } else {
    // The elements' own pattern, its upper half (half the slots' memory): once, fixing does not
    // change it. Each value goes to its place and, off the diagonal, to its mirror.
    if (bending_slots_.slot.empty()) {
      bending_hessian_ = bending_->HessianPattern(/*upper=*/true);
      bending_slots_ = bending_->HessianSlots(bending_hessian_, /*upper=*/true);
    }
    const int* b_outer = bending_hessian_.outerIndexPtr();
    const int* b_inner = bending_hessian_.innerIndexPtr();
    bending_value_slot_.assign(2 * static_cast<size_t>(bending_hessian_.nonZeros()), -1);
    for (int col = 0; col < bending_hessian_.outerSize(); ++col) {
      for (int k = b_outer[col]; k < b_outer[col + 1]; ++k) {
        const int row = b_inner[k];
        bending_value_slot_[2 * static_cast<size_t>(k)] = slot(row, col);
        if (row != col) bending_value_slot_[2 * static_cast<size_t>(k) + 1] = slot(col, row);
      }
    }
  }
  triplets_ = {};
  triplet_slot_.shrink_to_fit();
  diagonal_block_slot_.resize(9 * static_cast<size_t>(nv));
  for (int i = 0; i < nv; ++i)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) diagonal_block_slot_[9 * i + 3 * a + b] = slot(3 * i + a, 3 * i + b);
}

void ClothProblem::FixVertices(const std::vector<int>& vertices, const Vertices& positions) {
  if (static_cast<long>(vertices.size()) != positions.rows())
    throw InputError("fixed vertices: " + std::to_string(vertices.size()) + " ids but " +
                     std::to_string(positions.rows()) + " positions");
  std::vector<char> seen(num_vertices(), 0);
  for (size_t k = 0; k < vertices.size(); ++k) {
    const int v = vertices[k];
    if (v < 0 || v >= num_vertices())
      throw InputError("fixed vertex " + std::to_string(v) + " is not a vertex of the mesh");
    if (seen[v]) throw InputError("fixed vertex " + std::to_string(v) + " is given twice");
    if (!positions.row(static_cast<long>(k)).allFinite())
      throw InputError("fixed vertex " + std::to_string(v) + " has a non-finite position");
    seen[v] = 1;
  }
  fixed_ = vertices;
  is_fixed_ = seen;
  fixed_positions_ = positions;
  DropFixedFromPattern();
}

// A fixed dof's row and column hold nothing but the diagonal that Hessian() sets, so their
// off-diagonal entries leave the pattern: CHOLMOD then neither orders nor fills them (a clamped
// drape fixes a third of its vertices; the factorisation is most of a Newton step). Element
// entries that fall there are added to a fixed diagonal instead, which Hessian() overwrites.
void ClothProblem::DropFixedFromPattern() {
  if (pattern_reduced_) BuildPattern();  // fixed again: start from the full pattern
  pattern_reduced_ = false;
  fixed_diagonal_slots_.clear();
  if (fixed_.empty()) return;
  const int n = static_cast<int>(hessian_.cols());
  const int* outer = hessian_.outerIndexPtr();
  const int* inner = hessian_.innerIndexPtr();
  const auto keep = [&](int row, int col) {
    return row == col || (!is_fixed_[row / 3] && !is_fixed_[col / 3]);
  };
  Eigen::VectorXi column_sizes = Eigen::VectorXi::Zero(n);
  for (int col = 0; col < n; ++col)
    for (int k = outer[col]; k < outer[col + 1]; ++k) column_sizes[col] += keep(inner[k], col);
  Eigen::SparseMatrix<double> reduced(n, n);
  reduced.reserve(column_sizes);
  for (int col = 0; col < n; ++col)
    for (int k = outer[col]; k < outer[col + 1]; ++k)
      if (keep(inner[k], col)) reduced.insert(inner[k], col) = 0.0;
  reduced.makeCompressed();
  // Old slot -> new slot, in the same order within each column; dropped entries -> the diagonal
  // of the first fixed dof.
  std::vector<int> new_slot(hessian_.nonZeros(), -1);
  const int* new_outer = reduced.outerIndexPtr();
  for (int col = 0; col < n; ++col) {
    int next = new_outer[col];
    for (int k = outer[col]; k < outer[col + 1]; ++k)
      if (keep(inner[k], col)) new_slot[k] = next++;
  }
  const int first = 3 * fixed_.front();
  const int* new_inner = reduced.innerIndexPtr();
  const int trash = static_cast<int>(
      std::lower_bound(new_inner + new_outer[first], new_inner + new_outer[first + 1], first) -
      new_inner);
  for (int& slot : triplet_slot_) slot = new_slot[slot] >= 0 ? new_slot[slot] : trash;
  for (int& slot : bending_value_slot_)
    if (slot >= 0) slot = new_slot[slot] >= 0 ? new_slot[slot] : trash;
  for (int& slot : diagonal_block_slot_) slot = new_slot[slot] >= 0 ? new_slot[slot] : trash;
  hessian_.swap(reduced);  // O(1); Eigen 3.4's SparseMatrix has no move assignment
  for (int v : fixed_)
    for (int a = 0; a < 3; ++a)
      fixed_diagonal_slots_.push_back(diagonal_block_slot_[9 * v + 4 * a]);
  pattern_reduced_ = true;
}

void ClothProblem::SetFixedPositions(const Vertices& positions) {
  if (positions.rows() != fixed_positions_.rows() || !positions.allFinite())
    throw InputError("fixed positions: expected " + std::to_string(fixed_positions_.rows()) +
                     " finite rows");
  fixed_positions_ = positions;
}

void ClothProblem::AddSupport(const Support& support) { supports_.push_back(support); }

void ClothProblem::ApplyFixed(Vertices* x) const {
  for (size_t k = 0; k < fixed_.size(); ++k)
    x->row(fixed_[k]) = fixed_positions_.row(static_cast<long>(k));
}

int ClothProblem::Touching(const Eigen::Vector3d& p, double limit, double* phi,
                           Eigen::Vector3d* normal) const {
  int best = -1;
  double best_phi = limit;
  for (size_t s = 0; s < supports_.size(); ++s) {
    Eigen::Vector3d n;
    const double d = supports_[s].SignedDistance(p, &n);
    if (d < best_phi) {
      best_phi = d;
      best = static_cast<int>(s);
      *normal = n;
    }
  }
  *phi = best_phi;
  return best;
}

double ClothProblem::ContactEnergyGradient(const Vertices& x, Vertices* grad) const {
  if (supports_.empty()) return 0.0;  // a scene without obstacles pays nothing for contact
  double energy = 0.0;
  const double kt = tangential_stiffness_;
  const bool potential = options_.contact.friction_potential;
  for (int i = 0; i < num_vertices(); ++i) {
    if (is_fixed_[i]) continue;
    const Eigen::Vector3d p = x.row(i).transpose();
    for (const Support& s : supports_) {
      Eigen::Vector3d n;
      const double phi = s.SignedDistance(p, &n);
      if (phi >= 0.0) continue;
      energy += 0.5 * penalty_(i) * phi * phi;
      if (grad) grad->row(i) += (penalty_(i) * phi) * n.transpose();
    }
    const Anchor& a = anchors_[i];
    if (a.support >= 0 && a.sliding) {
      // Sliding (Coulomb): a constant force of μ f_n against the slip, potential f t̂·x.
      energy += a.friction_force * a.slip.dot(p - a.point);
      if (grad) grad->row(i) += a.friction_force * a.slip.transpose();
    } else if (a.support >= 0 && !(potential && a.friction_force <= 0.0)) {
      const Eigen::Vector3d d = p - a.point;
      const Eigen::Vector3d dt = d - a.normal * a.normal.dot(d);
      const double s = dt.norm();
      const double stick = a.friction_force / kt;  // friction_potential: the spring's reach [m]
      if (!potential || s <= stick) {
        energy += 0.5 * kt * dt.squaredNorm();
        if (grad) grad->row(i) += kt * dt.transpose();
      } else {
        energy += a.friction_force * (s - 0.5 * stick);
        if (grad) grad->row(i) += (a.friction_force / s) * dt.transpose();
      }
    }
  }
  return energy;
}

double ClothProblem::Energy(const Vertices& x) const {
  double e = membrane_.Energy(x) + (tensor_ ? tensor_->Energy(x) : bending_->Energy(x));
  for (int i = 0; i < num_vertices(); ++i) e -= masses_(i) * options_.gravity.dot(x.row(i));
  return e + ContactEnergyGradient(x, nullptr);
}

double ClothProblem::EnergyGradient(const Vertices& x, Vertices* grad) const {
  grad->setZero(x.rows(), 3);
  membrane_.AddGradient(x, *grad);
  double e = membrane_.Energy(x) +
             (tensor_ ? tensor_->EnergyGradient(x, *grad) : bending_->EnergyGradient(x, *grad));
  for (int i = 0; i < num_vertices(); ++i) {
    e -= masses_(i) * options_.gravity.dot(x.row(i));
    grad->row(i) -= masses_(i) * options_.gravity.transpose();
  }
  e += ContactEnergyGradient(x, grad);
  for (int v : fixed_) grad->row(v).setZero();
  return e;
}

const Eigen::SparseMatrix<double>& ClothProblem::Hessian(const Vertices& x,
                                                         HessianProjection projection) {
  const bool project = projection != HessianProjection::kNone;
  double* values = hessian_.valuePtr();
  std::fill(values, values + hessian_.nonZeros(), 0.0);
  size_t next = 0;  // position in triplet_slot_
  auto scatter = [&] {
    for (const auto& t : triplets_) values[triplet_slot_[next++]] += t.value();
  };
  for (int f = 0; f < rest_.num_triangles(); f += kAssemblyChunk) {
    triplets_.clear();
    membrane_.AddHessianTriplets(x, &triplets_, project, f,
                                 std::min(f + kAssemblyChunk, rest_.num_triangles()));
    scatter();
  }
  if (tensor_) {
    for (int h = 0; h < num_bending_elements(); h += kAssemblyChunk) {
      triplets_.clear();
      BendingTriplets(x, projection, h, std::min(h + kAssemblyChunk, num_bending_elements()));
      scatter();
    }
  } else if (bending_hessian_.nonZeros() > 0) {
    bending_->SetHessian(x, projection, bending_slots_, &bending_hessian_);
    const double* b = bending_hessian_.valuePtr();
    const int* to = bending_value_slot_.data();
    for (long k = 0; k < bending_hessian_.nonZeros(); ++k) {
      values[to[2 * k]] += b[k];
      if (to[2 * k + 1] >= 0) values[to[2 * k + 1]] += b[k];
    }
  }
  assert(next == triplet_slot_.size());
  if (!supports_.empty()) {
    for (int i = 0; i < num_vertices(); ++i) {
      if (is_fixed_[i]) continue;
      Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
      const Eigen::Vector3d p = x.row(i).transpose();
      for (const Support& s : supports_) {
        Eigen::Vector3d n;
        if (s.SignedDistance(p, &n) < 0.0) block += penalty_(i) * n * n.transpose();
      }
      const Anchor& a = anchors_[i];
      const bool potential = options_.contact.friction_potential;
      if (a.support >= 0 && !a.sliding && !(potential && a.friction_force <= 0.0)) {
        const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - a.normal * a.normal.transpose();
        const Eigen::Vector3d dt = tangent * (p - a.point);
        const double s = dt.norm();
        if (!potential || s * tangential_stiffness_ <= a.friction_force) {
          block += tangential_stiffness_ * tangent;
        } else {
          // μ f̄_n s: the norm's curvature, across the slip only.
          const Eigen::Vector3d t = dt / s;
          block += (a.friction_force / s) * (tangent - t * t.transpose());
        }
      }
      if (block.isZero(0.0)) continue;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) values[diagonal_block_slot_[9 * i + 3 * r + c]] += block(r, c);
    }
  }
  if (!fixed_.empty()) {
    // The fixed dofs' identity rows, scaled to the free dofs' mean diagonal (the fixed
    // diagonals also hold the element entries dropped from the pattern: DropFixedFromPattern).
    double diag_sum = 0.0;
    int free_dofs = 0;
    for (int i = 0; i < num_vertices(); ++i) {
      if (is_fixed_[i]) continue;
      for (int a = 0; a < 3; ++a) diag_sum += values[diagonal_block_slot_[9 * i + 4 * a]];
      free_dofs += 3;
    }
    const double scale = diag_sum > 0.0 ? diag_sum / free_dofs : 1.0;
    for (int k : fixed_diagonal_slots_) values[k] = scale;
  }
  return hessian_;
}

double ClothProblem::UpdateAnchors(const Vertices& x, const Vertices& previous) {
  const double mu = options_.contact.friction;
  if (supports_.empty() || mu <= 0.0) return 0.0;
  const double keep = options_.contact.anchor_keep_distance;
  double slid = 0.0;
  for (int i = 0; i < num_vertices(); ++i) {
    Anchor& a = anchors_[i];
    if (is_fixed_[i]) {
      a.support = -1;
      continue;
    }
    const Eigen::Vector3d p = x.row(i).transpose();
    double phi;
    Eigen::Vector3d n;
    const int s = Touching(p, a.support >= 0 ? keep : 0.0, &phi, &n);
    if (s < 0) {
      if (a.support >= 0) ++anchor_version_;
      a.support = -1;  // contact ended: the anchor is released
      continue;
    }
    const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - n * n.transpose();
    const double limit = mu * penalty_(i) * std::max(-phi, 0.0);  // μ f_n
    if (options_.contact.friction_potential) {
      if (a.support >= 0 && a.support != s) a.support = -1;  // another support: a new contact
      if (a.support < 0) {
        // Contact starts: anchored under where the node came from, its friction at once.
        const Eigen::Vector3d before = previous.row(i).transpose();
        Eigen::Vector3d n_before;
        const double phi_before = supports_[s].SignedDistance(before, &n_before);
        a = Anchor{s, before - phi_before * n_before, n, false, Eigen::Vector3d::Zero(), limit, false};
        ++anchor_version_;
        continue;
      }
      // The anchor stays where the contact began. The normal force and the tangent plane follow
      // the state once they are more than kLagTolerance off; what is still off after the
      // (relaxed) update keeps the solve from converging.
      slid = std::max(slid, UpdateLaggedFriction(i, -phi, n));
      continue;
    }
    ++anchor_version_;
    if (a.support >= 0 && a.support != s) a.support = -1;  // another support: a new contact
    if (a.support < 0) {  // contact starts: sticking, anchored under where the node came from
      const Eigen::Vector3d before = previous.row(i).transpose();
      Eigen::Vector3d n_before;
      const double phi_before = supports_[s].SignedDistance(before, &n_before);
      a = Anchor{s, before - phi_before * n_before, n_before, false, Eigen::Vector3d::Zero(), 0.0,
                 false};
      continue;
    }
    if (a.sliding) {
      const Eigen::Vector3d motion = tangent * (p - previous.row(i).transpose());
      if (motion.dot(a.slip) <= 0.0 || motion.norm() < 1e-12) {
        // Stopped or pulled back by the friction force: it sticks where it is.
        a = Anchor{s, p - phi * n, n, false, Eigen::Vector3d::Zero(), 0.0, true};
      } else {
        a.slip = motion.normalized();
        a.friction_force = limit;
        a.point = p;
        a.normal = n;
        a.support = s;
        slid = std::max(slid, motion.norm());
      }
      continue;
    }
    const Eigen::Vector3d dt = tangent * (p - a.point);
    const double tangential = tangential_stiffness_ * dt.norm();
    // A node that stopped sliding must be pulled 5 % past the limit to slide again: without
    // this hysteresis a node at the limit can flip between the two states forever.
    const double margin = a.stopped ? 1.05 : 1.0 + 1e-6;
    if (!options_.contact.lagged_slip && tangential > limit * margin && dt.norm() > 0.0) {
      // The spring pulls harder than friction can hold: it slides (Coulomb), from now on
      // against a constant force μ f_n.
      slid = std::max(slid, dt.norm() - limit / tangential_stiffness_);
      a = Anchor{s, p, n, true, dt.normalized(), limit, a.stopped};
      continue;
    }
    // Sticking: the anchor is a point of the support and stays one. It is only pulled back onto
    // the surface (round-off), along the support's own normal there: re-projecting it under the
    // node instead would drag it after the node on a curved surface (the rounded rim of a
    // drape's disk), a creep that no friction limit checks.
    Eigen::Vector3d normal_at_anchor;
    const double off_surface = supports_[s].SignedDistance(a.point, &normal_at_anchor);
    a.point -= off_surface * normal_at_anchor;
    a.normal = normal_at_anchor;
    a.support = s;
  }
  return slid;
}

double ClothProblem::UpdateLaggedFriction(int i, double depth, const Eigen::Vector3d& normal) {
  Anchor& a = anchors_[i];
  const double limit = options_.contact.friction * penalty_(i) * std::max(depth, 0.0);  // μ f_n
  const auto off = [&] {  // relative force gap and plane gap, the larger
    const double larger = std::max(limit, a.friction_force);
    const double force = larger > 0.0 ? std::abs(limit - a.friction_force) / larger : 0.0;
    return std::max(force, (normal - a.normal).norm());
  };
  if (!(off() > kLagTolerance)) return 0.0;
  // Relaxed: the k-th update of a node moves its lagged values 1 / (1 + k/32) of the way.
  const double w = 1.0 / (1.0 + a.lag_updates / kLagRelaxation);
  ++a.lag_updates;
  a.friction_force += w * (limit - a.friction_force);
  a.normal = (a.normal + w * (normal - a.normal)).normalized();
  ++anchor_version_;
  // A node that no longer presses (μ f_n = 0, within the keep distance) lets its lagged force
  // fade without holding the solve up: the force it can still exert fades with it.
  const double left = off();
  return limit > 0.0 && left > kLagTolerance ? left : 0.0;
}

double ClothProblem::SlipAnchors(const Vertices& x) {
  if (!lagged_slip()) return 0.0;  // off, or no friction or no support
  const double mu = options_.contact.friction;
  const double excess = options_.contact.slip_excess;
  const double g = options_.gravity.norm();
  const double kt = tangential_stiffness_;
  double moved = 0.0;
  for (int i = 0; i < num_vertices(); ++i) {
    Anchor& a = anchors_[i];
    if (a.support < 0 || a.sliding || is_fixed_[i]) continue;
    const Eigen::Vector3d p = x.row(i).transpose();
    const double phi = supports_[a.support].SignedDistance(p, nullptr);
    const double limit = mu * penalty_(i) * std::max(-phi, 0.0);  // μ f_n [N]
    const Eigen::Vector3d d = p - a.point;
    const Eigen::Vector3d dt = d - a.normal * a.normal.dot(d);
    const double pull = kt * dt.norm();  // [N]
    // It holds while it pulls at most `excess` of μ f_n past it (plus 1e-4 of its weight, so
    // that a node with next to no normal force does not slip by round-off).
    if (!(pull > (1.0 + excess) * limit + kSlipFloor * masses_(i) * g)) {
      a.last_slip.setZero();
      continue;
    }
    // To the cone's edge. Successive slips of one node in one direction shrink geometrically
    // (by r ≈ k_t / (k_t + the cloth's stiffness there), close to 1), so a slip that follows
    // the previous one with 0 < r < 1 jumps to the series' sum, 1/(1 - r) times it (Aitken, at
    // most 50), and the next slip starts a new pair.
    const Eigen::Vector3d slip = (pull - limit) / pull * dt;  // [m]
    double ahead = 1.0;
    const double previous = a.last_slip.squaredNorm();
    const double r = previous > 0.0 ? slip.dot(a.last_slip) / previous : 0.0;
    if (r > 0.0 && r < 1.0) {
      ahead = std::min(50.0, 1.0 / (1.0 - r));
      a.last_slip.setZero();
    } else {
      a.last_slip = slip;
    }
    a.point += ahead * slip;
    moved = std::max(moved, ahead * slip.norm());
    ++anchor_version_;
  }
  return moved;
}

double ClothProblem::ContactStepLimit(const Vertices& x, const Eigen::VectorXd& d) const {
  if (supports_.empty()) return 1.0;
  double depth = std::numeric_limits<double>::infinity();
  for (const Support& s : supports_) depth = std::min(depth, s.TunnelDepth());
  if (!std::isfinite(depth)) return 1.0;
  double alpha = 1.0;
  for (int i = 0; i < num_vertices(); ++i) {
    const double length = d.segment<3>(3 * i).norm();
    if (length == 0.0) continue;
    double phi = std::numeric_limits<double>::infinity();
    for (const Support& s : supports_) phi = std::min(phi, s.SignedDistance(x.row(i).transpose(), nullptr));
    const double allowed = std::max(phi, 0.0) + 0.5 * depth;
    if (length > allowed) alpha = std::min(alpha, allowed / length);
  }
  return alpha;
}

void ClothProblem::CarryAnchorsFrom(const ClothProblem& coarse,
                                    const std::vector<std::array<int, 2>>& parents) {
  const int old = coarse.num_vertices();
  if (old + static_cast<long>(parents.size()) != num_vertices())
    throw InputError("carried anchors: the mesh is not a refinement of the coarse one (" +
                     std::to_string(old) + " + " + std::to_string(parents.size()) + " vertices against " +
                     std::to_string(num_vertices()) + ")");
  if (coarse.supports_.size() != supports_.size())
    throw InputError("carried anchors: the coarse problem has " + std::to_string(coarse.supports_.size()) +
                     " supports, this one " + std::to_string(supports_.size()));
  for (const auto& [i, j] : parents)
    if (i < 0 || j < 0 || i >= old || j >= old)
      throw InputError("carried anchors: a split point's parent is not a coarse vertex");
  ++anchor_version_;
  for (int i = 0; i < old; ++i) {
    Anchor& a = anchors_[i];
    a = is_fixed_[i] ? Anchor{} : coarse.anchors_[i];
    // The same normal force on this mesh: the penalty scales with the node's lumped mass,
    // which a split changes (a quarter for a vertex whose triangles all split). The lag starts
    // afresh, so that the next updates go the whole way.
    if (coarse.penalty_(i) > 0.0) a.friction_force *= penalty_(i) / coarse.penalty_(i);
    a.lag_updates = 0;
  }
  for (size_t k = 0; k < parents.size(); ++k) {
    Anchor& a = anchors_[old + static_cast<int>(k)];
    a = Anchor{};
    const auto [i, j] = parents[k];
    const Anchor& ai = coarse.anchors_[i];
    const Anchor& aj = coarse.anchors_[j];
    if (is_fixed_[old + k] || ai.support < 0 || ai.support != aj.support || ai.sliding || aj.sliding) continue;
    Eigen::Vector3d n;
    Eigen::Vector3d point = 0.5 * (ai.point + aj.point);
    point -= supports_[ai.support].SignedDistance(point, &n) * n;
    a.support = ai.support;
    a.point = point;
    a.normal = n;
  }
}

void ClothProblem::ClearAnchors() {
  ++anchor_version_;
  for (Anchor& a : anchors_) a.support = -1;
}

int ClothProblem::num_anchors() const {
  return static_cast<int>(
      std::count_if(anchors_.begin(), anchors_.end(), [](const Anchor& a) { return a.support >= 0; }));
}

int ClothProblem::num_contacts(const Vertices& x) const {
  int count = 0;
  for (int i = 0; i < num_vertices(); ++i) {
    double phi;
    Eigen::Vector3d n;
    if (Touching(x.row(i).transpose(), 0.0, &phi, &n) >= 0) ++count;
  }
  return count;
}

double ClothProblem::FreeWeight() const {
  double w = 0.0;
  for (int i = 0; i < num_vertices(); ++i)
    if (!is_fixed_[i]) w += masses_(i);
  return w * options_.gravity.norm();
}

double ClothProblem::RelativeResidual(const Vertices& grad) const {
  double force2 = 0.0, weight2 = 0.0;
  const double g = options_.gravity.norm() > 0.0 ? options_.gravity.norm() : 9.80665;
  for (int i = 0; i < num_vertices(); ++i) {
    if (is_fixed_[i]) continue;
    force2 += grad.row(i).squaredNorm();
    weight2 += masses_(i) * masses_(i) * g * g;
  }
  if (weight2 <= 0.0) return 0.0;
  return std::sqrt(force2 / weight2);
}

}  // namespace textile
