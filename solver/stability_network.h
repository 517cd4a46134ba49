#pragma once
// The linearised bonded network of a scene: what the stability limits (stability_limits.h)
// take eigenvalues of. Built once from the packing and the scene, then
// applied matrix-free (one loop over the links, one gather over the particles; OpenMP above
// 4096 items, the result independent of the thread count).
//
// Degrees of freedom: Dim translations per particle, plus the rotations (1 in 2D, 3 in 3D) when a
// link has a tangential spring (otherwise rotations carry no stiffness and are left out); one
// translation along its normal per force-driven wall. Axes that FixedDofs prescribe (held or
// velocity-driven) are removed. Masses: M = diag(m, J) (Madan (2.3)-(2.4)), the wall mass.
//
// Links (the springs of the linear system, linearised about the packing's geometry):
//  - every pair of the packing's contact list: the Simulation makes each either a bond or an
//    unbonded contact; both are counted as linear springs kn (normal) and kt (tangential).
//    An unbonded pair in compression acts exactly so; one that opens carries nothing, and
//    leaving out a spring can only lower omega_max and rho(B) (Weyl monotonicity: every link
//    adds a positive semi-definite term), so counting it is on the safe side;
//  - particle-wall contacts: particles whose gap to a wall plane is at most
//    contacts.bond_gap_tolerance x R (touching or nearly; or below a given reach: the
//    Simulation passes its search skin, the walls' candidates), normal stiffness k_wall, tangential
//    k_t,wall for walls with friction (the solver's wall law has no tangential spring
//    otherwise); a velocity-driven wall is ground, a force-driven wall a degree of freedom;
//  - a particle left without any link (a rattler) gets one to its nearest neighbour within
//    the solver's neighbour-search skin (it can touch it), as the per-particle bound counts one
//    contact for it (time_step.h).
// Contact kinematics (Madan (2.30)-(2.32)): with n the unit normal i -> j (towards the wall for
// a wall link) and the arms s_i = R_i n, s_j = -R_j n, the relative displacement of the contact
// point is d = (u_j + theta_j x s_j) - (u_i + theta_i x s_i); the normal spring acts on n.d,
// the tangential spring on d - (n.d) n, so K = sum_links kn b_n b_n^T + kt B_t^T B_t.
// Moment-carrying bonds (bond_moment.h) add, on every pair of the packing's contact list, the
// rotational spring K_b = kb (I - n n^T) + kw n n^T (2D: kb) on theta_j - theta_i.
//
// The DDEM force iteration (Madan (2.41)-(2.54), (3.8)-(3.13); docs/stability.md, "DDEM
// convergence: rho(B)"): a particle's strain is eps_p = D_p (1/V_p) sym(sum_c s_c (x) F_c)
// over its links (wall forces included, with the arm -R normal, as the solver does; point
// loads are constant and do not enter the iteration), and the normal gap of link c is
// corrected by -sum_p R_p n_c.eps_p.n_c. For normal forces this is f <- A - B f with
// B = K_n M, M_cd = sum_{p in c, d} (R_p^2/V_p)(n_c n_c):D_p:(n_d n_d) symmetric positive
// semi-definite, so rho(B) = lambda_max(S), S = K_n^1/2 M K_n^1/2.

#include <array>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "solver/material.h"
#include "solver/scene.h"
#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
class LinearisedNetwork {
 public:
  static constexpr int kRotations = Dim == 2 ? 1 : 3;
  static constexpr int kNodeDofs = Dim + kRotations;

  // Throws InputError (naming the item) for an invalid scene or packing: indices out of range,
  // a contact joining a particle to itself or two particles with the same centre.
  // wall_reach_m >= 0: particles within this gap of a wall are linked to it (the solver's
  // wall candidates: the search skin); < 0: within contacts.bond_gap_tolerance x R.
  LinearisedNetwork(const Packing<Dim>& packing, const SceneOptions<Dim>& scene,
                    double wall_reach_m = -1.0);

  // --- Sizes and facts ---
  int dof_count() const { return dof_count_; }
  int particle_count() const { return static_cast<int>(radius_.size()); }
  int link_count() const { return static_cast<int>(link_i_.size()); }
  int contact_links() const { return contact_links_; }  // from the packing's list
  int wall_links() const { return wall_links_; }
  int rattler_links() const { return rattler_links_; }
  int rattlers_without_neighbour() const { return rattlers_alone_; }
  int fixed_dofs() const { return fixed_dofs_; }
  bool has_rotation() const { return rotation_; }
  bool has_tangential() const { return tangential_; }
  // Whether links carry bending (and in 3D twisting) springs: bonds with a moment.
  bool has_bending() const { return bending_; }
  // Particles are numbered internally along a space-filling curve (locality of the products);
  // the accessors below take and return the caller's numbering.
  double radius(int particle) const { return radius_[internal_index(particle)]; }
  // The particle (caller's numbering) owning scaled degree of freedom `dof` (-1: a wall's).
  int DofOwner(int dof) const {
    return dof_owner_[dof] < 0 ? -1 : original_index_[dof_owner_[dof]];
  }
  // Whether scaled degree of freedom `dof` is a rotation.
  bool DofIsRotation(int dof) const { return dof_axis_[dof] >= Dim; }
  // Per particle (caller's numbering), the sum of k_wall + kt_wall (1 + m R^2 / J) over its wall
  // links (the input of PerParticleCriticalTimeStep), empty without walls.
  const std::vector<double>& WallStiffnessPerParticle() const { return wall_stiffness_; }
  // The packing contacts as (i, j) pairs, i < j (the input of PerParticleCriticalTimeStep).
  std::vector<std::array<int, 2>> ContactPairs() const;

  // --- The mass-scaled stiffness A = M^-1/2 K M^-1/2 (omega^2 = eigenvalues of A) ---
  void ApplyScaledStiffness(const std::vector<double>& x, std::vector<double>& y) const;
  // y += M^-1/2 K_b M^-1/2 x: the bending (and twisting) springs of moment-carrying bonds
  // alone. They act on rotations only and do not strain DDEM particles (a couple's moment
  // tensor is antisymmetric), so every operator of the analysis adds them the same way.
  void AddBendingStiffness(const std::vector<double>& x, std::vector<double>& y) const;
  // Gershgorin bound: max over degrees of freedom of sum_b |A_ab| (summed link by link), a
  // deterministic upper bound of lambda_max(A) [1/s^2].
  double GershgorinBound() const;

  // --- Link-level pieces (vectors over links: one normal number, one tangential Vector) ---
  // Normal elongation g_c = n.d and tangential displacement d_t of every link, for scaled
  // coordinates x (u = M^-1/2 x).
  void LinkKinematics(const std::vector<double>& x, std::vector<double>* normal,
                      std::vector<Vector<Dim>>* tangential) const;
  // y = M^-1/2 C^T f: the scaled generalised forces of link forces f_n n + f_t on i (and the
  // opposite on j). `tangential` may be empty (no tangential forces).
  void GatherLinkForces(const std::vector<double>& normal,
                        const std::vector<Vector<Dim>>& tangential, std::vector<double>& y) const;
  // Particle strains of link forces, with the compliance D of Ep = 1 (scale by 1/Ep):
  // eps_p = D (1/V_p) sum_c R_p [f_n n n + sym(n (x) f_t)]. `tangential` may be empty.
  void StrainOfLinkForces(const ParticleCompliance<Dim>& unit_compliance,
                          const std::vector<double>& normal,
                          const std::vector<Vector<Dim>>& tangential,
                          std::vector<SymmetricTensor<Dim>>* strain) const;
  // Normal gap correction sum_p R_p n_c.eps_p.n_c of every link (Madan (2.53)).
  void NormalDisplacementOfStrain(const std::vector<SymmetricTensor<Dim>>& strain,
                                  std::vector<double>* normal) const;
  // Tangential displacement of the contact points sum_p R_p P_c eps_p n_c: the adjoint of the
  // tangential term of StrainOfLinkForces (the contact law ignores it; the analysis needs it
  // to form the transpose of the DDEM time-step operator).
  void TangentialDisplacementOfStrain(const std::vector<SymmetricTensor<Dim>>& strain,
                                      std::vector<Vector<Dim>>* tangential) const;
  // Link stiffnesses [N/m] and dashpot coefficients [N s/m] (Madan (2.33)-(2.37): the
  // contact's c = xi 2 sqrt(m_i m_j k / (m_i + m_j)); a wall's normal dashpot
  // xi_n 2 sqrt(m k_wall), as the solver's wall law).
  double normal_stiffness(int link) const { return link_kn_[link]; }
  double tangential_stiffness(int link) const { return link_kt_[link]; }
  double normal_dashpot(int link) const { return link_cn_[link]; }
  double tangential_dashpot(int link) const { return link_ct_[link]; }
  bool has_dashpots() const { return dashpots_; }
  // The DDEM operator S = K_n^1/2 M K_n^1/2 on link vectors, for the compliance of Ep = 1:
  // rho(B) = lambda_max(S) / Ep.
  void ApplyDdemOperator(const ParticleCompliance<Dim>& unit_compliance,
                         const std::vector<double>& x, std::vector<double>& y) const;

  // The same on two vectors at once (one pass over the network for both: the products are
  // memory-bound), y1 = S x1, y2 = S x2.
  void ApplyDdemOperatorPair(const ParticleCompliance<Dim>& unit_compliance,
                             const std::vector<double>& x1, const std::vector<double>& x2,
                             std::vector<double>& y1, std::vector<double>& y2) const;

  // The operator of the DDEM step of normal springs (stability_limits.cpp, the pencil):
  // y = A A^T x + shift S x with A = K_n^1/2 C M^-1/2, in two passes (links -> particles:
  // the motions M^-1 C^T K_n^1/2 x and the strains of the forces K_n^1/2 x; particles ->
  // links: the elongations and the strain corrections). Only for networks without rotational
  // degrees of freedom (kt = 0).
  void ApplyPencilOperator(const ParticleCompliance<Dim>& compliance, double shift,
                           const std::vector<double>& x, std::vector<double>& y) const;

  // The operator of the DDEM step with tangential springs, without dashpots (the pencil of
  // stability_limits.cpp for kt > 0): on link vectors v = (v_n, v_t), normals first, then
  // Dim numbers per link (their normal components are ignored),
  //   y = A~ A~^T v + shift (S v_n, 0),   A~ = [A_n + G A_t / 2; A_t],
  // with A_n = K_n^1/2 C_n M^-1/2, A_t = K_t^1/2 C_t M^-1/2 and G = K_n^1/2 M_nt K_t^1/2 the
  // normal gap correction of the strain of tangential forces. Size link_count() (1 + Dim).
  void ApplyTangentialPencilOperator(const ParticleCompliance<Dim>& compliance, double shift,
                                     const std::vector<double>& v, std::vector<double>& y) const;
  // y = (S v_n, 0) on the vectors above (the slope of the pencil's fixed point).
  void ApplyTangentialPencilShift(const ParticleCompliance<Dim>& compliance,
                                  const std::vector<double>& v, std::vector<double>& y) const;

  void set_num_threads(int threads) { num_threads_ = std::max(1, threads); }

 private:
  void Build(const Packing<Dim>& sorted_packing, const SceneOptions<Dim>& sorted_scene,
             double wall_reach_m);
  void BuildAdjacency();
  int internal_index(int particle) const { return internal_index_[particle]; }
  // The motions n_w . F / m_w of the force-driven walls (0 for the others) under the link
  // forces force(c) (the force on the particle end i of wall link c, as GatherLinkForces).
  template <typename LinkForce>
  std::vector<double> WallMotions(const LinkForce& force) const;

  int num_threads_ = 1;
  bool rotation_ = false, tangential_ = false, dashpots_ = false, bending_ = false;
  int dof_count_ = 0, fixed_dofs_ = 0;
  int contact_links_ = 0, wall_links_ = 0, rattler_links_ = 0, rattlers_alone_ = 0;
  // Particles, in the internal numbering; original_index_[internal] = the caller's index.
  std::vector<int> original_index_, internal_index_;
  std::vector<double> radius_, mass_, volume_;
  std::vector<std::array<int, kNodeDofs>> dof_;  // scaled dof index per axis, -1: none
  std::vector<double> dof_inverse_root_mass_;    // per dof: 1/sqrt(m or J or wall mass)
  std::vector<int> dof_owner_;
  std::vector<int> dof_axis_;  // 0..Dim-1 translation, Dim.. rotation, -1 wall
  // Force-driven walls as nodes: their dof (-1 if none), unit normal.
  std::vector<int> wall_dof_;
  std::vector<Vector<Dim>> wall_normal_;
  std::vector<std::vector<int>> wall_node_links_;
  std::vector<double> wall_stiffness_;
  // Links: end i (particle), end j (particle >= 0, ground -1, force-driven wall node -2 - w).
  std::vector<int> link_i_, link_j_;
  std::vector<Vector<Dim>> link_normal_;
  std::vector<double> link_kn_, link_kt_, link_root_kn_, link_root_kt_, link_cn_, link_ct_;
  // Bending and twisting stiffness of the contact links [N m/rad] (empty without bending).
  std::vector<double> link_kb_, link_kw_;
  // Particle -> link adjacency: entries 2 link + side (0: the particle is i, 1: it is j).
  std::vector<int> adjacency_offset_, adjacency_entry_;
  // Work arrays of the Apply methods, kept between calls: large vectors allocated afresh at
  // every product cost more in page faults than the product itself. (The Apply methods are
  // therefore not safe to call concurrently on one network.)
  mutable std::vector<double> scratch_normal_, scratch_force_;
  mutable std::vector<Vector<Dim>> scratch_tangential_, scratch_motion_;
  mutable std::vector<Angular<Dim>> scratch_spin_;
  mutable std::vector<SymmetricTensor<Dim>> scratch_strain_, scratch_strain2_;
  mutable std::vector<double> pencil_normal_, pencil_correction_, pencil_dofs_;
  mutable std::vector<Vector<Dim>> pencil_tangential_, pencil_slip_;
};

}  // namespace specimen
