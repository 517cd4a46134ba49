#pragma once
// Everything generate-packing writes for one packing, in one place so that every command
// that produces a packing (generate-packing, calibrate-to-material) writes the same set:
//   <dir>/<name>.packing          the packing (versioned text, bit-exact round trip)
//   <dir>/<name>.vtu              ParaView (points with radius, contacts as lines)
//   <dir>/<name>_yade.txt         Yade: yade.ymport.text('<name>_yade.txt')
//   <dir>/<name>.liggghts         LIGGGHTS/LAMMPS read_data, atom_style sphere
//   <dir>/<name>_report.json      metrics and the generator summary
//   <dir>/<name>_*.csv, *.png     pictures and the numbers they are drawn from
// The data files are written to temporary names and renamed together at the end; the
// pictures come last, and a missing gnuplot only costs the pictures (a warning).

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "generator/metrics.h"
#include "generator/packing.h"

namespace specimen {

struct PackingOutputOptions {
  std::string directory = "out";
  std::string name = "packing";
  bool pictures = true;  // false: the CSV files only, no PNG
  double liggghts_density_kg_per_m3 = 2650.0;
};

struct PackingOutputsWritten {
  std::vector<std::string> files;
  std::vector<std::string> warnings;
};

// `report` (any JSON object) is written with the metrics as <name>_report.json.
template <int Dim>
PackingOutputsWritten WritePackingOutputs(const Packing<Dim>& packing,
                                          const PackingMetrics<Dim>& metrics,
                                          const nlohmann::json& report,
                                          const PackingOutputOptions& options);

// Throws FileError if the directory cannot be created or written, InputError if the name
// is empty or contains a path separator. Call before long work.
void CheckPackingOutputLocation(const PackingOutputOptions& options);

}  // namespace specimen
