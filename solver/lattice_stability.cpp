#include "solver/lattice_stability.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace specimen {

LatticeStability AnalyseLatticeStability(const TriangleLattice& lattice, const std::vector<double>& masses,
                                         const LanczosOptions& options) {
  const int nodes = static_cast<int>(masses.size());
  std::vector<double> inverse_root(nodes, 0.0);  // M^-1/2, 0 for massless nodes
  int with_mass = 0;
  for (int i = 0; i < nodes; ++i) {
    if (!(masses[i] >= 0.0)) throw InputError("node " + std::to_string(i) + " has a negative mass");
    if (masses[i] > 0.0) inverse_root[i] = 1.0 / std::sqrt(masses[i]), ++with_mass;
  }
  if (with_mass == 0) throw InputError("no lattice node has mass");
  for (const auto& v : lattice.nodes)
    for (int i : v)
      if (i < 0 || i >= nodes) throw InputError("a triangle names node " + std::to_string(i) + ", beyond the masses");

  std::vector<Eigen::Matrix<double, 6, 6>> stiffness(lattice.size());
  for (int t = 0; t < lattice.size(); ++t) stiffness[t] = CartesianTriangleStiffness(lattice, t);

  LatticeStability out;
  // Gershgorin: omega^2 <= max_i sum_j |A_ij| for A = M^-1/2 K M^-1/2.
  std::vector<double> row(2 * nodes, 0.0);
  for (int t = 0; t < lattice.size(); ++t)
    for (int a = 0; a < 6; ++a) {
      const int ia = lattice.nodes[t][a / 2];
      for (int b = 0; b < 6; ++b)
        row[2 * ia + a % 2] += std::abs(stiffness[t](a, b)) * inverse_root[ia] * inverse_root[lattice.nodes[t][b / 2]];
    }
  const double gershgorin = *std::max_element(row.begin(), row.end());
  out.gershgorin_time_step_s = gershgorin > 0.0 ? 2.0 / std::sqrt(gershgorin) : 0.0;

  const SymmetricOperator apply = [&](const std::vector<double>& x, std::vector<double>& y) {
    std::fill(y.begin(), y.end(), 0.0);
    Eigen::Matrix<double, 6, 1> local;
    for (int t = 0; t < lattice.size(); ++t) {
      const std::array<int, 3>& v = lattice.nodes[t];
      for (int a = 0; a < 6; ++a) local[a] = x[2 * v[a / 2] + a % 2] * inverse_root[v[a / 2]];
      const Eigen::Matrix<double, 6, 1> f = stiffness[t] * local;
      for (int a = 0; a < 6; ++a) y[2 * v[a / 2] + a % 2] += f[a] * inverse_root[v[a / 2]];
    }
  };
  out.lanczos = LargestEigenvalue(2 * nodes, apply, options);
  // The exact top of the spectrum cannot exceed Gershgorin's bound: take the smaller.
  out.omega_max_squared = std::min(out.lanczos.certified_upper_bound, gershgorin);
  out.critical_time_step_s = 2.0 / std::sqrt(out.omega_max_squared);
  return out;
}

}  // namespace specimen
