#include "calibrate/lab_forward_model.h"

#include <atomic>
#include <chrono>
#include <future>
#include <limits>
#include <sstream>
#include <thread>

#include "calibrate/map_sweep.h"
#include "common/error.h"

namespace specimen {

namespace {

// Every user input is checked before the calibration starts: a run the solver refuses at
// micro parameters the calibration chose is the calibration's own failure (status 4, not 2).
[[noreturn]] void RethrowAsOwnFailure(const InputError& e, double kn, const MicroRatios& r) {
  std::ostringstream at;
  at.precision(4);
  at << "kn " << kn << " N/m, kt/kn " << r.tangential_to_normal_stiffness << ", Rt/Rn " << r.shear_to_tensile_strength;
  if (r.normal_stiffness_to_particle > 0.0)
    at << ", kn/(Ep l) " << r.normal_stiffness_to_particle << ", nu_p " << r.particle_poisson_ratio;
  throw ComputationError("the calibration chose micro parameters the solver refuses (" + at.str() + "): " +
                         e.what() + "; this is a failure of the calibration, not of the input");
}

}  // namespace

template <int Dim>
LabForwardModel<Dim>::LabForwardModel(const Packing<Dim>& ucs, const Packing<Dim>& bts,
                                      LabForwardModelSettings settings)
    : ucs_(ucs), bts_(bts), settings_(std::move(settings)) {
  if (!(settings_.density_kg_per_m3 > 0.0)) throw InputError("forward model: density must be > 0");
  if (settings_.workers < 1) throw InputError("forward model: workers must be >= 1");
}

template <int Dim>
MaterialParameters LabForwardModel<Dim>::MaterialFor(double kn, double rn, const MicroRatios& ratios) const {
  return MaterialAt(ratios, kn, rn, settings_.density_kg_per_m3, settings_.plane_model, settings_.group_length_m);
}

template <int Dim>
std::vector<ElasticMeasurement> LabForwardModel<Dim>::MeasureElastic(const std::vector<ElasticQuery>& queries) {
  std::vector<ElasticMeasurement> out(queries.size());
  std::atomic<size_t> next{0};
  std::exception_ptr failure;
  std::mutex mutex;
  auto work = [&]() {
    for (;;) {
      const size_t k = next++;
      if (k >= queries.size()) return;
      try {
        const MaterialParameters m = MaterialFor(queries[k].normal_stiffness, 1.0, queries[k].ratios);
        try {
          out[k] = MeasureIntactElasticConstants<Dim>(ucs_, m, settings_.protocol);
        } catch (const InputError& e) {
          RethrowAsOwnFailure(e, queries[k].normal_stiffness, queries[k].ratios);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = std::current_exception();
        return;
      }
    }
  };
  const int workers = std::min<int>(settings_.workers, static_cast<int>(queries.size()));
  std::vector<std::thread> threads;
  for (int w = 1; w < workers; ++w) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
  return out;
}

template <int Dim>
StrengthMeasurement LabForwardModel<Dim>::MeasureStrength(double kn, double rn, const MicroRatios& ratios) {
  const auto start = std::chrono::steady_clock::now();
  RoundTests tests;
  tests.material = MaterialFor(kn, rn, ratios);
  LabTestOptions test = StrengthTestProtocol(settings_.protocol);  // as the sweep's
  test.record_snapshots = true;
  test.progress = nullptr;
  LabTestOptions ucs_test = test, bts_test = test;
  ucs_test.kind = LabTestKind::kUniaxialCompression;
  bts_test.kind = LabTestKind::kBrazilian;
  if (settings_.progress) ucs_test.progress = [&](double f, const std::string& m) { settings_.progress(f, "UCS: " + m); };
  // Each test's failure is caught on its own, so that the message names the test (and both,
  // when both fail); the round is kept with its failure, so that strength_tests() stays one
  // entry per round.
  auto run = [&](const char* name, const Packing<Dim>& specimen, const LabTestOptions& options,
                 LabTestResult* out) -> std::string {
    try {
      try {
        *out = RunLabTest<Dim>(specimen, tests.material, options);
      } catch (const InputError& e) {
        RethrowAsOwnFailure(e, kn, ratios);
      }
      if (!out->peak_reached) throw ComputationError("reached its strain limit without a peak");
    } catch (const ComputationError& e) {
      return std::string(name) + " test: " + e.what();
    }
    return "";
  };
  std::string bts_failure;
  auto bts = std::async(std::launch::async, [&]() { bts_failure = run("Brazilian", bts_, bts_test, &tests.bts); });
  std::string failure = run("UCS", ucs_, ucs_test, &tests.ucs);
  bts.get();
  if (!bts_failure.empty()) failure += (failure.empty() ? "" : "; ") + bts_failure;
  if (!failure.empty()) {
    tests.failure = failure;
    strength_tests_.push_back(std::move(tests));
    throw ComputationError(failure);
  }
  StrengthMeasurement m;
  m.ucs_pa = tests.ucs.peak_stress_pa;
  m.tensile_strength_pa = tests.bts.tensile_strength_pa;
  if (tests.ucs.linear_elastic.measured) {
    m.linear_youngs_modulus_pa = tests.ucs.linear_elastic.youngs_modulus_pa;
    m.linear_poisson_ratio = tests.ucs.linear_elastic.poisson_ratio;
  }
  if (tests.ucs.elastic.measured) {
    m.secant_youngs_modulus_pa = tests.ucs.elastic.youngs_modulus_pa;
    m.secant_poisson_ratio = tests.ucs.elastic.poisson_ratio;
  }
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  strength_tests_.push_back(std::move(tests));
  return m;
}

template class LabForwardModel<2>;
template class LabForwardModel<3>;

}  // namespace specimen
