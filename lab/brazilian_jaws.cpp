#include "lab/brazilian_jaws.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Dense>

#include "common/error.h"
#include "common/format.h"

namespace specimen {

namespace {
constexpr double kPi = 3.14159265358979323846;
// A particle is on the surface when its gap to the circle is within this share of its
// radius (generated packings touch their boundary to 1e-3 r; the next layer lies a radius in).
constexpr double kSurfaceGapShare = 0.05;
}  // namespace

double HondrosFactor(double loading_arc_deg) {
  const double a = 0.5 * loading_arc_deg * kPi / 180.0;
  return a > 0.0 ? (std::sin(2.0 * a) - a) / std::sin(a) : 1.0;
}

template <int Dim>
std::array<JawArc<Dim>, 2> BrazilianJawArcs(const Packing<Dim>& packing, double loading_arc_deg) {
  const Domain<Dim>& domain = packing.domain;
  const DomainShape shape = domain.shape();
  if (shape != DomainShape::kDisc && shape != DomainShape::kCylinder)
    throw InputError("a loading arc needs a disc (2D) or cylinder (3D) specimen; the domain is a " +
                     domain.ShapeName());
  if (!(loading_arc_deg > 0.0 && loading_arc_deg <= 60.0))
    throw InputError("loading_arc = " + Number(loading_arc_deg) + ": must be in (0, 60] (degrees, the jaw's arc 2 alpha)");
  const double alpha = 0.5 * loading_arc_deg * kPi / 180.0;
  const Vector<2> centre = domain.CircleCentre();
  const double radius = domain.CircleRadius();
  // The surface particles by angle (from +x, counter-clockwise). A particle held by fewer
  // than Dim contacts of the packing (a rattler) is left out: pressed alone, nothing holds it
  // (a 3D jaw drove one through the disc).
  std::vector<int> contacts(packing.size(), 0);
  for (const auto& pair : packing.contacts)
    for (const int q : pair) ++contacts[q];
  std::vector<std::pair<double, int>> around;
  for (int q = 0; q < packing.size(); ++q) {
    if (contacts[q] < Dim) continue;
    const Vector<2> r(packing.centres[q].x() - centre.x(), packing.centres[q].y() - centre.y());
    const double gap = radius - (r.norm() + packing.radii[q]);
    if (gap <= kSurfaceGapShare * packing.radii[q] && r.norm() > 0.0) around.push_back({std::atan2(r.y(), r.x()), q});
  }
  std::sort(around.begin(), around.end());
  const int m = static_cast<int>(around.size());
  std::array<JawArc<Dim>, 2> jaws;
  for (int k = 0; k < m; ++k) {
    const int q = around[k].second;
    const Vector<2> r(packing.centres[q].x() - centre.x(), packing.centres[q].y() - centre.y());
    if (std::atan2(std::abs(r.x()), std::abs(r.y())) > alpha) continue;
    double share;
    if constexpr (Dim == 2) {
      // Half the angle to each neighbour on the surface, clipped to the arc: the angles from
      // the pole, unwrapped about this particle's.
      const double pole = r.y() > 0.0 ? 0.5 * kPi : -0.5 * kPi;
      auto from_pole = [&](double angle) { return std::remainder(angle - pole, 2.0 * kPi); };
      const double here = from_pole(around[k].first);
      const double before = here - std::abs(std::remainder(around[k].first - around[(k + m - 1) % m].first, 2.0 * kPi));
      const double after = here + std::abs(std::remainder(around[(k + 1) % m].first - around[k].first, 2.0 * kPi));
      share = std::min(alpha, 0.5 * (here + after)) - std::max(-alpha, 0.5 * (before + here));
      if (!(share > 0.0)) continue;  // (m = 1: no neighbour; cannot happen on a disc's surface)
    } else {
      share = kPi * packing.radii[q] * packing.radii[q];
    }
    JawArc<Dim>& jaw = jaws[r.y() > 0.0 ? 1 : 0];
    Vector<Dim> inward = Vector<Dim>::Zero();
    inward.x() = -r.x() / r.norm();
    inward.y() = -r.y() / r.norm();
    jaw.particles.push_back(q);
    jaw.weights.push_back(share);
    jaw.inward.push_back(inward);
  }
  // The jaws press a free body: their forces must balance whatever F is. Radial forces in
  // the disc's plane have no moment about its axis, but a net lateral force sum w n_x, and in
  // 3D the moments of the forces about the centre's x and y axes (sum w n_y (z - z_m) and
  // sum w n_x (z - z_m), z_m the mid-length), would push the disc out of the
  // jaws (a 3D disc slid away at a third of its strength). The shares are corrected to the
  // nearest balanced ones, w_k = w0_k (1 + lambda . g_k), g_k those quantities.
  constexpr int kConditions = Dim == 2 ? 1 : 3;
  const double z_mid = Dim == 3 ? 0.5 * (domain.Lower()[Dim - 1] + domain.Upper()[Dim - 1]) : 0.0;
  for (int side = 0; side < 2; ++side) {
    JawArc<Dim>& jaw = jaws[side];
    const std::string where = std::string("the loading arc of ") + Number(loading_arc_deg) + " degrees at the " +
                              (side == 1 ? "top" : "bottom") + " of the disc";
    if (jaw.particles.empty()) throw InputError(where + " holds no surface particle; widen it or use a finer packing");
    auto conditions = [&](size_t k) {
      Eigen::VectorXd g(kConditions);
      g[0] = jaw.inward[k].x();
      if constexpr (Dim == 3) {
        const double dz = packing.centres[jaw.particles[k]].z() - z_mid;
        g[1] = jaw.inward[k].y() * dz;
        g[2] = jaw.inward[k].x() * dz;
      }
      return g;
    };
    Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(kConditions, kConditions);
    Eigen::VectorXd residual = Eigen::VectorXd::Zero(kConditions);
    for (size_t k = 0; k < jaw.particles.size(); ++k) {
      const Eigen::VectorXd g = conditions(k);
      normal += jaw.weights[k] * g * g.transpose();
      residual += jaw.weights[k] * g;
    }
    const Eigen::VectorXd lambda = -normal.completeOrthogonalDecomposition().solve(residual);
    double total = 0.0;
    for (size_t k = 0; k < jaw.particles.size(); ++k) {
      jaw.weights[k] *= 1.0 + lambda.dot(conditions(k));
      if (!(jaw.weights[k] > 0.0))
        throw InputError(where + " holds too few surface particles (" + std::to_string(jaw.particles.size()) +
                         ") to balance its forces; widen it or use a finer packing");
      total += jaw.weights[k];
    }
    for (double& w : jaw.weights) w /= total;
  }
  return jaws;
}

template std::array<JawArc<2>, 2> BrazilianJawArcs<2>(const Packing<2>&, double);
template std::array<JawArc<3>, 2> BrazilianJawArcs<3>(const Packing<3>&, double);

}  // namespace specimen
