#include "calibrate/lab_forward_model.h"

#include <atomic>
#include <chrono>
#include <future>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "calibrate/map_sweep.h"
#include "common/error.h"
#include "common/ranks.h"

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

// An error as data between ranks, and back (the kind keeps the exit status of the command).
std::string ErrorKind(const std::exception& e) {
  if (dynamic_cast<const InputError*>(&e)) return "input";
  if (dynamic_cast<const FileError*>(&e)) return "file";
  if (dynamic_cast<const ComputationError*>(&e)) return "computation";
  return "internal";
}

[[noreturn]] void ThrowErrorOfKind(const std::string& kind, const std::string& message) {
  if (kind == "input") throw InputError(message);
  if (kind == "file") throw FileError(message);
  if (kind == "computation") throw ComputationError(message);
  throw std::runtime_error(message);
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
  const int rank = Rank(), ranks = RankCount();
  std::vector<size_t> mine;  // run k on rank k % N
  for (size_t k = static_cast<size_t>(rank); k < queries.size(); k += static_cast<size_t>(ranks)) mine.push_back(k);
  std::vector<ElasticMeasurement> out(queries.size());
  std::atomic<size_t> next{0};
  std::exception_ptr failure;
  size_t failed_query = 0;
  std::mutex mutex;
  auto work = [&]() {
    for (;;) {
      const size_t n = next++;
      if (n >= mine.size()) return;
      const size_t k = mine[n];
      try {
        const MaterialParameters m = MaterialFor(queries[k].normal_stiffness, 1.0, queries[k].ratios);
        try {
          out[k] = MeasureIntactElasticConstants<Dim>(ucs_, m, settings_.protocol);
        } catch (const InputError& e) {
          RethrowAsOwnFailure(e, queries[k].normal_stiffness, queries[k].ratios);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = std::current_exception(), failed_query = k;
        return;
      }
    }
  };
  const int workers = std::min<int>(settings_.workers, static_cast<int>(mine.size()));
  std::vector<std::thread> threads;
  for (int w = 1; w < workers; ++w) threads.emplace_back(work);
  if (workers >= 1) work();
  for (auto& t : threads) t.join();
  if (ranks == 1) {
    if (failure) std::rethrow_exception(failure);
    return out;
  }
  // Every rank's runs to every rank; a failure travels as data (its kind and message), and
  // every rank throws the first one (in query order).
  nlohmann::json share = {{"runs", nlohmann::json::array()}};
  for (size_t k : mine)
    share["runs"].push_back({{"k", k}, {"e", out[k].youngs_modulus_pa}, {"nu", out[k].poisson_ratio},
                             {"s", out[k].seconds}});
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const std::exception& e) {
      share["failure"] = {{"k", failed_query}, {"kind", ErrorKind(e)}, {"message", e.what()}};
    }
  }
  nlohmann::json first_failure;
  for (const std::string& text : AllGather(share.dump())) {
    const nlohmann::json other = nlohmann::json::parse(text);
    for (const nlohmann::json& run : other.at("runs")) {
      ElasticMeasurement& m = out.at(run.at("k").get<size_t>());
      m.youngs_modulus_pa = run.at("e").get<double>();
      m.poisson_ratio = run.at("nu").get<double>();
      m.seconds = run.at("s").get<double>();
    }
    if (other.contains("failure") &&
        (first_failure.is_null() || other["failure"].at("k").get<size_t>() < first_failure.at("k").get<size_t>()))
      first_failure = other["failure"];
  }
  if (!first_failure.is_null())
    ThrowErrorOfKind(first_failure.at("kind").get<std::string>(), first_failure.at("message").get<std::string>());
  return out;
}

template <int Dim>
StrengthMeasurement LabForwardModel<Dim>::MeasureStrength(double kn, double rn, const MicroRatios& ratios) {
  const auto start = std::chrono::steady_clock::now();
  const int rank = Rank(), ranks = RankCount();
  RoundTests tests;
  tests.material = MaterialFor(kn, rn, ratios);
  tests.bts_rank = ranks >= 2 ? 1 : 0;
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
  std::string ucs_failure, bts_failure;
  if (ranks == 1) {
    auto bts = std::async(std::launch::async, [&]() { bts_failure = run("Brazilian", bts_, bts_test, &tests.bts); });
    ucs_failure = run("UCS", ucs_, ucs_test, &tests.ucs);
    bts.get();
  } else {
    // Rank 0 the UCS, rank 1 the Brazilian test; then each sends what the calibrator reads
    // of its test (its failure, its strength, the UCS's elastic readings).
    nlohmann::json share = nlohmann::json::object();
    if (rank == 0) {
      ucs_failure = run("UCS", ucs_, ucs_test, &tests.ucs);
      const LabTestResult& u = tests.ucs;
      share = {{"ucs_failure", ucs_failure}, {"peak", u.peak_stress_pa},
               {"linear", {u.linear_elastic.measured, u.linear_elastic.youngs_modulus_pa, u.linear_elastic.poisson_ratio}},
               {"secant", {u.elastic.measured, u.elastic.youngs_modulus_pa, u.elastic.poisson_ratio}}};
    } else if (rank == tests.bts_rank) {
      bts_failure = run("Brazilian", bts_, bts_test, &tests.bts);
      share = {{"bts_failure", bts_failure}, {"tensile", tests.bts.tensile_strength_pa}};
    }
    const std::vector<std::string> all = AllGather(share.dump());
    const nlohmann::json u = nlohmann::json::parse(all[0]), b = nlohmann::json::parse(all[tests.bts_rank]);
    ucs_failure = u.at("ucs_failure").get<std::string>();
    bts_failure = b.at("bts_failure").get<std::string>();
    tests.ucs.peak_stress_pa = u.at("peak").get<double>();
    tests.ucs.linear_elastic.measured = u.at("linear")[0].get<bool>();
    tests.ucs.linear_elastic.youngs_modulus_pa = u.at("linear")[1].get<double>();
    tests.ucs.linear_elastic.poisson_ratio = u.at("linear")[2].get<double>();
    tests.ucs.elastic.measured = u.at("secant")[0].get<bool>();
    tests.ucs.elastic.youngs_modulus_pa = u.at("secant")[1].get<double>();
    tests.ucs.elastic.poisson_ratio = u.at("secant")[2].get<double>();
    tests.bts.tensile_strength_pa = b.at("tensile").get<double>();
  }
  std::string failure = ucs_failure;
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
