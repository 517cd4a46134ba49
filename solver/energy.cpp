#include "solver/energy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace specimen {

double EnergyBalance::Imbalance() const {
  return initial_total_j + ExternalWork() - (kinetic_j + Elastic() + Dissipated());
}

double EnergyBalance::RelativeImbalance() const {
  const double scale = std::max(std::abs(initial_total_j) + std::abs(ExternalWork()),
                                std::abs(kinetic_j) + Elastic() + std::abs(Dissipated()));
  return scale > 0.0 ? std::abs(Imbalance()) / scale : 0.0;
}

std::string EnergyBalance::Table(const std::string& indent) const {
  std::string out;
  char line[160];
  auto row = [&](const char* name, double value) {
    std::snprintf(line, sizeof(line), "%s%-34s %14.6e J\n", indent.c_str(), name, value);
    out += line;
  };
  row("kinetic", kinetic_j);
  row("contact elastic (f^2/2k)", contact_elastic_j);
  row("particle elastic (V sigma:eps/2)", particle_elastic_j);
  row("initial (kinetic + elastic)", initial_total_j);
  row("work of point loads", load_work_j);
  row("  of which through particle deformation", load_deformation_work_j);
  row("work of wall drives", wall_work_j);
  row("work of prescribed velocities", constraint_work_j);
  row("dissipated by local damping", damping_dissipation_j);
  row("dissipated by dashpots", dashpot_dissipation_j);
  row("dissipated by friction", friction_dissipation_j);
  row("released by bond breakage", breakage_release_j);
  row("imbalance", Imbalance());
  std::snprintf(line, sizeof(line), "%s%-34s %14.4f %%\n", indent.c_str(), "relative imbalance",
                100.0 * RelativeImbalance());
  out += line;
  return out;
}

nlohmann::json EnergyBalance::ToJson() const {
  return {{"kinetic_j", kinetic_j},
          {"contact_elastic_j", contact_elastic_j},
          {"particle_elastic_j", particle_elastic_j},
          {"initial_total_j", initial_total_j},
          {"load_work_j", load_work_j},
          {"load_deformation_work_j", load_deformation_work_j},
          {"wall_work_j", wall_work_j},
          {"constraint_work_j", constraint_work_j},
          {"external_work_j", ExternalWork()},
          {"damping_dissipation_j", damping_dissipation_j},
          {"dashpot_dissipation_j", dashpot_dissipation_j},
          {"friction_dissipation_j", friction_dissipation_j},
          {"breakage_release_j", breakage_release_j},
          {"imbalance_j", Imbalance()},
          {"relative_imbalance", RelativeImbalance()}};
}

}  // namespace specimen
