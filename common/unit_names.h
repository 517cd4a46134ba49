#pragma once
// The names of the numbers in the output files say their unit (docs/exports.md, "Units and
// names in the output files"): "peak_force_n", "mean_radius_m", "max_overlap_per_r_mean".
// A 2D model is a slab one metre thick, so its forces, energies and stiffnesses are per metre
// of thickness and their names say so; these helpers give the name for the dimension.

#include <string>

namespace specimen {

// "platen_force_n" in 3D, "platen_force_n_per_m" in 2D (per metre of thickness).
inline std::string PerThickness(const std::string& name_with_unit, int dimension) {
  return dimension == 2 ? name_with_unit + "_per_m" : name_with_unit;
}

// "domain_volume_m3" in 3D, "domain_area_m2" in 2D: `stem` is "domain".
inline std::string VolumeName(const std::string& stem, int dimension) {
  return stem + (dimension == 2 ? "_area_m2" : "_volume_m3");
}

}  // namespace specimen
