#include "generator/hole_filling.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace specimen {

template <int Dim>
bool ApolloniusSphere(const std::vector<Vector<Dim>>& sphere_centres,
                      const std::vector<double>& sphere_radii,
                      const std::vector<Vector<Dim>>& plane_points,
                      const std::vector<Vector<Dim>>& plane_normals, Vector<Dim>* centre,
                      double* radius) {
  const size_t spheres = sphere_centres.size();
  if (spheres < 1 || spheres + plane_points.size() != static_cast<size_t>(Dim + 1)) return false;
  // Tangency to sphere k: |c - p_k|^2 = (rho + s_k)^2. Subtracting the equation of sphere
  // 0 from the others leaves equations linear in (c, rho); a plane (w, n) gives the linear
  // equation (w - c).n = rho. Solve the Dim linear equations for c = c0 + c1 rho, then the
  // quadratic of sphere 0 for rho.
  Eigen::Matrix<double, Dim, Dim> a;
  Vector<Dim> b0, b1;
  const Vector<Dim>& p0 = sphere_centres[0];
  const double s0 = sphere_radii[0];
  int row = 0;
  for (size_t k = 1; k < spheres; ++k, ++row) {
    const Vector<Dim>& p = sphere_centres[k];
    const double s = sphere_radii[k];
    // -2 c.(p - p0) + |p|^2 - |p0|^2 - 2 rho (s - s0) - (s^2 - s0^2) = 0
    a.row(row) = 2.0 * (p - p0).transpose();
    b0[row] = p.squaredNorm() - p0.squaredNorm() - (s * s - s0 * s0);
    b1[row] = -2.0 * (s - s0);
  }
  for (size_t k = 0; k < plane_points.size(); ++k, ++row) {
    // c.n = w.n - rho
    a.row(row) = plane_normals[k].transpose();
    b0[row] = plane_points[k].dot(plane_normals[k]);
    b1[row] = -1.0;
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, Dim, Dim>> lu(a);
  if (!lu.isInvertible()) return false;
  const Vector<Dim> c0 = lu.solve(b0);
  const Vector<Dim> c1 = lu.solve(b1);
  // |c0 + c1 rho - p0|^2 = (rho + s0)^2
  const Vector<Dim> d = c0 - p0;
  const double qa = c1.squaredNorm() - 1.0;
  const double qb = 2.0 * (c1.dot(d) - s0);
  const double qc = d.squaredNorm() - s0 * s0;
  double best = -1.0;
  auto consider = [&](double rho) {
    if (rho > 0.0 && std::isfinite(rho) && (best < 0.0 || rho < best)) best = rho;
  };
  if (std::abs(qa) < 1e-14) {
    if (qb != 0.0) consider(-qc / qb);
  } else {
    const double discriminant = qb * qb - 4.0 * qa * qc;
    if (discriminant < 0.0) return false;
    const double root = std::sqrt(discriminant);
    // Numerically stable pair of roots.
    const double q = -0.5 * (qb + (qb >= 0.0 ? root : -root));
    if (q != 0.0) consider(qc / q);
    consider(q / qa);
  }
  if (best <= 0.0) return false;
  *centre = c0 + c1 * best;
  *radius = best;
  return true;
}

template <int Dim>
int FillHoles(const Domain<Dim>& domain, const ContactGraph<Dim>& graph,
              const HoleFillingOptions& options, std::vector<Vector<Dim>>& x,
              std::vector<double>& r) {
  const int n = static_cast<int>(x.size());
  const auto& facets = domain.Facets();
  // Particle adjacency (compressed rows) for the overlap check of a candidate.
  std::vector<int> offsets(n + 1, 0), neighbours;
  for (const auto& e : graph.edges) ++offsets[e[0] + 1], ++offsets[e[1] + 1];
  for (int i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
  neighbours.resize(offsets[n]);
  {
    std::vector<int> fill(offsets.begin(), offsets.end() - 1);
    for (const auto& e : graph.edges) {
      neighbours[fill[e[0]]++] = e[1];
      neighbours[fill[e[1]]++] = e[0];
    }
  }

  struct Candidate {
    double radius;
    Vector<Dim> centre;
    std::array<int, Dim + 1> particles;  // real particles of the simplex (-1 = none)
  };
  std::vector<Candidate> candidates;
  for (const auto& cell : graph.cells) {
    std::vector<Vector<Dim>> sphere_centres, plane_points, plane_normals;
    std::vector<double> sphere_radii;
    std::vector<int> planar_facets;
    std::array<int, Dim + 1> particles;
    particles.fill(-1);
    Eigen::Matrix<double, Dim, Dim + 1> corners;  // simplex vertices (mirrors for ghosts)
    bool usable = true;
    for (int k = 0; k <= Dim && usable; ++k) {
      const GraphSite& site = cell[k];
      corners.col(k) = site.facet < 0 ? x[site.particle]
                                      : domain.Mirror(domain.Facets()[site.facet], x[site.particle]);
      if (site.facet < 0) {
        particles[k] = site.particle;
        sphere_centres.push_back(x[site.particle]);
        sphere_radii.push_back(r[site.particle]);
        continue;
      }
      const BoundaryFacet<Dim>& facet = facets[site.facet];
      if (facet.kind == FacetKind::kPlane) {
        // The same plane twice: the simplex lies beyond the wall.
        if (std::find(planar_facets.begin(), planar_facets.end(), site.facet) != planar_facets.end())
          usable = false;
        planar_facets.push_back(site.facet);
        plane_points.push_back(facet.point);
        plane_normals.push_back(facet.normal);
      } else {
        // Curved wall: the mirror image stands in for it (tangent to it at the wall).
        sphere_centres.push_back(domain.Mirror(facet, x[site.particle]));
        sphere_radii.push_back(r[site.particle]);
      }
    }
    if (!usable || sphere_centres.empty()) continue;
    Candidate candidate;
    if (!ApolloniusSphere<Dim>(sphere_centres, sphere_radii, plane_points, plane_normals,
                               &candidate.centre, &candidate.radius))
      continue;
    if (candidate.radius < options.min_radius) continue;
    // The sphere must sit in this simplex's hole: its centre inside the simplex.
    Eigen::Matrix<double, Dim + 1, Dim + 1> barycentric_system;
    barycentric_system.template topRows<Dim>() = corners;
    barycentric_system.row(Dim).setOnes();
    Eigen::Matrix<double, Dim + 1, 1> point;
    point << candidate.centre, 1.0;
    const Eigen::Matrix<double, Dim + 1, 1> weights = barycentric_system.fullPivLu().solve(point);
    if (weights.minCoeff() < -1e-9) continue;
    candidate.radius = std::min(candidate.radius, options.max_radius);
    if (domain.SignedDistance(candidate.centre) < candidate.radius * (1.0 - 1e-9)) continue;
    candidate.particles = particles;
    candidates.push_back(candidate);
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.radius > b.radius; });

  std::vector<char> touched(n, 0);
  int inserted = 0;
  for (const Candidate& c : candidates) {
    if (inserted >= options.max_insertions) break;
    // One insertion per neighbourhood per call: a later candidate next to a new particle
    // was computed without it.
    bool fresh = true;
    for (int p : c.particles)
      if (p >= 0 && touched[p]) fresh = false;
    if (!fresh) continue;
    bool clear = true;
    for (int p : c.particles) {
      if (p < 0) continue;
      auto overlaps = [&](int j) {
        return (x[j] - c.centre).norm() < r[j] + c.radius - 1e-9 * c.radius;
      };
      if (overlaps(p)) clear = false;
      for (int k = offsets[p]; k < offsets[p + 1] && clear; ++k)
        if (overlaps(neighbours[k])) clear = false;
    }
    if (!clear) continue;
    for (int p : c.particles) {
      if (p < 0) continue;
      touched[p] = 1;
      for (int k = offsets[p]; k < offsets[p + 1]; ++k) touched[neighbours[k]] = 1;
    }
    x.push_back(c.centre);
    r.push_back(c.radius);
    ++inserted;
  }
  return inserted;
}

template bool ApolloniusSphere<2>(const std::vector<Vector<2>>&, const std::vector<double>&,
                                  const std::vector<Vector<2>>&, const std::vector<Vector<2>>&,
                                  Vector<2>*, double*);
template bool ApolloniusSphere<3>(const std::vector<Vector<3>>&, const std::vector<double>&,
                                  const std::vector<Vector<3>>&, const std::vector<Vector<3>>&,
                                  Vector<3>*, double*);
template int FillHoles<2>(const Domain<2>&, const ContactGraph<2>&, const HoleFillingOptions&,
                          std::vector<Vector<2>>&, std::vector<double>&);
template int FillHoles<3>(const Domain<3>&, const ContactGraph<3>&, const HoleFillingOptions&,
                          std::vector<Vector<3>>&, std::vector<double>&);

}  // namespace specimen
