#include "textile/sim/elements/contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

bool Finite(const Eigen::Vector3d& v) { return v.allFinite(); }

// Signed distance of a point q (in the frame of a rounded box/cylinder profile) where q holds the
// per-axis excess over the inner core: the classic "rounded box" formula
//   d = |max(q, 0)| + min(max_i q_i, 0) - r.
// grad_axes receives ∂d/∂q (a unit vector); the caller maps it back through the axis signs.
template <int N>
double RoundedCoreDistance(const Eigen::Matrix<double, N, 1>& q, double r,
                           Eigen::Matrix<double, N, 1>* grad_q) {
  const Eigen::Matrix<double, N, 1> outside = q.cwiseMax(0.0);
  const double out_norm = outside.norm();
  if (out_norm > 0.0) {
    *grad_q = outside / out_norm;
    return out_norm - r;
  }
  int axis = 0;
  const double inner = q.maxCoeff(&axis);
  grad_q->setZero();
  (*grad_q)(axis) = 1.0;
  return inner - r;
}

}  // namespace

Support Support::Plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  if (!Finite(point) || !Finite(normal) || normal.norm() < 1e-12)
    throw InputError("plane support: point and normal must be finite, the normal non-zero");
  Support s;
  s.kind = Kind::kPlane;
  s.center = point;
  s.normal = normal.normalized();
  return s;
}

Support Support::Box(const Eigen::Vector3d& center, const Eigen::Vector3d& half_extents,
                     double rounding) {
  if (!Finite(center) || !Finite(half_extents) || half_extents.minCoeff() <= 0.0)
    throw InputError("box support: centre and half extents must be finite, the extents > 0");
  if (!std::isfinite(rounding) || rounding < 0.0 || rounding > half_extents.minCoeff())
    throw InputError("box support: rounding must be in [0, smallest half extent]");
  Support s;
  s.kind = Kind::kBox;
  s.center = center;
  s.half_extents = half_extents;
  s.rounding = rounding;
  return s;
}

Support Support::Disk(const Eigen::Vector3d& top_center, double radius, double thickness,
                      double rounding) {
  if (!Finite(top_center) || !std::isfinite(radius) || !std::isfinite(thickness) ||
      radius <= 0.0 || thickness <= 0.0)
    throw InputError("disk support: centre, radius and thickness must be finite, sizes > 0");
  if (!std::isfinite(rounding) || rounding < 0.0 || rounding > 0.5 * thickness ||
      rounding > radius)
    throw InputError("disk support: rim rounding must be in [0, min(thickness/2, radius)]");
  Support s;
  s.kind = Kind::kDisk;
  s.center = top_center;
  s.radius = radius;
  s.thickness = thickness;
  s.rounding = rounding;
  return s;
}

double Support::SignedDistance(const Eigen::Vector3d& p, Eigen::Vector3d* normal) const {
  switch (kind) {
    case Kind::kPlane: {
      if (normal) *normal = this->normal;
      return this->normal.dot(p - center);
    }
    case Kind::kBox: {
      const Eigen::Vector3d rel = p - center;
      const Eigen::Vector3d q =
          rel.cwiseAbs() - (half_extents - Eigen::Vector3d::Constant(rounding));
      Eigen::Vector3d g;
      const double d = RoundedCoreDistance<3>(q, rounding, &g);
      if (normal) {
        for (int c = 0; c < 3; ++c) g(c) *= rel(c) < 0.0 ? -1.0 : 1.0;
        *normal = g;
      }
      return d;
    }
    case Kind::kDisk: {
      // Profile coordinates: radial distance from the axis, height from the mid-plane.
      const Eigen::Vector3d rel = p - (center - Eigen::Vector3d(0, 0, 0.5 * thickness));
      const double rho = std::hypot(rel.x(), rel.y());
      const Eigen::Vector2d q(rho - (radius - rounding),
                              std::abs(rel.z()) - (0.5 * thickness - rounding));
      Eigen::Vector2d g;
      const double d = RoundedCoreDistance<2>(q, rounding, &g);
      if (normal) {
        const Eigen::Vector2d radial =
            rho > 0.0 ? Eigen::Vector2d(rel.x() / rho, rel.y() / rho) : Eigen::Vector2d(1.0, 0.0);
        *normal = Eigen::Vector3d(g(0) * radial.x(), g(0) * radial.y(),
                                  g(1) * (rel.z() < 0.0 ? -1.0 : 1.0));
      }
      return d;
    }
  }
  return 0.0;
}

double Support::TunnelDepth() const {
  switch (kind) {
    case Kind::kPlane:
      return std::numeric_limits<double>::infinity();
    case Kind::kBox:
      return half_extents.minCoeff();
    case Kind::kDisk:
      return 0.5 * thickness;
  }
  return 0.0;
}

std::string Support::Describe() const {
  std::ostringstream out;
  switch (kind) {
    case Kind::kPlane:
      out << "plane through (" << center.transpose() << ") m, normal (" << normal.transpose()
          << ")";
      break;
    case Kind::kBox:
      out << "box " << 2 * half_extents.x() << " x " << 2 * half_extents.y() << " x "
          << 2 * half_extents.z() << " m at (" << center.transpose() << ")";
      break;
    case Kind::kDisk:
      out << "disk radius " << radius << " m, top at (" << center.transpose() << ") m";
      break;
  }
  return out.str();
}

bool ContactOptions::Check(std::string* why) const {
  if (!(sink_under_own_weight > 0.0) || !std::isfinite(sink_under_own_weight)) {
    *why = "contact sink_under_own_weight must be > 0 and finite";
    return false;
  }
  if (!(friction >= 0.0) || friction > 10.0) {
    *why = "friction coefficient must be in [0, 10]";
    return false;
  }
  if (!(tangential_ratio > 0.0) || !std::isfinite(tangential_ratio)) {
    *why = "contact tangential_ratio must be > 0 and finite";
    return false;
  }
  if (!(anchor_keep_distance >= 0.0) || !std::isfinite(anchor_keep_distance)) {
    *why = "contact anchor_keep_distance must be >= 0 and finite";
    return false;
  }
  if (!(slip_excess >= 0.0 && slip_excess <= 1.0)) {
    *why = "contact slip_excess must lie in [0, 1]";
    return false;
  }
  return true;
}

}  // namespace textile
