#include "solver/material.h"
#include "common/format.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace specimen {

std::string PlaneModelName(PlaneModel model) {
  return model == PlaneModel::kPlaneStrain ? "plane strain" : "plane stress";
}

bool MaterialParameters::IsValid(std::string* error) const {
  auto fail = [&](const std::string& field, double value, const std::string& range) {
    if (error) *error = field + " = " + Number(value) + " is not allowed: it must be " + range;
    return false;
  };
  if (!(normal_stiffness_n_per_m > 0.0) || !std::isfinite(normal_stiffness_n_per_m))
    return fail("normal_stiffness_n_per_m (kn)", normal_stiffness_n_per_m, "finite and > 0");
  if (!(tangential_stiffness_n_per_m >= 0.0) || !std::isfinite(tangential_stiffness_n_per_m))
    return fail("tangential_stiffness_n_per_m (kt)", tangential_stiffness_n_per_m,
                "finite and >= 0");
  if (!(bond_tensile_strength_n > 0.0))
    return fail("bond_tensile_strength_n (Rn)", bond_tensile_strength_n,
                "> 0 (infinity = unbreakable)");
  if (!(bond_shear_strength_n > 0.0))
    return fail("bond_shear_strength_n (Rt)", bond_shear_strength_n,
                "> 0 (infinity = unbreakable)");
  if (!(friction_coefficient >= 0.0) || !std::isfinite(friction_coefficient))
    return fail("friction_coefficient (mu)", friction_coefficient, "finite and >= 0");
  if (!(bond_radius_ratio >= 0.0 && bond_radius_ratio <= 1.0))
    return fail("bond_radius_ratio (lambda)", bond_radius_ratio,
                "in [0, 1] (0: bonds without moment)");
  if (!(bond_range >= 1.0 && bond_range <= 1.5))
    return fail("bond_range (gamma)", bond_range, "in [1, 1.5] (1: the packing's contacts are the bonds)");
  if (!(density_kg_per_m3 > 0.0) || !std::isfinite(density_kg_per_m3))
    return fail("density_kg_per_m3", density_kg_per_m3, "finite and > 0");
  // Above 10 the tangential springs set the time step while the normal ones set the loading
  // rates: a typo (kt for kn) there asks for billions of steps.
  if (!(tangential_stiffness_n_per_m <= 10.0 * normal_stiffness_n_per_m))
    return fail("tangential_stiffness_n_per_m (kt)", tangential_stiffness_n_per_m,
                "at most 10 kn = " + Number(10.0 * normal_stiffness_n_per_m) + " (kt/kn <= 10)");
  if (particle_youngs_modulus_pa.has_value() &&
      (!(*particle_youngs_modulus_pa > 0.0) || std::isnan(*particle_youngs_modulus_pa)))
    return fail("particle_youngs_modulus_pa (Ep)", *particle_youngs_modulus_pa,
                "> 0 (leave it unset for rigid particles)");
  if (!(particle_poisson_ratio > -1.0 && particle_poisson_ratio < 0.5))
    return fail("particle_poisson_ratio (nu_p)", particle_poisson_ratio, "in (-1, 0.5)");
  if (!(translational_damping >= 0.0 && translational_damping < 1.0))
    return fail("translational_damping (alpha_t)", translational_damping, "in [0, 1)");
  if (!(rotational_damping >= 0.0 && rotational_damping < 1.0))
    return fail("rotational_damping (alpha_r)", rotational_damping, "in [0, 1)");
  if (!(normal_dashpot_ratio >= 0.0) || !std::isfinite(normal_dashpot_ratio))
    return fail("normal_dashpot_ratio (xi_n)", normal_dashpot_ratio, "finite and >= 0");
  if (!(tangential_dashpot_ratio >= 0.0) || !std::isfinite(tangential_dashpot_ratio))
    return fail("tangential_dashpot_ratio (xi_t)", tangential_dashpot_ratio, "finite and >= 0");
  if (!(mass_scaling_budget >= 0.0 && mass_scaling_budget <= 0.05))
    return fail("mass_scaling_budget", mass_scaling_budget, "in [0, 0.05]");
  return true;
}

bool MaterialParameters::IsPhysical(double length_m, std::string* error) const {
  auto fail = [&](const std::string& what, double value, const std::string& range) {
    if (error) *error = what + " = " + Number(value) + " is not allowed: it must be " + range;
    return false;
  };
  constexpr double kLowestModulus = 1.0, kHighestModulus = 1e16;  // Pa
  const double modulus = normal_stiffness_n_per_m / length_m;
  if (!(modulus >= kLowestModulus && modulus <= kHighestModulus))
    return fail("normal_stiffness_n_per_m (kn)", normal_stiffness_n_per_m,
                "in [" + Number(kLowestModulus * length_m) + ", " + Number(kHighestModulus * length_m) +
                    "] N/m here (kn / L in [1 Pa, 1e16 Pa], L = " + Number(length_m) + " m)");
  // No upper bound on Ep: Ep -> infinity is the rigid limit, a legitimate check of DDEM.
  if (particle_youngs_modulus_pa && !(*particle_youngs_modulus_pa >= kLowestModulus))
    return fail("particle_youngs_modulus_pa (Ep)", *particle_youngs_modulus_pa, ">= 1 Pa");
  if (!(density_kg_per_m3 >= 0.1 && density_kg_per_m3 <= 1e13))
    return fail("density_kg_per_m3", density_kg_per_m3, "in [0.1, 1e13] kg/m^3");
  return true;
}

template <int Dim>
ParticleCompliance<Dim>::ParticleCompliance(double youngs_modulus_pa, double poisson_ratio,
                                            PlaneModel plane_model) {
  const double e = youngs_modulus_pa, nu = poisson_ratio;
  if (Dim == 2 && plane_model == PlaneModel::kPlaneStrain) {
    // Madan (2.48).
    normal_ = (1.0 - nu * nu) / e;
    coupling_ = -nu * (1.0 + nu) / e;
  } else {
    // Madan (2.49); 3D isotropic Hooke.
    normal_ = 1.0 / e;
    coupling_ = -nu / e;
  }
  shear_ = (1.0 + nu) / e;
}

template <int Dim>
SymmetricTensor<Dim> ParticleCompliance<Dim>::Stress(const SymmetricTensor<Dim>& strain) const {
  // The normal block is (a - b) I + b J (J: all ones), whose inverse is
  // I/(a - b) - b J / ((a - b)(a + (Dim - 1) b)).
  const double a = normal_, b = coupling_;
  const double diagonal = 1.0 / (a - b);
  const double ones = -b / ((a - b) * (a + (Dim - 1) * b));
  SymmetricTensor<Dim> stress;
  double trace = 0.0;
  for (int k = 0; k < Dim; ++k) trace += strain[k];
  for (int k = 0; k < Dim; ++k) stress[k] = diagonal * strain[k] + ones * trace;
  for (int k = Dim; k < kVoigtSize<Dim>; ++k) stress[k] = strain[k] / shear_;
  return stress;
}

template <int Dim>
double ParticleCompliance<Dim>::LargestEigenvalue() const {
  return std::max({normal_ - coupling_, normal_ + (Dim - 1) * coupling_, shear_});
}

template class ParticleCompliance<2>;
template class ParticleCompliance<3>;

}  // namespace specimen
