#include "calibrate/voigt_estimate.h"

#include <cmath>
#include <string>

#include "common/error.h"
#include "common/format.h"

namespace specimen {

template <int Dim>
FabricStiffnessSums ComputeFabricStiffnessSums(const Packing<Dim>& packing) {
  // sum over contacts of l_i n_j n_k l_l = |l|^2 n_i n_j n_k n_l (branch l = |l| n), and of
  // l_i (delta_jk - n_j n_k) l_l = |l|^2 (n_i n_l delta_jk - n_i n_j n_k n_l).
  double n1111 = 0.0, n1122 = 0.0, t1111 = 0.0, t1122 = 0.0;
  int axis_pairs = 0;
  for (const auto& c : packing.contacts) {
    const Vector<Dim> branch = packing.centres[c[1]] - packing.centres[c[0]];
    const double length_squared = branch.squaredNorm();
    if (length_squared == 0.0) continue;
    const Vector<Dim> n = branch / std::sqrt(length_squared);
    for (int a = 0; a < Dim; ++a) {
      const double aaaa = n[a] * n[a] * n[a] * n[a];
      n1111 += length_squared * aaaa;
      t1111 += length_squared * (n[a] * n[a] - aaaa);  // i = l = j = k = a
      for (int b = a + 1; b < Dim; ++b) {
        const double aabb = n[a] * n[a] * n[b] * n[b];
        n1122 += length_squared * aabb;
        // C^t_aabb = l_a (delta_ab - n_a n_b) l_b = -|l|^2 n_a^2 n_b^2
        t1122 -= length_squared * aabb;
      }
    }
  }
  axis_pairs = Dim * (Dim - 1) / 2;
  const double volume = packing.domain.Volume();
  FabricStiffnessSums sums;
  sums.normal_1111 = n1111 / (Dim * volume);
  sums.tangential_1111 = t1111 / (Dim * volume);
  sums.normal_1122 = n1122 / (axis_pairs * volume);
  sums.tangential_1122 = t1122 / (axis_pairs * volume);
  return sums;
}

ElasticConstants VoigtElasticConstants(const FabricStiffnessSums& sums, double kn, double kt) {
  // C1111 = lambda + 2 mu, C1122 = lambda (plane strain / 3D), then the usual conversion.
  const double c1111 = kn * sums.normal_1111 + kt * sums.tangential_1111;
  const double c1122 = kn * sums.normal_1122 + kt * sums.tangential_1122;
  const double lambda = c1122;
  const double mu = 0.5 * (c1111 - c1122);
  ElasticConstants e;
  e.poisson_ratio = lambda / (2.0 * (lambda + mu));
  e.youngs_modulus_pa = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
  return e;
}

ContactStiffnesses InvertVoigt(const FabricStiffnessSums& sums, const ElasticConstants& target) {
  const double e = target.youngs_modulus_pa, nu = target.poisson_ratio;
  const double scale = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double rhs_1111 = scale * (1.0 - nu), rhs_1122 = scale * nu;
  const double determinant =
      sums.normal_1111 * sums.tangential_1122 - sums.normal_1122 * sums.tangential_1111;
  if (std::abs(determinant) < 1e-14 * std::abs(sums.normal_1111 * sums.tangential_1111))
    throw InputError("the Voigt system (Labra 4.18-4.19) is singular for this packing");
  ContactStiffnesses k;
  k.normal_n_per_m = (rhs_1111 * sums.tangential_1122 - rhs_1122 * sums.tangential_1111) / determinant;
  k.tangential_n_per_m = (sums.normal_1111 * rhs_1122 - sums.normal_1122 * rhs_1111) / determinant;
  if (k.tangential_n_per_m < 0.0) {
    // The largest nu reachable with kt >= 0 is that of kt = 0.
    const double limit = VoigtElasticConstants(sums, 1.0, 0.0).poisson_ratio;
    throw InputError("poisson_ratio = " + Number(nu) +
                     " is beyond what rigid-particle contacts reach on this packing (Voigt limit " +
                     std::to_string(limit) + " at kt = 0); a deformable-particle (DDEM) model is needed");
  }
  return k;
}

template FabricStiffnessSums ComputeFabricStiffnessSums<2>(const Packing<2>&);
template FabricStiffnessSums ComputeFabricStiffnessSums<3>(const Packing<3>&);

}  // namespace specimen
