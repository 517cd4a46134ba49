#pragma once
// Closed-form convergence limits of the DDEM force iteration on regular packings of equal
// particles (Madan 2019, sections 3.4-3.6: (3.27), (3.42), (3.78)), the references the
// stability analysis prints next to the limit of the actual packing.
//
// 2D (discs, thickness l), plane strain, limits on kn/(Ep l) (rho(B) = 1):
//   row  (3.27): 4 kn (1 - nu^2) / (pi Ep l) < 1   ->  pi / (4 (1 - nu^2))
//   SC   (3.42): 4 kn (1 + nu) / (pi Ep l) < 1     ->  pi / (4 (1 + nu))
//   HCP  (3.78): max{3, 6 (1 - 2 nu)} kn (1 + nu) / (pi Ep l) < 1
// Plane stress (Ep, nu) has the compliance of plane strain (Ep', nu') with nu' = nu/(1 + nu),
// Ep' = Ep (1 - nu'^2) [derived: equal a, b, c in Madan (2.48)/(2.49)], so the plane-strain
// limit L(nu') on kn/(Ep' l) is the limit (1 - nu'^2) L(nu') on kn/(Ep l).
// 3D (spheres, beyond the thesis, derived the same way with V = 4/3 pi R^3 and
// D = isotropic Hooke), limits on kn/(Ep R):
//   row: sigma_xx = 2 R f / V, h_c = h + 2 R eps_xx:  B = 3 kn / (pi Ep R)  ->  pi/3
//   simple cubic: B = 3 kn/(pi Ep R) [[1,-nu,-nu],[-nu,1,-nu],[-nu,-nu,1]], eigenvalues
//   (1 + nu) (deviatoric, twice) and (1 - 2 nu) (hydrostatic)  ->  pi / (3 max(1 + nu, 1 - 2 nu))
//   (no 3D close-packed formula is given; reported as not available).

#include "solver/material.h"

namespace specimen {

struct LatticeLimits {
  // Limits on kn/(Ep l) (2D) or kn/(Ep R) (3D) at rho(B) = 1; NaN where not available.
  double row = 0.0;
  double square = 0.0;     // SC (2D square lattice, 3D simple cubic)
  double hexagonal = 0.0;  // HCP (2D only)
};

// The lattice limits for a particle Poisson ratio nu_p in (-1, 0.5).
LatticeLimits ClosedFormLimits(int dimension, double poisson_ratio, PlaneModel plane_model);

}  // namespace specimen
