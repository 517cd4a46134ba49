#include "lab/lab_envelope.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "common/error.h"

namespace specimen {
namespace {

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

}  // namespace

void CheckConfinements(const std::vector<double>& confining) {
  std::set<double> distinct;
  for (size_t k = 0; k < confining.size(); ++k) {
    if (!(confining[k] >= 0.0) || !std::isfinite(confining[k]))
      throw InputError("confining stress #" + std::to_string(k + 1) + " = " +
                       Format("%g", confining[k]) +
                       " Pa is not allowed: it must be finite and >= 0 (compression positive)");
    distinct.insert(confining[k]);
  }
  if (distinct.size() < 2)
    throw InputError("a strength envelope needs at least two distinct confining stresses (three "
                     "or more recommended); got " +
                     std::to_string(distinct.size()));
}

template <int Dim>
ConfinedEnvelope RunConfinedEnvelope(const Packing<Dim>& packing,
                                     const MaterialParameters& material,
                                     const LabTestOptions& options,
                                     const std::vector<double>& confining) {
  if (options.kind != LabTestKind::kConfinedCompression)
    throw InputError(std::string("RunConfinedEnvelope needs the test 'biaxial', not '") +
                     LabTestKindName(options.kind) + "'");
  CheckConfinements(confining);
  ConfinedEnvelope envelope;
  envelope.confining_stress_pa = confining;
  std::vector<double> sigma3, sigma1;
  for (size_t k = 0; k < confining.size(); ++k) {
    LabTestOptions one = options;
    one.confining_stress_pa = confining[k];
    if (options.progress)
      one.progress = [&, k](double fraction, const std::string& message) {
        options.progress((k + std::max(0.0, fraction)) / confining.size(),
                         "sigma_3 = " + Format("%.4g MPa", confining[k] * 1e-6) + ": " + message);
      };
    envelope.tests.push_back(RunLabTest<Dim>(packing, material, one));
    if (envelope.tests.back().peak_reached) {
      sigma3.push_back(confining[k]);
      sigma1.push_back(envelope.tests.back().peak_stress_pa);
    }
  }
  std::set<double> distinct(sigma3.begin(), sigma3.end());
  if (distinct.size() < 2) {
    envelope.fit_message = "fewer than two confinements reached a peak: no envelope";
  } else {
    envelope.fit = FitMohrCoulomb(sigma3, sigma1);
    if (!envelope.fit.valid)
      envelope.fit_message = "the fitted line sigma_1 = a + b sigma_3 has b <= 1 or a <= 0: "
                             "no positive friction angle and cohesion";
  }
  return envelope;
}

std::string ConfinedEnvelope::BriefReport() const {
  std::ostringstream out;
  out << "envelope of " << tests.size() << " confined tests: ";
  if (fit.valid)
    out << "c = " << Format("%.4g MPa", fit.cohesion_pa * 1e-6)
        << ", phi = " << Format("%.3g deg", fit.friction_angle_deg)
        << " (sigma_1 = " << Format("%.4g MPa", fit.intercept_pa * 1e-6) << " + "
        << Format("%.4g", fit.slope) << " sigma_3)";
  else
    out << fit_message;
  return out.str();
}

std::string ConfinedEnvelope::FullReport() const {
  std::ostringstream out;
  out << "Confined biaxial envelope\n";
  out << "  sigma_3 [MPa]   sigma_1 peak [MPa]   peak   E [GPa]   nu      broken bonds   "
         "largest confinement error\n";
  for (size_t k = 0; k < tests.size(); ++k) {
    const LabTestResult& t = tests[k];
    char line[256];
    std::snprintf(line, sizeof(line), "  %-15.4g %-20.5g %-6s %-9.4g %-7.4f %-14ld %.3g %%\n",
                  confining_stress_pa[k] * 1e-6, t.peak_stress_pa * 1e-6,
                  t.peak_reached ? "yes" : "no", t.elastic.youngs_modulus_pa * 1e-9,
                  t.elastic.poisson_ratio, t.broken_in_tension + t.broken_in_shear,
                  100 * t.confinement_max_error);
    out << line;
  }
  if (fit.valid) {
    out << "  fit sigma_1 = a + b sigma_3: a = " << Format("%.5g MPa", fit.intercept_pa * 1e-6)
        << ", b = " << Format("%.5g", fit.slope) << ", rms residual "
        << Format("%.3g MPa", fit.rms_residual_pa * 1e-6) << "\n";
    out << "  Mohr-Coulomb: cohesion c = " << Format("%.5g MPa", fit.cohesion_pa * 1e-6)
        << ", friction angle phi = " << Format("%.4g deg", fit.friction_angle_deg) << "\n";
  } else {
    out << "  no Mohr-Coulomb fit: " << fit_message << "\n";
  }
  return out.str();
}

nlohmann::json ConfinedEnvelope::ToJson() const {
  nlohmann::json j;
  j["confining_stress_pa"] = confining_stress_pa;
  j["tests"] = nlohmann::json::array();
  for (const LabTestResult& t : tests) j["tests"].push_back(t.ToJson());
  // Without a fit its numbers are null, not 0: the message says why there is none.
  auto fitted = [&](double value) { return fit.valid ? nlohmann::json(value) : nlohmann::json(nullptr); };
  j["fit"] = {{"valid", fit.valid},
              {"intercept_pa", fitted(fit.intercept_pa)},
              {"slope", fitted(fit.slope)},
              {"cohesion_pa", fitted(fit.cohesion_pa)},
              {"friction_angle_deg", fitted(fit.friction_angle_deg)},
              {"rms_residual_pa", fitted(fit.rms_residual_pa)},
              {"points", fit.points},
              {"message", fit_message}};
  return j;
}

template ConfinedEnvelope RunConfinedEnvelope<2>(const Packing<2>&, const MaterialParameters&,
                                                 const LabTestOptions&, const std::vector<double>&);
template ConfinedEnvelope RunConfinedEnvelope<3>(const Packing<3>&, const MaterialParameters&,
                                                 const LabTestOptions&, const std::vector<double>&);

}  // namespace specimen
