#include "solver/bond_moment.h"

namespace specimen {

template <int Dim>
double BondRotationalStiffness(double radius_i, double radius_j, double radius_ratio, double kn,
                               double kt) {
  const BondSection<Dim> s = BondSectionOf<Dim>(radius_i, radius_j, radius_ratio, kn, kt);
  return std::max(s.bending_stiffness, s.twisting_stiffness);
}

template <int Dim>
double BondMomentElasticEnergy(const ContactArrays<Dim>& c, const std::vector<double>& radius,
                               double radius_ratio, double kn, double kt) {
  if (!c.has_bond_moments()) return 0.0;
  double energy = 0.0;
  for (int k = 0; k < c.size(); ++k) {
    if (c.state[k] != ContactState::kBonded) continue;  // a broken bond carries no moment
    const auto [i, j] = c.pair[k];
    const BondSection<Dim> section = BondSectionOf<Dim>(radius[i], radius[j], radius_ratio, kn, kt);
    energy += BondMomentEnergy<Dim>(c.bond_moment[k], c.normal[k], section);
  }
  return energy;
}

template double BondRotationalStiffness<2>(double, double, double, double, double);
template double BondRotationalStiffness<3>(double, double, double, double, double);
template double BondMomentElasticEnergy<2>(const ContactArrays<2>&, const std::vector<double>&,
                                           double, double, double);
template double BondMomentElasticEnergy<3>(const ContactArrays<3>&, const std::vector<double>&,
                                           double, double, double);

}  // namespace specimen
