#include "textile/sim/mesh/mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

double TriangleArea(const TriangleMesh& m, int f) {
  const Eigen::Vector3d a = m.vertices.row(m.triangles(f, 0));
  const Eigen::Vector3d b = m.vertices.row(m.triangles(f, 1));
  const Eigen::Vector3d c = m.vertices.row(m.triangles(f, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

// Directed edge (a, b) of triangle f -> which triangle and its third vertex.
struct EdgeUse {
  int face;
  int opposite;
};

}  // namespace

Eigen::VectorXd TriangleAreas(const TriangleMesh& m) {
  Eigen::VectorXd a(m.num_triangles());
  for (int f = 0; f < m.num_triangles(); ++f) a(f) = TriangleArea(m, f);
  return a;
}

void CheckMesh(const TriangleMesh& m) {
  const int nv = m.num_vertices(), nf = m.num_triangles();
  if (nf == 0) throw InputError("mesh: no triangles");
  for (int i = 0; i < nv; ++i) {
    if (!m.vertices.row(i).allFinite()) {
      throw InputError("mesh: vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
    }
  }
  std::vector<int> used(nv, 0);
  for (int f = 0; f < nf; ++f) {
    const auto t = m.triangles.row(f);
    for (int k = 0; k < 3; ++k) {
      if (t(k) < 0 || t(k) >= nv) {
        throw InputError("mesh: triangle " + std::to_string(f) + " refers to vertex " +
                         std::to_string(t(k)) + ", outside 0.." + std::to_string(nv - 1));
      }
      ++used[t(k)];
    }
    if (t(0) == t(1) || t(1) == t(2) || t(0) == t(2)) {
      throw InputError("mesh: triangle " + std::to_string(f) + " repeats a vertex");
    }
  }
  for (int i = 0; i < nv; ++i) {
    if (!used[i]) throw InputError("mesh: vertex " + std::to_string(i) + " is used by no triangle");
  }
  const Eigen::VectorXd areas = TriangleAreas(m);
  const double mean_area = areas.mean();
  for (int f = 0; f < nf; ++f) {
    if (!(areas(f) > 1e-12 * mean_area)) {
      std::ostringstream s;
      s << "mesh: triangle " << f << " is degenerate (area " << areas(f) << " m²)";
      throw InputError(s.str());
    }
  }
  // Duplicate vertices: sort by x and compare neighbours within the tolerance.
  const double diag = (m.vertices.colwise().maxCoeff() - m.vertices.colwise().minCoeff()).norm();
  const double tol = 1e-9 * std::max(diag, 1e-300);
  std::vector<int> order(nv);
  for (int i = 0; i < nv; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return m.vertices(a, 0) < m.vertices(b, 0); });
  for (int a = 0; a < nv; ++a) {
    for (int b = a + 1; b < nv && m.vertices(order[b], 0) - m.vertices(order[a], 0) <= tol; ++b) {
      if ((m.vertices.row(order[a]) - m.vertices.row(order[b])).norm() <= tol) {
        throw InputError("mesh: vertices " + std::to_string(std::min(order[a], order[b])) + " and " +
                         std::to_string(std::max(order[a], order[b])) + " coincide (duplicate vertex)");
      }
    }
  }
  // Manifold edges with consistent orientation: each directed edge at most once, each
  // undirected edge at most twice.
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = m.triangles(f, k), b = m.triangles(f, (k + 1) % 3);
      if (directed.count({a, b})) {
        const int g = directed[{a, b}];
        throw InputError("mesh: edge (" + std::to_string(a) + ", " + std::to_string(b) +
                         ") of triangles " + std::to_string(g) + " and " + std::to_string(f) +
                         " is oriented the same way in both (flipped triangle or non-manifold)");
      }
      directed[{a, b}] = f;
    }
  }
  std::map<std::pair<int, int>, int> undirected;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = m.triangles(f, k), b = m.triangles(f, (k + 1) % 3);
      if (++undirected[{std::min(a, b), std::max(a, b)}] > 2) {
        throw InputError("mesh: edge (" + std::to_string(std::min(a, b)) + ", " +
                         std::to_string(std::max(a, b)) +
                         ") is shared by more than two triangles (non-manifold), e.g. triangle " +
                         std::to_string(f));
      }
    }
  }
}

std::vector<Hinge> BuildHinges(const TriangleMesh& m) {
  std::map<std::pair<int, int>, EdgeUse> directed;
  for (int f = 0; f < m.num_triangles(); ++f) {
    for (int k = 0; k < 3; ++k) {
      directed[{m.triangles(f, k), m.triangles(f, (k + 1) % 3)}] = {f, m.triangles(f, (k + 2) % 3)};
    }
  }
  std::vector<Hinge> hinges;
  for (const auto& [edge, use] : directed) {
    const auto [a, b] = edge;
    if (a > b) continue;  // visit each interior edge once, from its (small, large) direction
    const auto other = directed.find({b, a});
    if (other == directed.end()) continue;
    // Triangle (a, b, o0) holds directed edge a->b; wing v0 = o0 with edge (v2, v3) = (a, b) so
    // that (v0, v2, v3) = (o0, a, b) is a cyclic shift of the triangle's own order.
    Hinge h;
    h.v = {use.opposite, other->second.opposite, a, b};
    h.faces = {use.face, other->second.face};
    hinges.push_back(h);
  }
  return hinges;
}

std::vector<std::array<int, 2>> BoundaryEdges(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < m.num_triangles(); ++f) {
    for (int k = 0; k < 3; ++k) directed[{m.triangles(f, k), m.triangles(f, (k + 1) % 3)}] = f;
  }
  std::vector<std::array<int, 2>> out;
  for (const auto& [edge, f] : directed) {
    (void)f;
    if (!directed.count({edge.second, edge.first})) out.push_back({edge.first, edge.second});
  }
  return out;
}

Vertices RefinedMesh::Prolong(const Vertices& x) const {
  const long old = mesh.vertices.rows() - static_cast<long>(parents.size());
  if (x.rows() != old)
    throw InputError("prolong: " + std::to_string(x.rows()) + " positions for a mesh of " +
                     std::to_string(old) + " vertices");
  Vertices out(mesh.vertices.rows(), 3);
  out.topRows(old) = x;
  for (size_t i = 0; i < parents.size(); ++i)
    out.row(old + static_cast<long>(i)) = 0.5 * (x.row(parents[i][0]) + x.row(parents[i][1]));
  return out;
}

RefinedMesh RefineTriangles(const TriangleMesh& m, const std::vector<bool>& marked) {
  const int nf = m.num_triangles();
  if (static_cast<int>(marked.size()) != nf)
    throw InputError("refine: " + std::to_string(marked.size()) + " flags for " +
                     std::to_string(nf) + " triangles");
  auto key = [](int a, int b) { return a < b ? std::make_pair(a, b) : std::make_pair(b, a); };
  // Edges to split; closure: a triangle with two split edges gets its third split too.
  std::map<std::pair<int, int>, int> split;  // edge -> new vertex id (assigned below)
  std::vector<bool> red(marked);
  for (int f = 0; f < nf; ++f)
    if (red[f])
      for (int k = 0; k < 3; ++k) split[key(m.triangles(f, k), m.triangles(f, (k + 1) % 3))] = -1;
  for (bool changed = true; changed;) {
    changed = false;
    for (int f = 0; f < nf; ++f) {
      if (red[f]) continue;
      int count = 0;
      for (int k = 0; k < 3; ++k)
        count += split.count(key(m.triangles(f, k), m.triangles(f, (k + 1) % 3))) ? 1 : 0;
      if (count >= 2) {
        red[f] = true;
        changed = true;
        for (int k = 0; k < 3; ++k) split[key(m.triangles(f, k), m.triangles(f, (k + 1) % 3))] = -1;
      }
    }
  }
  RefinedMesh r;
  const int nv = m.num_vertices();
  int next = nv;
  for (auto& [edge, id] : split) {
    id = next++;
    r.parents.push_back({edge.first, edge.second});
  }
  r.mesh.vertices.resize(next, 3);
  r.mesh.vertices.topRows(nv) = m.vertices;
  for (size_t i = 0; i < r.parents.size(); ++i)
    r.mesh.vertices.row(nv + static_cast<long>(i)) =
        0.5 * (m.vertices.row(r.parents[i][0]) + m.vertices.row(r.parents[i][1]));
  std::vector<std::array<int, 3>> tris;
  for (int f = 0; f < nf; ++f) {
    const int a = m.triangles(f, 0), b = m.triangles(f, 1), c = m.triangles(f, 2);
    auto mid = [&](int p, int q) {
      const auto it = split.find(key(p, q));
      return it == split.end() ? -1 : it->second;
    };
    const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    auto add = [&](int p, int q, int s) {
      tris.push_back({p, q, s});
      r.parent_triangle.push_back(f);
    };
    if (red[f]) {
      add(a, ab, ca);
      add(ab, b, bc);
      add(ca, bc, c);
      add(ab, bc, ca);
    } else if (ab >= 0) {
      add(a, ab, c);
      add(ab, b, c);
    } else if (bc >= 0) {
      add(b, bc, a);
      add(bc, c, a);
    } else if (ca >= 0) {
      add(c, ca, b);
      add(ca, a, b);
    } else {
      add(a, b, c);
    }
  }
  r.mesh.triangles.resize(static_cast<long>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) r.mesh.triangles(static_cast<long>(t), k) = tris[t][k];
  return r;
}

TriangleMesh RegularGridMesh(double width, double height, int nx, int ny) {
  if (!(width > 0) || !(height > 0) || nx < 1 || ny < 1) {
    throw InputError("grid mesh: sizes must be > 0 and cell counts >= 1");
  }
  TriangleMesh m;
  m.vertices.resize((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.vertices.row(j * (nx + 1) + i) << width * i / nx, height * j / ny, 0.0;
  m.triangles.resize(2 * nx * ny, 3);
  int f = 0;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      m.triangles.row(f++) << a, b, d;
      m.triangles.row(f++) << a, d, c;
    }
  }
  return m;
}

TriangleMesh CrissCrossGridMesh(double width, double height, int nx, int ny) {
  if (!(width > 0) || !(height > 0) || nx < 1 || ny < 1) {
    throw InputError("grid mesh: sizes must be > 0 and cell counts >= 1");
  }
  TriangleMesh m;
  const int corners = (nx + 1) * (ny + 1);
  m.vertices.resize(corners + nx * ny, 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.vertices.row(j * (nx + 1) + i) << width * i / nx, height * j / ny, 0.0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      m.vertices.row(corners + j * nx + i) << width * (i + 0.5) / nx, height * (j + 0.5) / ny, 0.0;
  m.triangles.resize(4 * nx * ny, 3);
  int f = 0;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1, o = corners + j * nx + i;
      m.triangles.row(f++) << a, b, o;
      m.triangles.row(f++) << b, d, o;
      m.triangles.row(f++) << d, c, o;
      m.triangles.row(f++) << c, a, o;
    }
  }
  return m;
}

}  // namespace textile
