#pragma once
// What the calibration loop (calibration_solver.h) asks of the real specimens: the elastic
// constants of the intact specimen and the two strengths at a micro parameter set. The lab
// implementation (lab_forward_model.h) runs the virtual tests; the tests of the loop use a
// cheap closed-form model with noise and bias instead, so that convergence, step rejection
// and the reach report are checked in seconds.

#include <vector>

#include "calibrate/map_set.h"

namespace specimen {

// The elastic constants of the intact specimen (the linear portion, lab_measurement.h
// LinearPortionElasticConstants; 2D: plane strain).
struct ElasticMeasurement {
  double youngs_modulus_pa = 0.0;
  double poisson_ratio = 0.0;
  double seconds = 0.0;
};

// One strength round: the UCS and the Brazilian tensile strength.
struct StrengthMeasurement {
  double ucs_pa = 0.0;
  double tensile_strength_pa = 0.0;
  // The linear portion of the same UCS run (a cross-check of the elastic stage; 0 when a bond
  // broke within its first samples) and the secants over the lab window x its own peak
  // (Labra's reading, which includes damage when bonds break inside the window).
  double linear_youngs_modulus_pa = 0.0, linear_poisson_ratio = 0.0;
  double secant_youngs_modulus_pa = 0.0, secant_poisson_ratio = 0.0;
  double seconds = 0.0;
};

// An elastic run: kn and the ratios (the strengths do not matter: bonds are intact).
struct ElasticQuery {
  double normal_stiffness = 0.0;  // kn [N/m]
  MicroRatios ratios;
};

class ForwardModel {
 public:
  virtual ~ForwardModel() = default;
  // The elastic constants at each query, in order; the implementation may run them at once.
  // Throws ComputationError when a run fails.
  virtual std::vector<ElasticMeasurement> MeasureElastic(const std::vector<ElasticQuery>& queries) = 0;
  // UCS and Brazilian strengths at kn, Rn and the ratios (Rt = Rt/Rn x Rn, kt = kt/kn x kn).
  // Throws ComputationError when a test fails (diverges, or no peak within its strain limit),
  // its message naming the test; the loop records a failed round and goes on.
  virtual StrengthMeasurement MeasureStrength(double normal_stiffness, double bond_tensile_strength,
                                              const MicroRatios& ratios) = 0;
};

}  // namespace specimen
