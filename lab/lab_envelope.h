#pragma once
// The peak-strength envelope of confined biaxial tests (lab_test.h kConfinedCompression)
// at several confining stresses, and its Mohr-Coulomb cohesion and friction angle from the
// linear fit sigma_1 = a + b sigma_3 (lab_measurement.h FitMohrCoulomb):
//   phi = asin((b - 1) / (b + 1)),  c = a (1 - sin phi) / (2 cos phi).
//
//   LabTestOptions options;
//   options.kind = LabTestKind::kConfinedCompression;
//   ConfinedEnvelope envelope = RunConfinedEnvelope<2>(packing, material, options, {1e6, 5e6, 10e6});
//   std::cout << envelope.FullReport();
//
// Only tests that reached a peak enter the fit; the envelope says which did not.

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "lab/lab_measurement.h"
#include "lab/lab_test.h"

namespace specimen {

struct ConfinedEnvelope {
  std::vector<double> confining_stress_pa;  // as given
  std::vector<LabTestResult> tests;         // one per confinement, same order
  MohrCoulombFit fit;                       // over the tests that reached a peak
  std::string fit_message;                  // why the fit is not valid, if it is not

  std::string BriefReport() const;
  std::string FullReport() const;
  nlohmann::json ToJson() const;
};

// Throws InputError (before any work) for fewer than two distinct confinements, a negative
// one (naming its index and value), or anything RunLabTest refuses; options.kind must be
// kConfinedCompression (its confining_stress_pa is replaced by each value in turn).
template <int Dim>
ConfinedEnvelope RunConfinedEnvelope(const Packing<Dim>& packing,
                                     const MaterialParameters& material,
                                     const LabTestOptions& options,
                                     const std::vector<double>& confining_stress_pa);

// The checks above alone (for a command that validates everything before work).
void CheckConfinements(const std::vector<double>& confining_stress_pa);

}  // namespace specimen
