#pragma once
// Dimensionless micro-macro groups (Labra 4.20-4.59, Madan 4.7-4.14). The calibrator's
// maps are tables of these groups against the micro ratios (kt/kn, Rt/Rn, mu, kn/(Ep l),
// nu_p): with global contact constants, E scales with kn (2D) or kn / r (3D) and strengths
// with Rn / r (2D) or Rn / r^2 (3D), so a map built on one packing holds for any kn, Rn.
//
// The "improved" groups normalise by the packing's coordination and solid fraction:
//   Psi_E = E r~ / (kn nc (1 - e))          (4.49, 4.54)
//   Psi_c = sigma_c A~ / (Rn nc (1 - e))     (4.56)
//   Psi_t = sigma_t A~ / (Rn nc (1 - e))     (4.57)
// with the characteristic radius and area
//   3D: r~ = 4 <r^3> / <l^2> [m]   (4.51),   A~ = 2 <r^3> / <l> [m^2]        (4.59)
//   2D: r~ = 4 <r^2> / <l^2> [-]   (4.53),   A~ = 2 <r^2> t / <l> [m^2], t = 1 m (4.58)
// (Labra's 2D worked example quotes r~ as a length, 0.15365 mm, that behaves like A~/t;
// the definitions above are used consistently for building and inverting the maps, so the
// groups are self-consistent whatever the printed convention.)
// 2D quantities are per unit thickness: kn in N/m (per m of thickness), Rn in N.

#include <nlohmann/json_fwd.hpp>

#include "generator/metrics.h"

namespace specimen {

// What the groups need from a packing, and what identifies the packing a map was built on.
struct PackingDescriptors {
  int dimension = 2;
  int particles = 0;
  double porosity = 0.0;          // nominal e (Labra 3.13)
  double coordination = 0.0;      // nc = 2 Nc / Np
  double mean_radius = 0.0;       // volume-based r_bar [m]
  double radius_ratio = 0.0;
  double mean_radius_squared = 0.0;          // <r^2> [m^2]
  double mean_radius_cubed = 0.0;            // <r^3> [m^3]
  double mean_branch_length = 0.0;           // <l> [m]
  double mean_branch_length_squared = 0.0;   // <l^2> [m^2]

  double CharacteristicRadius() const;  // r~ (4.51, 4.53)
  double CharacteristicArea() const;    // A~ [m^2] (4.58, 4.59)
  double SolidCoordination() const { return coordination * (1.0 - porosity); }  // nc (1 - e)
};

template <int Dim>
PackingDescriptors DescribePacking(const PackingMetrics<Dim>& metrics);

nlohmann::json DescriptorsToJson(const PackingDescriptors& d);
PackingDescriptors DescriptorsFromJson(const nlohmann::json& j);

// Improved groups and their inverses (what the calibrator solves for).
double ElasticGroup(const PackingDescriptors& d, double youngs_modulus_pa, double normal_stiffness);
double NormalStiffnessFromElasticGroup(const PackingDescriptors& d, double youngs_modulus_pa,
                                       double elastic_group);
double StrengthGroup(const PackingDescriptors& d, double strength_pa, double bond_tensile_strength_n);
double BondStrengthFromStrengthGroup(const PackingDescriptors& d, double strength_pa,
                                     double strength_group);

// Particle density that keeps the specimen's mass (Labra, "scaled density"): rho / (1 - e).
double ScaledDensity(double density_kg_per_m3, double porosity);

}  // namespace specimen
