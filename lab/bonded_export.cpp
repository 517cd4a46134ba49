#include "lab/bonded_export.h"

#include <cmath>
#include <ostream>

#include "common/error.h"
#include "common/format.h"
#include "generator/exports.h"

namespace specimen {

template <int Dim>
std::vector<std::array<int, 2>> ExportedBonds(const Packing<Dim>& packing, double bond_gap_tolerance) {
  std::vector<std::array<int, 2>> bonds;
  for (const auto& c : packing.contacts) {
    const double r_i = packing.radii[c[0]], r_j = packing.radii[c[1]];
    if (std::abs(packing.Gap(c[0], c[1])) <= bond_gap_tolerance * 0.5 * (r_i + r_j)) bonds.push_back(c);
  }
  return bonds;
}

void RequireRigidPairBonds(const MaterialParameters& material, const std::string& source, const std::string& target,
                           const std::string& moment_reason) {
  std::string error;
  if (!material.IsValid(&error)) throw InputError(source + ": " + error);
  if (material.deformable())
    throw InputError(source + ": particle_youngs_modulus is given (deformable particles, DDEM): " + target +
                     "'s particles are rigid, so the export would not be this material; export a rigid-particle "
                     "set (calibrate-to-material --model rigid)");
  if (material.bonds_carry_moments())
    throw InputError(source + ": bond_radius_ratio = " + Number(material.bond_radius_ratio) +
                     " (bonds with a moment) is not allowed: it must be 0 for the " + target + " export (" +
                     moment_reason + ")");
  if (material.bond_range > 1.0)
    throw InputError(source + ": bond_range = " + Number(material.bond_range) +
                     " (bonds within an interaction range) is not allowed: it must be 1 for the " + target +
                     " export (it bonds the packing's contact pairs only)");
  if (!std::isfinite(material.bond_tensile_strength_n) || !std::isfinite(material.bond_shear_strength_n))
    throw InputError(source + ": an unbreakable bond (bond_tensile_strength or bond_shear_strength = inf) "
                     "has no " + target + " equivalent here: give finite strengths");
}

template <int Dim>
void RequireBondedExportable(const Packing<Dim>& packing, double bond_gap_tolerance, const std::string& format) {
  RequireExportable(packing, format);
  if (packing.size() == 0) throw InputError("cannot export the " + format + ": the packing has no particles");
  if (!(bond_gap_tolerance >= 0.0 && bond_gap_tolerance <= 1.0))
    throw InputError("bond_gap_tolerance = " + Number(bond_gap_tolerance) + " is not allowed: it must be in [0, 1]");
}

std::string PythonNumber(const std::optional<double>& value) {
  return value ? ExactDouble(*value) : std::string("None");
}

std::string PythonText(const std::string& text) {
  std::string safe = text.substr(0, 200);
  for (char& c : safe)
    if (c == '\n' || c == '\r' || c == '"' || c == '\\') c = ' ';
  return safe;
}

void WritePythonMaterialConstants(const MaterialParameters* material, std::ostream& out) {
  auto constant = [&](double MaterialParameters::*field) {
    return material ? std::optional<double>(material->*field) : std::nullopt;
  };
  out << "KN = " << PythonNumber(constant(&MaterialParameters::normal_stiffness_n_per_m)) << "  # [N/m]\n"
      << "KT = " << PythonNumber(constant(&MaterialParameters::tangential_stiffness_n_per_m)) << "  # [N/m]\n"
      << "RN = " << PythonNumber(constant(&MaterialParameters::bond_tensile_strength_n)) << "  # [N]\n"
      << "RT = " << PythonNumber(constant(&MaterialParameters::bond_shear_strength_n)) << "  # [N]\n"
      << "MU = " << PythonNumber(constant(&MaterialParameters::friction_coefficient)) << "\n"
      << "DENSITY = " << PythonNumber(constant(&MaterialParameters::density_kg_per_m3)) << "  # [kg/m^3]\n";
}

const char* const kPythonReportFunction = R"PY(

def report(result, json_path):
    """Prints the result as JSON and writes it to json_path when given."""
    text = json.dumps(result, indent=2)
    print(text)
    if json_path:
        with open(json_path, "w") as out:
            out.write(text + "\n")
)PY";

template std::vector<std::array<int, 2>> ExportedBonds<2>(const Packing<2>&, double);
template std::vector<std::array<int, 2>> ExportedBonds<3>(const Packing<3>&, double);
template void RequireBondedExportable<2>(const Packing<2>&, double, const std::string&);
template void RequireBondedExportable<3>(const Packing<3>&, double, const std::string&);

}  // namespace specimen
