#pragma once
// The bonded-particle material: global contact constants (Labra 2012, section 2.3: the
// same kn, kt, Rn, Rt, mu for every contact, not scaled by radius), particle density,
// damping, and the optional DDEM particle elasticity (Madan 2019, section 2.4). Also the
// particle compliance D_p of Madan (2.46)-(2.49) and its inverse.
//
// Units are SI. 2D quantities are per unit thickness l = 1 m: kn, kt in N/m, strengths in
// N (per metre of thickness), Ep in Pa.

#include <limits>
#include <optional>
#include <string>

#include "solver/vector_algebra.h"

namespace specimen {

// How a 2D DDEM particle deforms out of plane (Madan (2.48) and (2.49)). Ignored in 3D.
enum class PlaneModel { kPlaneStrain, kPlaneStress };

std::string PlaneModelName(PlaneModel model);

struct MaterialParameters {
  // --- Contact law (Labra (2.32)-(2.37), Madan (2.25)-(2.40)) ---
  // Normal contact stiffness kn [N/m], > 0.
  double normal_stiffness_n_per_m = 0.0;
  // Tangential contact stiffness kt [N/m], >= 0. 0 = no tangential force at all (no
  // tangential history, no friction, no rotation from contacts).
  double tangential_stiffness_n_per_m = 0.0;
  // Bond tensile strength Rn [N], > 0; a bond breaks when its elastic normal force exceeds
  // it (Labra (2.34)). Infinity = unbreakable in tension.
  double bond_tensile_strength_n = std::numeric_limits<double>::infinity();
  // Bond shear strength Rt [N], > 0; a bond breaks when |ft| exceeds it (Labra (2.35)).
  // Infinity = unbreakable in shear.
  double bond_shear_strength_n = std::numeric_limits<double>::infinity();
  // Coulomb friction coefficient mu of unbonded contacts, >= 0 (Labra (2.21)-(2.23)).
  double friction_coefficient = 0.0;
  // Bond radius over the smaller particle radius, lambda in [0, 1]. 0: Labra's contact bond
  // (no moment); > 0: the bond also resists relative rotation and fails on the peripheral
  // stress of its section (bond_moment.h, after Potyondy & Cundall 2004).
  double bond_radius_ratio = 0.0;
  // Interaction range of bonding, gamma in [1, 1.5]. 1: the packing's contact pairs are the
  // bonds; > 1: every pair whose centres lie within gamma (ri + rj) is bonded too, at its
  // initial distance (bond_range.h, as Yade's interactionDetectionFactor).
  double bond_range = 1.0;

  // --- Particles ---
  // Particle density rho [kg/m^3], > 0. 2D: m = rho pi R^2 l with l = 1 m.
  double density_kg_per_m3 = 0.0;
  // DDEM particle Young's modulus Ep [Pa], > 0. Absent = rigid particles (plain DEM, no
  // DDEM stage in the step).
  std::optional<double> particle_youngs_modulus_pa;
  // DDEM particle Poisson ratio nu_p, in (-1, 0.5).
  double particle_poisson_ratio = 0.0;
  // 2D particle model: plane strain (Madan's lattice studies) or plane stress (his FEM
  // two-particle check). 3D particles are isotropic elastic balls.
  PlaneModel plane_model = PlaneModel::kPlaneStrain;

  // --- Damping ---
  // Non-viscous local damping alpha_t, alpha_r in [0, 1) (Madan (2.7)-(2.8)).
  double translational_damping = 0.0;
  double rotational_damping = 0.0;
  // Contact dashpots as a fraction xi of the pair's critical damping
  // c_cr = 2 sqrt(m_i m_j k / (m_i + m_j)) (Madan (2.33)-(2.37)), >= 0. They lower the
  // critical time step by sqrt(1 + xi^2) - xi (Labra (2.53)).
  double normal_dashpot_ratio = 0.0;
  double tangential_dashpot_ratio = 0.0;

  // --- Inertia scaling (quasi-static runs) ---
  // Share of the total mass that may be added to the particles that limit the time step,
  // in [0, 0.05]; 0 = every particle has its true mass. The critical step is set by the
  // lightest, stiffest particles (2 sqrt(m / k_eff), Madan (2.18)): in a polydisperse packing
  // a few small ones. Raising their inertia to that of the limit a larger share reaches
  // (PFC's density scaling, restricted to those few) lengthens the step at the cost of their
  // own dynamics; quasi-static results do not depend on inertia. See particles.h.
  double mass_scaling_budget = 0.0;

  bool deformable() const { return particle_youngs_modulus_pa.has_value(); }
  bool bonds_carry_moments() const { return bond_radius_ratio > 0.0; }
  bool breakable() const {
    return std::isfinite(bond_tensile_strength_n) ||
           (tangential_stiffness_n_per_m > 0.0 && std::isfinite(bond_shear_strength_n));
  }

  // Names the first invalid field, its value and the allowed range.
  bool IsValid(std::string* error) const;
  // The ranges of a physical material, checked where the particle size is known: the
  // stiffness modulus kn / L (L = 1 m thickness in 2D, the volume-mean radius in 3D) in
  // [1 Pa, 1e16 Pa] (gels to far beyond diamond), Ep >= 1 Pa, density in [0.1, 1e13] kg/m^3
  // (room for density scaling). Outside them a run is a typo: the time step and the
  // energies lose every digit (kn = 1e-300) or overflow (kn = 1e300).
  bool IsPhysical(double length_m, std::string* error) const;
};

// The linear isotropic compliance of a DDEM particle, eps = D sigma (Madan (2.46)), in the
// compact tensor form of vector_algebra.h:
//   eps_ii = a sigma_ii + b sum_{j != i} sigma_jj,   eps_ij = c sigma_ij (i != j)
// 2D plane strain (2.48): a = (1 - nu^2)/E, b = -nu (1 + nu)/E, c = (1 + nu)/E;
// 2D plane stress (2.49): a = 1/E, b = -nu/E, c = (1 + nu)/E; 3D: as plane stress, three
// normal components (beyond the thesis: the same assumptions in three dimensions).
template <int Dim>
class ParticleCompliance {
 public:
  // Zero compliance: rigid particles.
  ParticleCompliance() = default;
  ParticleCompliance(double youngs_modulus_pa, double poisson_ratio, PlaneModel plane_model);

  SymmetricTensor<Dim> Strain(const SymmetricTensor<Dim>& stress) const {
    // eps_ii = (a - b) sigma_ii + b tr(sigma), eps_ij = c sigma_ij.
    SymmetricTensor<Dim> strain;
    double trace = 0.0;
    for (int k = 0; k < Dim; ++k) trace += stress[k];
    for (int k = 0; k < Dim; ++k) strain[k] = (normal_ - coupling_) * stress[k] + coupling_ * trace;
    for (int k = Dim; k < kVoigtSize<Dim>; ++k) strain[k] = shear_ * stress[k];
    return strain;
  }
  // The inverse map, sigma = D^-1 eps (in-plane components in 2D). Rigid: not defined.
  SymmetricTensor<Dim> Stress(const SymmetricTensor<Dim>& strain) const;
  bool rigid() const { return shear_ == 0.0; }
  // The largest eigenvalue of D acting on symmetric tensors (Frobenius norm): the bound of
  // |(n (x) n) : D : (m (x) m)| for unit n, m. max(a - b, a + (Dim - 1) b, c).
  double LargestEigenvalue() const;

 private:
  double normal_ = 0.0;    // a
  double coupling_ = 0.0;  // b
  double shear_ = 0.0;     // c
};

}  // namespace specimen
