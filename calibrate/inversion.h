#pragma once
// Inversion of the micro-macro maps (issue 6): the micro ratios (kt/kn, Rt/Rn, mu,
// kn/(Ep l), nu_p) that reproduce a target nu and sigma_c / sigma_t, then kn and Rn from
// the elastic and strength groups, which scale exactly (E ~ kn, strengths ~ Rn at fixed
// ratios; dimensionless_groups.h).
//
//   minimise  w_nu (nu(x) / nu* - 1)^2 + w_ratio ((Psi_c / Psi_t)(x) / (sigma_c/sigma_t)* - 1)^2
//   over the map's box, subject to kn/(Ep l) <= admissible(nu_p) (the DDEM convergence
//   bound rho(B) <= limit, Madan section 3), with NLopt SLSQP and the maps' gradients,
//   from several starts. A target the maps cannot reach is reported with the closest
//   achievable set and which strength was honoured, never silently.

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/response_surface.h"
#include "calibrate/target_material.h"

namespace specimen {

// The dimensionless micro parameters of a calibration.
struct MicroRatios {
  double tangential_to_normal_stiffness = 0.0;  // kt / kn
  double shear_to_tensile_strength = 1.0;       // Rt / Rn
  double friction_coefficient = 0.0;            // mu
  double normal_stiffness_to_particle = 0.0;    // kn / (Ep l); 0 = rigid particles
  double particle_poisson_ratio = 0.0;          // nu_p
};

// Names of the ratios as map inputs.
enum class MicroRatio { kStiffnessRatio, kStrengthRatio, kFriction, kParticleCompliance, kParticlePoisson };
std::string MicroRatioName(MicroRatio ratio);

// Response surfaces of the four macro quantities over the same inputs.
struct MapSet {
  std::vector<MicroRatio> inputs;  // the ratios that vary, in the surfaces' input order
  MicroRatios fixed;               // values of the ratios that do not vary
  ResponseSurface poisson_ratio;   // nu (2D: plane strain)
  ResponseSurface elastic_group;   // Psi_E
  ResponseSurface compressive_group;  // Psi_c
  ResponseSurface tensile_group;      // Psi_t

  MicroRatios RatiosAt(const std::vector<double>& x) const;
  // The box of the sweep (the elastic surfaces may not span the strength-only ratios).
  Eigen::VectorXd Lower() const;
  Eigen::VectorXd Upper() const;
  std::vector<double> InputsOf(const MicroRatios& ratios) const;
};

enum class HonouredStrength { kCompressive, kTensile };

struct InversionOptions {
  // nu is matched first: an unreachable sigma_c / sigma_t is reported, and must not pull nu
  // off its target (the weights of the squared relative errors).
  double poisson_weight = 100.0;
  double strength_ratio_weight = 1.0;
  // Largest admissible kn/(Ep l) for a given nu_p (the DDEM convergence bound at the
  // required rho(B) margin); empty = no DDEM constraint (rigid maps).
  std::function<double(double particle_poisson_ratio)> admissible_particle_compliance;
  // When sigma_c / sigma_t cannot be matched, which strength Rn is taken from.
  HonouredStrength honour = HonouredStrength::kCompressive;
  int starts = 12;                 // multi-start points (deterministic)
  double relative_tolerance = 1e-3;  // a target within this is "reached"
};

struct InversionResult {
  MicroRatios ratios;
  double normal_stiffness = 0.0;      // kn [N/m]
  double tangential_stiffness = 0.0;  // kt
  double bond_tensile_strength = 0.0; // Rn [N]
  double bond_shear_strength = 0.0;   // Rt
  double particle_youngs_modulus = 0.0;  // Ep [Pa], 0 = rigid
  // Predicted macro values and relative errors against the target.
  double youngs_modulus = 0.0, poisson_ratio = 0.0, ucs = 0.0, tensile_strength = 0.0;
  double error_youngs = 0.0, error_poisson = 0.0, error_ucs = 0.0, error_tensile = 0.0;
  bool strength_ratio_reached = true;
  bool poisson_reached = true;
  HonouredStrength honoured = HonouredStrength::kCompressive;
  std::vector<std::string> notes;  // unreachable targets and why

  nlohmann::json ToJson() const;
  std::string FullReport() const;
};

InversionResult InvertMaps(const MapSet& maps, const PackingDescriptors& packing,
                           const TargetMaterial& target, const InversionOptions& options);

// Correction of nu between verification rounds (calibrate-to-material, verification).
struct PoissonRound {
  MicroRatios ratios;           // the round's ratios
  double poisson_ratio = 0.0;   // the nu it measured
};
struct PoissonCorrection {
  MicroRatios next;  // ratios for the next round (inside the maps' box)
  std::string what;  // e.g. "kt/kn 0.15 -> 0.15; kn/(Ep l) 0.0875 -> 0.21; "
  // Share of the last round's error the levers could not remove, in [0, 1]: the box stopped
  // them (or the maps have no such lever, or it does not act). 1: nothing moved.
  double unremoved_share = 0.0;
};
// Moves kt/kn so that nu reaches the target; in DDEM maps, the share of the step the box does
// not allow kt/kn goes to kn/(Ep l) (it raises nu, Madan 4.10; the box keeps rho(B) within its
// bound). Each slope is the secant of the last two rounds when only that ratio moved between
// them and it agrees in sign with the maps' gradient, else the gradient; a step is at most half
// the box. `history` holds the rounds so far, the last one current (not empty).
PoissonCorrection CorrectPoisson(const MapSet& maps, const std::vector<PoissonRound>& history,
                                 double target_poisson);

// A verification round's ratios and the sigma_c / sigma_t it measured (UCS over BTS).
struct StrengthRatioRound {
  MicroRatios ratios;
  double strength_ratio = 0.0;
};
// When both strengths are honoured: moves Rt/Rn of `next` (the ratios after the other
// corrections of this round) so that sigma_c / sigma_t reaches the target, by a Newton step
// in ln(sigma_c / sigma_t) with the slope of ln(Psi_c / Psi_t) along Rt/Rn (or the secant of
// the last two rounds when only Rt/Rn moved and it agrees in sign), at most half the box.
// Unchanged when Rt/Rn is not an input of the maps or the ratio does not depend on it.
// Without it a kt/kn correction of nu shifts sigma_t and nothing brings it back.
PoissonCorrection CorrectStrengthRatio(const MapSet& maps, const MicroRatios& next,
                                       const std::vector<StrengthRatioRound>& history,
                                       double target_ratio);

}  // namespace specimen
