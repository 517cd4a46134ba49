#pragma once
// The uniform-strain (Voigt) estimate of the elastic constants of a bonded packing and its
// inversion for (kn, kt): Labra (4.10)-(4.19). It is an upper bound that dense packings of
// high coordination approach ("perfect agreement" in 2D, Labra section 4.2); the
// calibrator uses it as the starting point and prior of the stiffness maps.
//
//   C_ijkl = (1/V) sum_c l_i (kn n_j n_k + kt (delta_jk - n_j n_k)) l_l
//          = kn C^n_ijkl + kt C^t_ijkl                                   (4.10)-(4.17)
//   isotropic part: kn C^n_1111 + kt C^t_1111 = E (1 - nu) / ((1 + nu)(1 - 2 nu))   (4.18)
//                   kn C^n_1122 + kt C^t_1122 = E nu / ((1 + nu)(1 - 2 nu))        (4.19)
//
// In 2D the constants are those of plane strain (docs/lab.md, "Measurement": plane-strain
// E, nu are reported), per unit thickness (V = area x 1 m). The fabric sums are averaged over the symmetric
// orientations (1111 over the axes, 1122 over the pairs) so that a slightly anisotropic
// packing is identified by its isotropic part.

#include "generator/packing.h"

namespace specimen {

// The isotropic parts of C^n and C^t of a packing (units 1/m in 3D, dimensionless in 2D
// per unit thickness: sum of l^2 over the domain volume).
struct FabricStiffnessSums {
  double normal_1111 = 0.0;
  double normal_1122 = 0.0;
  double tangential_1111 = 0.0;
  double tangential_1122 = 0.0;
};

template <int Dim>
FabricStiffnessSums ComputeFabricStiffnessSums(const Packing<Dim>& packing);

struct ElasticConstants {
  double youngs_modulus_pa = 0.0;  // 2D: plane strain
  double poisson_ratio = 0.0;
};

// Voigt estimate for given contact stiffnesses [N/m].
ElasticConstants VoigtElasticConstants(const FabricStiffnessSums& sums, double normal_stiffness,
                                       double tangential_stiffness);

struct ContactStiffnesses {
  double normal_n_per_m = 0.0;
  double tangential_n_per_m = 0.0;
};

// Solves (4.18)-(4.19) for (kn, kt). Throws InputError when the target needs kt < 0 (nu
// above the packing's Voigt limit: 1/4 in 2D plane strain, 1/4 in 3D for isotropic fabric)
// or the system is singular, naming the limit.
ContactStiffnesses InvertVoigt(const FabricStiffnessSums& sums, const ElasticConstants& target);

}  // namespace specimen
