#pragma once
// What calibrate-to-material writes, in one place:
//   <dir>/<name>_parameters.toml     the calibrated [material] table (run-test scene format)
//   <dir>/<name>_ucs_scene.toml,     complete run-test scenes of the verification tests with
//   <dir>/<name>_bts_scene.toml      the calibrated set, on the packings below: rerun them
//   <dir>/<name>_ucs.packing, _bts.packing   the verification specimens
//   <dir>/<name>_report.json, _report.txt    the summary (CalibrationSummary)
//   <dir>/<name>_sweep.csv           the map's sweep points: ratios, measured values, groups
//   <dir>/<name>_map_curves.csv      the fitted surfaces through the chosen point
//   <dir>/<name>_maps.png            nu and Psi_E against kt/kn, sigma_c/sigma_t and Psi_c
//                                    against the last axis, sweep points and chosen point
//   <dir>/<name>_verification.csv    every verification round: parameters, achieved, errors
//                                    (a failed round: its failure instead of strengths)
//   <dir>/<name>_verify_ucs_*, _verify_bts_*  the final verification tests (lab_outputs.h:
//                                    stress-strain CSV and picture, cracks, VTU)
//   <dir>/<name>_round<N>_ucs_scene.toml, _bts_scene.toml   the tests of failed round N, to
//                                    repeat the failure with run-test
// With no round measured (every one failed) there is no calibrated set: no parameters, scenes
// of the best round or final tests; the rest is written.
// Data files appear together (OutputGroup); pictures come last and a missing gnuplot only
// costs them (a warning).

#include <string>
#include <vector>

#include "calibrate/calibration.h"

namespace specimen {

struct CalibrationOutputOptions {
  std::string directory = "out/calibration";
  std::string name = "calibration";
  bool pictures = true;
};

struct CalibrationOutputsWritten {
  std::vector<std::string> files;
  std::vector<std::string> warnings;
};

// Throws InputError for an empty name or one holding '/', FileError if the directory
// cannot be created or written. Call before long work.
void CheckCalibrationOutputLocation(const CalibrationOutputOptions& options);

// The [material] table of a run-test scene for `material` (full precision); plane_model only
// in 2D.
std::string MaterialTomlTable(const MaterialParameters& material, int dimension);

template <int Dim>
CalibrationOutputsWritten WriteCalibrationOutputs(const CalibrationSummary& summary,
                                                  const CalibrationSpecimens<Dim>& specimens,
                                                  const CalibrationOptions& options,
                                                  const CalibrationOutputOptions& output);

// The own outputs of the best round's Brazilian test (<name>_verify_bts*, as run-test writes
// them), on the rank that ran it when it is not rank 0 (summary.final_bts_rank);
// WriteCalibrationOutputs writes them when it holds the test. Nothing without a result.
template <int Dim>
CalibrationOutputsWritten WriteFinalBrazilianOutputs(const CalibrationSummary& summary,
                                                     const CalibrationSpecimens<Dim>& specimens,
                                                     const CalibrationOutputOptions& output);

}  // namespace specimen
