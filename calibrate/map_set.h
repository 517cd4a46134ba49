#pragma once
// The micro-macro maps: the dimensionless micro ratios (kt/kn, Rt/Rn, mu, kn/(Ep l), nu_p)
// and the response surfaces of nu and of the groups Psi_E, Psi_c, Psi_t over the ratios that
// vary (dimensionless_groups.h). With global contact constants E ~ kn and the strengths ~ Rn
// at fixed ratios, so the ratios and these four surfaces are all a calibration needs to know
// of a packing (Labra 4.49-4.59, Madan 4.9-4.10).

#include <string>
#include <vector>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/response_surface.h"

namespace specimen {

// The dimensionless micro parameters of a calibration.
struct MicroRatios {
  double tangential_to_normal_stiffness = 0.0;  // kt / kn
  double shear_to_tensile_strength = 1.0;       // Rt / Rn
  double friction_coefficient = 0.0;            // mu
  double normal_stiffness_to_particle = 0.0;    // kn / (Ep l); 0 = rigid particles
  double particle_poisson_ratio = 0.0;          // nu_p
  double bond_range = 1.0;                      // gamma: bonds within gamma (ri + rj), fixed
};

// Names of the ratios as map inputs.
enum class MicroRatio { kStiffnessRatio, kStrengthRatio, kFriction, kParticleCompliance, kParticlePoisson };
std::string MicroRatioName(MicroRatio ratio);

// The value of one ratio; the ratios with one of them set.
double RatioValue(const MicroRatios& ratios, MicroRatio ratio);
void SetRatioValue(MicroRatios* ratios, MicroRatio ratio, double value);

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

}  // namespace specimen
