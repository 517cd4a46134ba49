#include "calibrate/map_set.h"

namespace specimen {

std::string MicroRatioName(MicroRatio ratio) {
  switch (ratio) {
    case MicroRatio::kStiffnessRatio: return "kt/kn";
    case MicroRatio::kStrengthRatio: return "Rt/Rn";
    case MicroRatio::kFriction: return "mu";
    case MicroRatio::kParticleCompliance: return "kn/(Ep l)";
    case MicroRatio::kParticlePoisson: return "nu_p";
  }
  return "?";
}

double RatioValue(const MicroRatios& r, MicroRatio ratio) {
  switch (ratio) {
    case MicroRatio::kStiffnessRatio: return r.tangential_to_normal_stiffness;
    case MicroRatio::kStrengthRatio: return r.shear_to_tensile_strength;
    case MicroRatio::kFriction: return r.friction_coefficient;
    case MicroRatio::kParticleCompliance: return r.normal_stiffness_to_particle;
    case MicroRatio::kParticlePoisson: return r.particle_poisson_ratio;
  }
  return 0.0;
}

void SetRatioValue(MicroRatios* r, MicroRatio ratio, double value) {
  switch (ratio) {
    case MicroRatio::kStiffnessRatio: r->tangential_to_normal_stiffness = value; break;
    case MicroRatio::kStrengthRatio: r->shear_to_tensile_strength = value; break;
    case MicroRatio::kFriction: r->friction_coefficient = value; break;
    case MicroRatio::kParticleCompliance: r->normal_stiffness_to_particle = value; break;
    case MicroRatio::kParticlePoisson: r->particle_poisson_ratio = value; break;
  }
}

Eigen::VectorXd MapSet::Lower() const {
  return poisson_ratio.lower().cwiseMin(compressive_group.lower());
}

Eigen::VectorXd MapSet::Upper() const {
  return poisson_ratio.upper().cwiseMax(compressive_group.upper());
}

MicroRatios MapSet::RatiosAt(const std::vector<double>& x) const {
  MicroRatios r = fixed;
  for (size_t k = 0; k < inputs.size(); ++k) SetRatioValue(&r, inputs[k], x[k]);
  return r;
}

std::vector<double> MapSet::InputsOf(const MicroRatios& r) const {
  std::vector<double> x;
  for (MicroRatio input : inputs) x.push_back(RatioValue(r, input));
  return x;
}

}  // namespace specimen
