#include "calibrate/intact_elastic.h"

#include <chrono>
#include <limits>

#include "common/error.h"

namespace specimen {

LabTestOptions ElasticRunOptions(const LabTestOptions& protocol) {
  LabTestOptions o = protocol;
  o.kind = LabTestKind::kUniaxialCompression;
  o.strain_limit = 1.5e-3;
  o.sample_interval_steps = 50;
  o.check_quasi_static = false;
  o.record_snapshots = false;
  o.num_threads = 1;
  o.progress = nullptr;
  return o;
}

template <int Dim>
ElasticMeasurement MeasureIntactElasticConstants(const Packing<Dim>& ucs, MaterialParameters material,
                                                 const LabTestOptions& protocol) {
  const auto start = std::chrono::steady_clock::now();
  material.bond_tensile_strength_n = std::numeric_limits<double>::infinity();
  material.bond_shear_strength_n = std::numeric_limits<double>::infinity();
  const LabTestResult r = RunLabTest<Dim>(ucs, material, ElasticRunOptions(protocol));
  if (!r.linear_elastic.measured)
    throw ComputationError("the elastic run measured no linear portion (" + std::to_string(r.curve.size()) +
                           " samples): " + r.termination_message);
  ElasticMeasurement m;
  m.youngs_modulus_pa = r.linear_elastic.youngs_modulus_pa;
  m.poisson_ratio = r.linear_elastic.poisson_ratio;
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return m;
}

template ElasticMeasurement MeasureIntactElasticConstants<2>(const Packing<2>&, MaterialParameters,
                                                             const LabTestOptions&);
template ElasticMeasurement MeasureIntactElasticConstants<3>(const Packing<3>&, MaterialParameters,
                                                             const LabTestOptions&);

}  // namespace specimen
