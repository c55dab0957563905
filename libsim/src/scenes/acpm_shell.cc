#include "textile/sim/scenes/acpm_shell.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <sstream>

#include "textile/sim/elastica/cantilever_outputs.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

// Triangles of a tensor-product grid xs × ys (vertex (i, j) = i * ny1 + j), each cell split
// along one diagonal: alternating like a chequerboard, or the same one over each half of the
// width and mirrored between the halves. Both are mirror-symmetric across the width.
TriangleMesh TensorGrid(const std::vector<double>& xs, const std::vector<double>& ys,
                        bool alternate) {
  const int nx1 = static_cast<int>(xs.size()), ny1 = static_cast<int>(ys.size());
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<long>(nx1) * ny1, 3);
  for (int i = 0; i < nx1; ++i)
    for (int j = 0; j < ny1; ++j) mesh.vertices.row(i * ny1 + j) << xs[i], ys[j], 0.0;
  mesh.triangles.resize(2L * (nx1 - 1) * (ny1 - 1), 3);
  int f = 0;
  for (int i = 0; i + 1 < nx1; ++i) {
    for (int j = 0; j + 1 < ny1; ++j) {
      const int a = i * ny1 + j, b = (i + 1) * ny1 + j, c = (i + 1) * ny1 + j + 1,
                d = i * ny1 + j + 1;
      if (alternate ? (i + j) % 2 == 0 : 2 * j + 1 < ny1 - 1) {
        mesh.triangles.row(f++) << a, b, c;
        mesh.triangles.row(f++) << a, c, d;
      } else {
        mesh.triangles.row(f++) << a, b, d;
        mesh.triangles.row(f++) << b, c, d;
      }
    }
  }
  return mesh;
}

// Cells along the push over the reference overhang (at least 8).
int CellsAlong(double reference_overhang, double element_length) {
  return std::max(8, static_cast<int>(std::ceil(reference_overhang / element_length)));
}

// The settings with exactly twice the cells along of `settings` over the reference overhang
// (the Richardson extrapolation assumes the element halved).
ShellAcpmSettings HalvedSettings(const ShellAcpmSettings& settings, double reference_overhang) {
  ShellAcpmSettings half = settings;
  half.element_length = reference_overhang /
                        (2.0 * CellsAlong(reference_overhang, settings.element_length)) *
                        (1.0 + 1e-9);
  return half;
}

// A length [m] in mm for messages ("300", "342.5").
std::string MmText(double m) {
  std::ostringstream s;
  s.precision(4);
  s << units::MToMm(m);
  return s.str();
}

using Clock = std::chrono::steady_clock;

// The end of a whole run's time (ShellAcpmSettings::max_seconds from its start).
Clock::time_point DeadlineAfter(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(std::min(seconds, 1e7)));
}

// The material as the push bends it: along the warp, so a measured bias law takes no part
// (the curvature-tensor elements, the default, take none; the hinges would bend their diagonals
// with it, an artefact of the grid, not of the strip).
Material WarpStrip(const Material& material) {
  Material m = material;
  m.bending_bias.reset();
  return m;
}

// One push: the sample at a given overhang, its grid and its solver state.
class PushedSample {
 public:
  PushedSample(const Material& material, const AcpmOptions& options, const AcpmSeam& seam,
               const ShellAcpmSettings& settings, double reference_overhang,
               Clock::time_point deadline)
      : material_(WarpStrip(material)),
        options_(options),
        seam_(seam),
        settings_(settings),
        deadline_(deadline) {
    nx_ = CellsAlong(reference_overhang, settings.element_length);
    platform_ = reference_overhang / nx_;
    // A seam across gets a second platform row (below): the seam line may lie behind the edge.
    platform_rows_ = seam.direction == AcpmSeamDirection::kAcross ? 2 : 1;
    // Across the width: uniform, with the seam along the push direction on a grid line.
    const bool along = seam.direction == AcpmSeamDirection::kAlong;
    const int ny = along ? settings.width_cells_seam : settings.width_cells_plain;
    for (int j = 0; j <= ny; ++j) ys_.push_back(options.width * j / ny);
    if (along) {
      const double zs = std::isfinite(seam.position) ? seam.position : 0.5 * options.width;
      // A seam on (or within round-off of) a side edge runs along that edge's grid line; any
      // other seam moves the nearest inner line onto it (moving an inner line onto an edge
      // would leave a cell of zero width).
      const double snap = kEdgeSnap * options.width;
      if (std::abs(zs) <= snap) {
        seam_z_ = ys_.front();
      } else if (std::abs(zs - options.width) <= snap) {
        seam_z_ = ys_.back();
      } else {
        auto nearest = std::min_element(ys_.begin() + 1, ys_.end() - 1, [&](double a, double b) {
          return std::abs(a - zs) < std::abs(b - zs);
        });
        *nearest = zs;
        seam_z_ = zs;
      }
    }
  }

  // Solves the sample at overhang L, warm-started from the last solved state. False (with
  // *message) when the solver did not converge.
  bool Solve(double overhang, std::string* message) {
    std::vector<double> xs;
    if (platform_rows_ == 2) {
      // The seam across lies D behind the front, at x = L - D, which is behind the edge
      // (x < 0) until L reaches D. S(d) reaches d_max + fade (120 mm by default), so the hinges
      // past the edge are stiffened by a seam still on the platform: the platform reaches back
      // to the seam line (its second row, held like the first; one cell of the usual length
      // stays at the edge, so the edge's elements do not change).
      xs.push_back(std::min(overhang - seam_.position, -2.0 * platform_));
    }
    xs.push_back(-platform_);
    for (int i = 0; i <= nx_; ++i) xs.push_back(overhang * i / nx_);
    // The hinge energies need alternating diagonals (with one diagonal everywhere their
    // bend-twist coupling tilts the front across the width). The curvature tensor is exact on
    // a uniform split (there it is the mid-edge formula as well) but lets a chequerboard of
    // skinny cells fold along its zigzag diagonals almost for free (statics.md); it gets a
    // uniform split per half width, mirrored, so that mirror rays agree.
    TriangleMesh mesh = TensorGrid(xs, ys_, settings_.bending == BendingDiscretization::kHinge);
    std::vector<Seam> seams;
    if (seam_.direction == AcpmSeamDirection::kAlong) {
      SeamLine line(2, 2);
      line << -platform_, seam_z_, overhang, seam_z_;
      seams.push_back({seam_.profile, line});
    } else if (seam_.direction == AcpmSeamDirection::kAcross) {
      // On the overhang, or on the platform (then the platform's first row): either way the
      // hinges past the edge get S(d) by their distance d to the line (docs/spec/physics.md,
      // "Seams").
      SeamLine line(2, 2);
      line << overhang - seam_.position, 0.0, overhang - seam_.position, options_.width;
      seams.push_back({seam_.profile, line});
    }
    ClothOptions cloth;
    cloth.contact.friction = 0.0;
    cloth.discretization = settings_.bending;
    problem_ = std::make_unique<ClothProblem>(mesh, material_, seams, cloth);
    std::vector<int> held;
    for (int v = 0; v < mesh.num_vertices(); ++v)
      if (mesh.vertices(v, 0) <= 0.0) held.push_back(v);
    Vertices at(static_cast<long>(held.size()), 3);
    for (size_t k = 0; k < held.size(); ++k)
      at.row(static_cast<long>(k)) = mesh.vertices.row(held[k]);
    problem_->FixVertices(held, at);
    if (state_.rows() != mesh.num_vertices()) {
      state_ = mesh.vertices;
    } else {
      // Warm start: the last state, stretched along its own shape to the new length.
      const double scale = overhang / overhang_;
      for (int v = 0; v < state_.rows(); ++v)
        if (mesh.vertices(v, 0) > 0.0) state_.row(v) *= scale;
      // The held rows where this mesh has them (a seam across moves the platform's first row).
      for (int v : held) state_.row(v) = mesh.vertices.row(v);
    }
    // Each solve gets at most the run's time left (ShellAcpmSettings::max_seconds).
    const double left = std::chrono::duration<double>(deadline_ - Clock::now()).count();
    if (!(left > 0.0)) {
      *message = "shell model: time cap of " + std::to_string(settings_.max_seconds) +
                 " s (ShellAcpmSettings::max_seconds) reached after " + std::to_string(solves_) +
                 " static solves";
      return false;
    }
    SolveOptions solve = settings_.solve;
    solve.max_seconds = std::min(solve.max_seconds, left);
    const SolveSummary s = SolveStatic(problem_.get(), &state_, solve);
    ++solves_;
    overhang_ = overhang;
    mesh_ = std::move(mesh);
    if (!s.converged) {
      *message = "shell model: the static solve at overhang " +
                 std::to_string(units::MToMm(overhang)) + " mm did not converge: " + s.message;
      state_.resize(0, 3);  // a state that did not converge is not a warm start
      return false;
    }
    return true;
  }

  // Height of the front above the barrier plane at width position z [m] (negative: the ray is
  // cut). The plane holds the platform edge and descends at the barrier angle.
  double FrontOverBarrier(double z) const {
    const int ny1 = static_cast<int>(ys_.size());
    const int row = (static_cast<int>(mesh_.num_vertices()) / ny1) - 1;
    int j = 0;
    while (j + 2 < ny1 && ys_[j + 1] < z) ++j;
    const double t = std::clamp((z - ys_[j]) / (ys_[j + 1] - ys_[j]), 0.0, 1.0);
    const Eigen::Vector3d p = (1.0 - t) * state_.row(row * ny1 + j).transpose() +
                              t * state_.row(row * ny1 + j + 1).transpose();
    const double a = options_.barrier_angle;
    return std::sin(a) * p.x() + std::cos(a) * p.z();
  }

  // The side profile along the grid line nearest to z: (x, height) from the edge to the front.
  void SideProfile(double z, std::vector<double>* px, std::vector<double>* py) const {
    const int ny1 = static_cast<int>(ys_.size());
    int j = 0;
    for (int k = 1; k < ny1; ++k)
      if (std::abs(ys_[k] - z) < std::abs(ys_[j] - z)) j = k;
    px->clear();
    py->clear();
    for (int i = platform_rows_; i < mesh_.num_vertices() / ny1; ++i) {  // from the edge on
      px->push_back(state_(i * ny1 + j, 0));
      py->push_back(state_(i * ny1 + j, 2));
    }
  }

  int solves() const { return solves_; }
  int num_vertices() const { return mesh_.num_vertices(); }
  const Vertices& state() const { return state_; }
  // The overhanging part (x ≥ 0) of the last solved state as a mesh.
  TriangleMesh Overhang() const {
    TriangleMesh out;
    std::vector<int> index(mesh_.num_vertices(), -1);
    int n = 0;
    for (int v = 0; v < mesh_.num_vertices(); ++v)
      if (mesh_.vertices(v, 0) >= 0.0) index[v] = n++;
    out.vertices.resize(n, 3);
    for (int v = 0; v < mesh_.num_vertices(); ++v)
      if (index[v] >= 0) out.vertices.row(index[v]) = state_.row(v);
    std::vector<int> kept;
    for (int f = 0; f < mesh_.num_triangles(); ++f)
      if (index[mesh_.triangles(f, 0)] >= 0 && index[mesh_.triangles(f, 1)] >= 0 &&
          index[mesh_.triangles(f, 2)] >= 0)
        kept.push_back(f);
    out.triangles.resize(static_cast<long>(kept.size()), 3);
    for (size_t k = 0; k < kept.size(); ++k)
      for (int c = 0; c < 3; ++c)
        out.triangles(static_cast<long>(k), c) = index[mesh_.triangles(kept[k], c)];
    return out;
  }
  void Restore(const Vertices& state, double overhang) {
    state_ = state;
    overhang_ = overhang;
  }

 private:
  const Material material_;
  const AcpmOptions& options_;
  AcpmSeam seam_;
  ShellAcpmSettings settings_;
  // Seams closer than this fraction of the width to a side edge lie on the edge.
  static constexpr double kEdgeSnap = 1e-9;
  int nx_ = 0;
  double platform_ = 0.0;
  int platform_rows_ = 1;  // held rows behind the edge (x < 0)
  std::vector<double> ys_;
  double seam_z_ = 0.0;
  std::unique_ptr<ClothProblem> problem_;
  TriangleMesh mesh_;
  Clock::time_point deadline_;
  Vertices state_;
  double overhang_ = 1.0;
  int solves_ = 0;
};

struct Solved {
  std::vector<double> front;  // per ray, height over the barrier [m]
  Vertices state;
};

// Pushes until every ray is cut, then refines each ray's crossing.
AcpmCrossings Push(const Material& material, const AcpmOptions& options, const AcpmSeam& seam,
                   const std::vector<double>& ray_z, const ShellAcpmSettings& settings,
                   double reference, Clock::time_point deadline) {
  AcpmCrossings out;
  PushedSample sample(material, options, seam, settings, reference, deadline);
  std::map<double, Solved> solved;  // by overhang
  auto solve = [&](double overhang) -> const Solved* {
    // Warm start from the nearest solved overhang.
    if (!solved.empty()) {
      auto it = solved.lower_bound(overhang);
      if (it == solved.end() ||
          (it != solved.begin() && overhang - std::prev(it)->first < it->first - overhang))
        it = it == solved.begin() ? it : std::prev(it);
      sample.Restore(it->second.state, it->first);
    }
    if (!sample.Solve(overhang, &out.message)) return nullptr;
    Solved s{{}, sample.state()};
    for (double z : ray_z) s.front.push_back(sample.FrontOverBarrier(z));
    return &(solved[overhang] = std::move(s));
  };
  // Push in steps of 10 % of the reference until every ray is cut (or the sample ends).
  double overhang = 0.6 * reference;
  const double step = 0.1 * reference;
  for (;;) {
    const Solved* s = solve(overhang);
    if (!s) return out;
    if (*std::max_element(s->front.begin(), s->front.end()) <= 0.0) break;
    if (overhang >= options.length) {
      // Bad input, as for the plain fabric (ShellAcpmCrossings).
      throw InputError(std::string(seam.direction == AcpmSeamDirection::kNone
                                       ? "the fabric"
                                       : "the fabric with the seam") +
                       " does not reach the barrier within " + MmText(options.length) +
                       " mm (shell model): too stiff for a " + MmText(options.length) +
                       " mm sample on this tester");
    }
    overhang = std::min(overhang + step, options.length);
  }
  // Each ray: Illinois regula falsi between the last uncut and the first cut state.
  out.overhang.assign(ray_z.size(), 0.0);
  for (size_t r = 0; r < ray_z.size(); ++r) {
    double lo = 0.0, hi = 0.0, f_lo = 0.0, f_hi = 0.0;
    bool have_lo = false;
    for (const auto& [l, s] : solved) {
      if (s.front[r] > 0.0) {
        lo = l;
        f_lo = s.front[r];
        have_lo = true;
      } else {
        hi = l;
        f_hi = s.front[r];
        if (have_lo) break;
      }
    }
    if (!have_lo) {
      out.message = "shell model: ray " + std::to_string(r) + " is cut at the first push step";
      return out;
    }
    int side = 0;
    // Illinois converges superlinearly (4-8 solves per ray here); the cap only guards against
    // a bracket that floating point cannot narrow further.
    constexpr int kMaxRefinements = 60;
    for (int refinement = 0; hi - lo > options.crossing_tolerance; ++refinement) {
      if (refinement == kMaxRefinements) {
        out.message = "shell model: ray " + std::to_string(r) + "'s crossing did not narrow to " +
                      std::to_string(units::MToMm(options.crossing_tolerance)) + " mm in " +
                      std::to_string(kMaxRefinements) + " solves";
        return out;
      }
      double mid = hi - f_hi * (hi - lo) / (f_hi - f_lo);
      if (!(mid > lo && mid < hi)) mid = 0.5 * (lo + hi);
      const Solved* s = solve(mid);
      if (!s) return out;
      const double f = s->front[r];
      if (f > 0.0) {
        lo = mid;
        f_lo = f;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      } else {
        hi = mid;
        f_hi = f;
        if (side == 1) f_lo *= 0.5;
        side = 1;
      }
    }
    out.overhang[r] = hi - f_hi * (hi - lo) / (f_hi - f_lo);
  }
  // Side profile at the middle ray's crossing.
  out.profile_ray = static_cast<int>(ray_z.size() / 2);
  if (solve(out.overhang[out.profile_ray])) {
    sample.SideProfile(ray_z[out.profile_ray], &out.profile_x, &out.profile_y);
    out.shape = sample.Overhang();
  }
  out.solves = sample.solves();
  out.converged = true;
  std::ostringstream notes;
  notes << "shell: " << sample.num_vertices() << " vertices, element "
        << units::MToMm(settings.element_length) << " mm along the push, " << out.solves
        << " static solves";
  out.notes = notes.str();
  return out;
}

}  // namespace

bool ShellAcpmSettings::Check(std::string* why) const {
  if (!(element_length > 1e-5) || !std::isfinite(element_length)) {
    *why = "shell element length must be > 0.01 mm";
    return false;
  }
  if (width_cells_plain < 1 || width_cells_seam < 2) {
    *why = "shell width cells must be >= 1 (plain) and >= 2 (seam along)";
    return false;
  }
  if (!(std::isfinite(max_seconds) && max_seconds >= 0.0)) {
    *why = "shell max_seconds must be finite and >= 0";
    return false;
  }
  return solve.Check(why);
}

AcpmCrossings ShellAcpmCrossings(const Material& material, const AcpmOptions& options,
                                 const std::vector<double>& ray_z,
                                 const ShellAcpmSettings& settings) {
  std::string why;
  if (!settings.Check(&why)) throw InputError(why);
  if (!options.Check(&why)) throw InputError(why);
  const Clock::time_point deadline = DeadlineAfter(settings.max_seconds);
  // The plain fabric's exact crossing sets the scale of the grid and the push.
  // Within the sample's length (options.length), as the elastica model searches.
  CrossingOptions search;
  search.barrier_angle = options.barrier_angle;
  search.max_length = options.length;
  const BarrierCrossing plain_exact =
      FindBarrierCrossing(material.EffectiveLaw(), material.areal_density, search);
  if (!plain_exact.converged) {
    // Too stiff for the tester is bad input, as in the elastica model (acpm.h, RunAcpm).
    if (plain_exact.message.rfind("does not reach the barrier", 0) == 0)
      throw InputError("the fabric " + plain_exact.message + ": too stiff for a " +
                       MmText(options.length) + " mm sample on this tester");
    AcpmCrossings out;
    out.message = "shell model: " + plain_exact.message;
    return out;
  }
  const double reference = plain_exact.overhang;
  // One push, or two (element e and e/2) combined as 2 L(e/2) - L(e): the crossing converges
  // at first order in e (acpm-accuracy), so this cancels the leading error. *coarse: the push
  // at e alone.
  auto run = [&](const AcpmSeam& seam, const std::vector<double>& rays, AcpmCrossings* coarse) {
    *coarse = Push(material, options, seam, rays, settings, reference, deadline);
    if (!settings.extrapolate || !coarse->converged) return *coarse;
    const ShellAcpmSettings half = HalvedSettings(settings, reference);
    AcpmCrossings fine = Push(material, options, seam, rays, half, reference, deadline);
    if (!fine.converged) return fine;
    for (size_t r = 0; r < rays.size(); ++r)
      fine.overhang[r] = 2.0 * fine.overhang[r] - coarse->overhang[r];
    fine.solves += coarse->solves;
    std::ostringstream note;
    note << "; crossings extrapolated from elements of " << units::MToMm(settings.element_length)
         << " and " << units::MToMm(half.element_length) << " mm";
    fine.notes += note.str();
    return fine;
  };
  AcpmCrossings coarse;
  if (options.seam.direction == AcpmSeamDirection::kNone) return run(options.seam, ray_z, &coarse);
  // A seamed sample: one push at the element length (the costly one: the seam needs cells
  // across the width) and the plain fabric as above (2 cells across, cheap). The factor is the
  // ratio of the two at the same resolution, where the discretisation error cancels; the seamed
  // crossings get the plain run's extrapolation as a relative correction.
  AcpmCrossings result =
      Push(material, options, options.seam, ray_z, settings, reference, deadline);
  if (!result.converged) return result;
  const std::vector<double> centre = {0.5 * options.width};
  const AcpmCrossings plain = run(AcpmSeam{}, centre, &coarse);
  if (!plain.converged) {
    result.converged = false;
    result.message = "shell model: plain reference: " + plain.message;
    return result;
  }
  const double correction = plain.overhang.front() / coarse.overhang.front();
  if (correction != 1.0) {
    for (double& l : result.overhang) l *= correction;
    std::ostringstream note;
    note << "; seamed crossings scaled by the plain strip's extrapolation (x" << correction << ")";
    result.notes += note.str();
  }
  result.plain_overhang = plain.overhang.front();
  result.solves += plain.solves;
  return result;
}

namespace {

// The centre line of the plain sample at `overhang`, reached by continuation from 0.4 L in
// steps of 0.15 L, each warm-started from the last converged state; a step that fails is
// retried at half the length (down to 1 % of L). False with *message when it cannot get there.
bool CantileverAt(PushedSample* sample, double overhang, double width, std::vector<double>* x,
                  std::vector<double>* y, std::string* message) {
  double reached = 0.25 * overhang;  // nominally: the flat start
  double step = 0.15 * overhang;
  Vertices good;  // empty: start flat
  while (reached < overhang) {
    const double next = std::min(overhang, reached + step);
    if (sample->Solve(next, message)) {
      reached = next;
      good = sample->state();
      continue;
    }
    step *= 0.5;
    if (step < 0.01 * overhang) return false;
    sample->Restore(good, reached);
  }
  sample->SideProfile(0.5 * width, x, y);
  return true;
}

}  // namespace

ShellCantilever SolveShellCantilever(const Material& material, double overhang, double width,
                                     const ShellAcpmSettings& settings) {
  std::string why;
  if (!settings.Check(&why)) throw InputError(why);
  if (!(overhang > 0.0 && overhang <= 1.0))
    throw InputError("shell cantilever: overhang must lie in (0, 1000] mm");
  if (!(width > 0.0 && width <= 0.2))
    throw InputError("shell cantilever: width must lie in (0, 200] mm");
  AcpmOptions options;
  options.width = width;
  options.length = overhang;
  ShellCantilever out;
  const Clock::time_point deadline = DeadlineAfter(settings.max_seconds);
  PushedSample coarse(material, options, AcpmSeam{}, settings, overhang, deadline);
  if (!CantileverAt(&coarse, overhang, width, &out.x, &out.y, &out.message)) return out;
  out.solves = coarse.solves();
  out.vertices = coarse.num_vertices();
  std::ostringstream notes;
  notes << std::setprecision(2) << "elements "
        << units::MToMm(overhang / CellsAlong(overhang, settings.element_length)) << " mm along";
  if (settings.extrapolate) {
    const ShellAcpmSettings half = HalvedSettings(settings, overhang);
    PushedSample fine(material, options, AcpmSeam{}, half, overhang, deadline);
    std::vector<double> fx, fy;
    if (!CantileverAt(&fine, overhang, width, &fx, &fy, &out.message)) return out;
    // Fine vertex 2k is coarse vertex k's material point: extrapolate each to e -> 0.
    if (fx.size() != 2 * out.x.size() - 1) {
      out.message = "shell cantilever: the fine grid does not halve the coarse one";
      return out;
    }
    for (size_t k = 0; k < out.x.size(); ++k) {
      out.x[k] = 2.0 * fx[2 * k] - out.x[k];
      out.y[k] = 2.0 * fy[2 * k] - out.y[k];
    }
    out.solves += fine.solves();
    out.vertices = fine.num_vertices();
    notes << " and half that, extrapolated point by point";
  }
  out.notes = notes.str();
  out.converged = true;
  return out;
}

}  // namespace textile
