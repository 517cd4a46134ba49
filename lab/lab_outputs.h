#pragma once
// Everything run-test writes for one lab test (lab_test.h), in one place so that the
// calibrator's verification run writes the same set:
//   <dir>/<name>_curve.csv          the sampled curve: strains (Bagi, platen), stresses,
//                                   control quantity, broken bonds, energy terms
//   <dir>/<name>_bonds.csv          the broken bonds: pair, kind, time, strain, midpoint
//   <dir>/<name>_summary.json       the result (LabTestResult::ToJson) and the caller's report
//   <dir>/<name>_stress_strain.png  the stress-strain curve (gnuplot, from the curve CSV)
//   <dir>/<name>_cracks.png (2D)    the specimen at the end with the broken bonds drawn
//                                   (red: tension, blue: shear), from <name>_cracks.csv and
//                                   <name>_particles.csv
//   <dir>/<name>_peak.vtu, _end.vtu ParaView snapshots at the peak and at the end: particles
//                                   (radius, displacement) and every initial bond as a line
//                                   with its state (cell array "kind": 0 particle, 1 intact
//                                   bond, 2 broken in tension, 3 broken in shear, the codes
//                                   of common/element_kind.h, also in the CSV files)
// The data files are written to temporary names and renamed together (common/atomic_file.h);
// the pictures come last, and a missing gnuplot only costs the pictures (a warning).
// Strains are tension positive in the tensor columns; the "axial" columns are positive in
// compression (docs/lab.md, "Measurement", signs: reported strengths are positive numbers).

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "lab/lab_envelope.h"
#include "lab/lab_test.h"

namespace specimen {

struct LabOutputOptions {
  std::string directory = "out";
  std::string name = "test";
  bool pictures = true;   // PNG pictures (the CSV files they are drawn from are written anyway)
  bool snapshots = true;  // VTU snapshots (needs LabTestOptions::record_snapshots)
};

struct LabOutputsWritten {
  std::vector<std::string> files;
  std::vector<std::string> warnings;
};

// Throws InputError if the name is empty or holds a '/', FileError if the directory cannot
// be created or written. Call before long work.
void CheckLabOutputLocation(const LabOutputOptions& options);

// Writes the files above for one test. `report` (a JSON object, may be empty) is merged
// into the summary (e.g. the scene and the command line).
template <int Dim>
LabOutputsWritten WriteLabOutputs(const LabTestResult& result, const Packing<Dim>& packing,
                                  const nlohmann::json& report, const LabOutputOptions& options);

// A confined envelope: each test's files with the suffix _s3_<k> (k = 1, 2, ...), and
//   <dir>/<name>_envelope.csv, <name>_envelope.png (peak sigma_1 against sigma_3 with the fit),
//   <dir>/<name>_summary.json (the envelope, its tests and `report`).
template <int Dim>
LabOutputsWritten WriteEnvelopeOutputs(const ConfinedEnvelope& envelope,
                                       const Packing<Dim>& packing, const nlohmann::json& report,
                                       const LabOutputOptions& options);

}  // namespace specimen
