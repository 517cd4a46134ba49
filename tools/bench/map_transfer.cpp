// map-transfer: how well the stored maps predict the strength ratio sigma_c / sigma_t on the
// real specimens before any round of a calibration ("Transfer of the maps").
//
//   map-transfer --maps data/maps/maps_2d_dem_<key>.json --ucs-packing ucs.packing
//                --bts-packing bts.packing --points points.csv
//
// The maps are read as a calibration reads them: the surfaces fitted to the sweep, the sweep
// grid (calibrate/sweep_grid.h) and the measurements stored with them on an equivalent
// specimen (calibrate/surrogate.h). points.csv holds measurements on the real specimens
// (columns label, kt_over_kn, kn_over_ep_l, rt_over_rn, ucs_pa, tensile_strength_pa; the
// friction and nu_p are the maps' fixed values). For each point one CSV line goes to standard
// output: the measured ratio and four predictions of it, the fitted surfaces and the sweep
// grid, each uncorrected and corrected by the stored measurements. tools/bench/map_transfer.py
// collects the points from the calibration benchmark's rounds and prints the table.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/map_store.h"
#include "calibrate/surrogate.h"
#include "common/error.h"
#include "generator/metrics.h"
#include "generator/packing_io.h"

namespace {

using specimen::InputError;

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) out.push_back(field);
  return out;
}

specimen::PackingDescriptors Describe(const std::string& path) {
  return specimen::DescribePacking<2>(specimen::ComputePackingMetrics<2>(specimen::LoadPacking<2>(path)));
}

int Run(const std::string& maps_path, const std::string& ucs_path, const std::string& bts_path,
        const std::string& points_path) {
  const specimen::StoredMaps maps = specimen::LoadStoredMaps(maps_path);
  if (maps.dimension != 2) throw InputError(maps_path + ": 2D maps only");
  const specimen::PackingDescriptors ucs = Describe(ucs_path), bts = Describe(bts_path);
  specimen::CalibrationSurrogate surrogate(maps.maps, ucs, bts);
  surrogate.SetSweepGrid(specimen::SweepGrid(maps.design, maps.points));
  int stored = 0;
  for (const specimen::VerifiedPoint& v : maps.verified)
    if (specimen::MapsMatchPacking(v.specimen, ucs, nullptr)) {
      surrogate.AddMeasurement(v.ToMeasurement(ucs, bts), /*stored=*/true);
      ++stored;
    }
  std::ifstream in(points_path);
  if (!in) throw InputError(points_path + ": cannot be opened");
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = Split(line);
  const std::vector<std::string> expected = {"label", "kt_over_kn", "kn_over_ep_l", "rt_over_rn", "ucs_pa",
                                             "tensile_strength_pa"};
  if (header != expected) throw InputError(points_path + ": the header must be label,kt_over_kn,kn_over_ep_l,"
                                                         "rt_over_rn,ucs_pa,tensile_strength_pa");
  // Printed only once every line has been read: a bad line leaves no partial table.
  // Two estimates of the corrected ratio's error where nothing was measured, to set beside the
  // errors measured: the spread of the stored corrections about their mean (the transfer
  // uncertainty the reach widens its interval by, calibration_solver.h) and their leave-one-out
  // error (surrogate.h), root mean square.
  double spread = 0.0, leave_one_out = 0.0;
  {
    const std::vector<double> d = surrogate.StoredStrengthRatioCorrections();
    const std::vector<double> l = surrogate.StoredStrengthRatioLeaveOneOut();
    double mean = 0.0;
    for (double v : d) mean += v / static_cast<double>(d.size());
    for (double v : d) spread = std::max(spread, std::abs(v - mean));
    for (double v : l) leave_one_out += v * v / static_cast<double>(l.size());
    leave_one_out = std::sqrt(leave_one_out);
  }
  std::string table =
      "label,measured,surfaces,surfaces_corrected,grid,grid_corrected,stored_measurements,"
      "correction_spread,correction_leave_one_out_rms\n";
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    const std::vector<std::string> f = Split(line);
    if (f.size() != expected.size())
      throw InputError(points_path + ", line " + std::to_string(row) + ": 6 fields expected");
    // A field that is not a positive number (kn/(Ep l): not negative) is named with its line.
    auto number = [&](int k, bool zero_allowed) {
      double v = 0.0;
      try {
        v = std::stod(f[k]);
      } catch (const std::exception&) {
        v = std::nan("");
      }
      if (!(std::isfinite(v) && (v > 0.0 || (zero_allowed && v == 0.0))))
        throw InputError(points_path + ", line " + std::to_string(row) + ": " + expected[k] + " = '" + f[k] +
                         "' must be a " + (zero_allowed ? "non-negative" : "positive") + " number");
      return v;
    };
    specimen::MicroRatios r = maps.maps.fixed;
    r.tangential_to_normal_stiffness = number(1, false);
    r.normal_stiffness_to_particle = number(2, true);
    r.shear_to_tensile_strength = number(3, false);
    const double measured = number(4, false) / number(5, false);
    char line_out[512];
    std::snprintf(line_out, sizeof line_out, "%s,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.6g,%.6g\n", f[0].c_str(), measured,
                  surrogate.MapUcsPerStrength(r) / surrogate.MapTensilePerStrength(r), surrogate.StrengthRatio(r),
                  surrogate.MapGridStrengthRatio(r), surrogate.GridStrengthRatio(r), stored, spread, leave_one_out);
    table += line_out;
  }
  std::fputs(table.c_str(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"map-transfer: the stored maps' strength ratio against measurements on the real specimens"};
  std::string maps, ucs, bts, points;
  app.add_option("--maps", maps, "stored maps (JSON)")->required();
  app.add_option("--ucs-packing", ucs, "the real UCS specimen")->required();
  app.add_option("--bts-packing", bts, "the real Brazilian specimen")->required();
  app.add_option("--points", points, "CSV of measurements on those specimens")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    return Run(maps, ucs, bts, points);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "map-transfer: %s\n", e.what());
    return 2;
  }
}
