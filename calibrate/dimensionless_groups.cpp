#include "calibrate/dimensionless_groups.h"

#include <nlohmann/json.hpp>

#include "common/error.h"

namespace specimen {

double PackingDescriptors::CharacteristicRadius() const {
  if (!(mean_branch_length_squared > 0.0))
    throw InputError("the packing has no contacts: its characteristic radius (Labra 4.51) is undefined");
  return dimension == 3 ? 4.0 * mean_radius_cubed / mean_branch_length_squared
                        : 4.0 * mean_radius_squared / mean_branch_length_squared;
}

double PackingDescriptors::CharacteristicArea() const {
  if (!(mean_branch_length > 0.0))
    throw InputError("the packing has no contacts: its characteristic area (Labra 4.58) is undefined");
  constexpr double kThickness = 1.0;  // 2D: per unit thickness
  return dimension == 3 ? 2.0 * mean_radius_cubed / mean_branch_length
                        : 2.0 * mean_radius_squared * kThickness / mean_branch_length;
}

template <int Dim>
PackingDescriptors DescribePacking(const PackingMetrics<Dim>& m) {
  PackingDescriptors d;
  d.dimension = Dim;
  d.particles = m.particle_count;
  d.porosity = m.nominal_porosity;
  d.coordination = m.coordination_number;
  d.mean_radius = m.mean_radius;
  d.radius_ratio = m.radius_ratio;
  d.mean_radius_squared = m.mean_radius_squared;
  d.mean_radius_cubed = m.mean_radius_cubed;
  d.mean_branch_length = m.mean_branch_length;
  d.mean_branch_length_squared = m.mean_branch_length_squared;
  return d;
}

nlohmann::json DescriptorsToJson(const PackingDescriptors& d) {
  return {{"dimension", d.dimension},
          {"particles", d.particles},
          {"porosity", d.porosity},
          {"coordination", d.coordination},
          {"mean_radius", d.mean_radius},
          {"radius_ratio", d.radius_ratio},
          {"mean_radius_squared", d.mean_radius_squared},
          {"mean_radius_cubed", d.mean_radius_cubed},
          {"mean_branch_length", d.mean_branch_length},
          {"mean_branch_length_squared", d.mean_branch_length_squared}};
}

PackingDescriptors DescriptorsFromJson(const nlohmann::json& j) {
  PackingDescriptors d;
  try {
    d.dimension = j.at("dimension").get<int>();
    d.particles = j.at("particles").get<int>();
    d.porosity = j.at("porosity").get<double>();
    d.coordination = j.at("coordination").get<double>();
    d.mean_radius = j.at("mean_radius").get<double>();
    d.radius_ratio = j.at("radius_ratio").get<double>();
    d.mean_radius_squared = j.at("mean_radius_squared").get<double>();
    d.mean_radius_cubed = j.at("mean_radius_cubed").get<double>();
    d.mean_branch_length = j.at("mean_branch_length").get<double>();
    d.mean_branch_length_squared = j.at("mean_branch_length_squared").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw FileError(std::string("packing descriptors: ") + e.what());
  }
  return d;
}

double ElasticGroup(const PackingDescriptors& d, double e, double kn) {
  return e * d.CharacteristicRadius() / (kn * d.SolidCoordination());
}

double NormalStiffnessFromElasticGroup(const PackingDescriptors& d, double e, double group) {
  return e * d.CharacteristicRadius() / (group * d.SolidCoordination());
}

double StrengthGroup(const PackingDescriptors& d, double strength, double rn) {
  return strength * d.CharacteristicArea() / (rn * d.SolidCoordination());
}

double BondStrengthFromStrengthGroup(const PackingDescriptors& d, double strength, double group) {
  return strength * d.CharacteristicArea() / (group * d.SolidCoordination());
}

double ScaledDensity(double density, double porosity) {
  if (!(porosity >= 0.0 && porosity < 1.0))
    throw InputError("porosity = " + std::to_string(porosity) + " is not allowed: it must be in [0, 1)");
  return density / (1.0 - porosity);
}

template PackingDescriptors DescribePacking<2>(const PackingMetrics<2>&);
template PackingDescriptors DescribePacking<3>(const PackingMetrics<3>&);

}  // namespace specimen
