#pragma once
// The energy audit (Madan (2.55)-(2.61)): W_ext = dE_k + dE_el + E_diss.
//
// Discretisation, chosen so that the balance closes to round-off for linear springs:
// kinetic energy at t_n is 1/2 m v_{n-1/2} . v_{n+1/2} (the conserved form of central
// differences); elastic energies are evaluated from the forces at t_n; point-load and wall
// work are trapezoidal over the displacement from t_{n-1} to t_n; local damping and
// prescribed-velocity work use the midpoint velocity; dashpot dissipation is c v_r^2 dt with
// the half-step velocity (first order).
//
// DDEM point loads act at a surface point whose displacement is the centre's plus eps s
// (Madan (2.52)); counting only the centre displacement, as the thesis' W_ext = 1/2 F dH
// does, leaves the particle energy above the work by half the loaded particles' elastic
// energy (Madan Table 4.3: 0.4-1.5 % mismatch). Both parts are reported; the balance uses
// their sum. What remains is the explicit DDEM lag (strain from the previous step's forces)
// and the incremental tangential law (first order in dt under rotation).

#include <nlohmann/json_fwd.hpp>
#include <string>

namespace specimen {

struct EnergyBalance {
  // State terms at t_n [J].
  double kinetic_j = 0.0;           // translation + rotation (+ force-driven walls)
  // sum fn^2/(2 kn) + |ft|^2/(2 kt), contacts and walls, and the bonds' moment energy
  // |Mb|^2/(2 kb) + Mt^2/(2 kw) (bond_moment.h)
  double contact_elastic_j = 0.0;
  double particle_elastic_j = 0.0;  // DDEM: sum 1/2 V sigma : eps, Madan (2.61)
  double initial_total_j = 0.0;     // kinetic + elastic at t = 0
  // Path terms since t = 0 [J].
  // Point loads: on the displacement of their application points, the centre displacement
  // plus (DDEM) the deformation eps s of the load point (Madan (2.52)).
  double load_work_j = 0.0;
  // The part of load_work_j done through the particle deformation. The thesis' W_ext
  // (Madan (4.29), 1/2 F dH on the centres) is load_work_j - load_deformation_work_j.
  double load_deformation_work_j = 0.0;
  double wall_work_j = 0.0;
  double constraint_work_j = 0.0;
  double damping_dissipation_j = 0.0;   // local damping
  double dashpot_dissipation_j = 0.0;   // contact and wall dashpots
  double friction_dissipation_j = 0.0;  // Coulomb slip (contacts and walls)
  double breakage_release_j = 0.0;      // elastic energy of bonds at the moment they broke

  double ExternalWork() const { return load_work_j + wall_work_j + constraint_work_j; }
  double Dissipated() const {
    return damping_dissipation_j + dashpot_dissipation_j + friction_dissipation_j +
           breakage_release_j;
  }
  double Elastic() const { return contact_elastic_j + particle_elastic_j; }
  // (initial + external work) - (kinetic + elastic + dissipated): zero for an exact audit.
  double Imbalance() const;
  // |Imbalance| relative to the larger of the energy supplied (initial + |work|) and the
  // energy present (kinetic + elastic + dissipated); 0 when there is no energy at all.
  double RelativeImbalance() const;

  // A small table, one term per line.
  std::string Table(const std::string& indent) const;
  nlohmann::json ToJson() const;
};

}  // namespace specimen
