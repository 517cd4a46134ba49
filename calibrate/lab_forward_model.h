#pragma once
// The forward model of a calibration on real specimens (forward_model.h): the virtual
// laboratory (lab/lab_test.h) on the UCS specimen and the Brazilian disc.
//
//  - Elastic runs (intact_elastic.h), two at once on two workers.
//  - Strength rounds: the UCS and the Brazilian test at once, one solver thread each, as the
//    map sweep runs them.
//
// Under mpirun (common/ranks.h) every rank calls the same measurements: the elastic runs of a
// batch are split over the ranks (run k on rank k % N) and gathered, and a strength round
// runs its UCS on rank 0 and its Brazilian test on rank 1; every rank gets the same
// measurements (so its calibrator takes the same steps).
//
//   LabForwardModel<2> model(specimens.ucs, specimens.bts, settings);
//   ElasticMeasurement e = model.MeasureElastic({{kn, ratios}}).front();

#include <mutex>
#include <string>
#include <vector>

#include "calibrate/forward_model.h"
#include "calibrate/intact_elastic.h"
#include "common/progress.h"
#include "generator/packing.h"
#include "lab/lab_test.h"
#include "solver/material.h"

namespace specimen {

struct LabForwardModelSettings {
  LabTestOptions protocol;       // of every test (kind, strain limit, progress set per test)
  double density_kg_per_m3 = 0;  // rho of the target, > 0 (scaled per test when the protocol says)
  PlaneModel plane_model = PlaneModel::kPlaneStrain;
  double group_length_m = 1.0;   // l of kn/(Ep l): 1 m in 2D, the mean radius in 3D
  int workers = 2;               // elastic runs at once, >= 1
  ProgressCallback progress;     // may be empty
};

template <int Dim>
class LabForwardModel : public ForwardModel {
 public:
  // The packings must outlive the model.
  LabForwardModel(const Packing<Dim>& ucs_specimen, const Packing<Dim>& bts_specimen, LabForwardModelSettings settings);

  std::vector<ElasticMeasurement> MeasureElastic(const std::vector<ElasticQuery>& queries) override;
  StrengthMeasurement MeasureStrength(double normal_stiffness, double bond_tensile_strength,
                                      const MicroRatios& ratios) override;

  // The tests of every strength round so far, in order (for the outputs of the best one); a
  // round whose test failed is kept with its failure (MeasureStrength threw it).
  // With several ranks a rank holds only the test it ran: rank 0 the UCS, rank bts_rank (1)
  // the Brazilian test (whose outputs it writes: a LabTestResult carries the curve, the
  // broken bonds and two snapshots of every particle, which are not sent).
  struct RoundTests {
    MaterialParameters material;
    LabTestResult ucs, bts;
    int bts_rank = 0;
    std::string failure;  // empty when both tests measured their strength
  };
  const std::vector<RoundTests>& strength_tests() const { return strength_tests_; }
  MaterialParameters MaterialFor(double normal_stiffness, double bond_tensile_strength,
                                 const MicroRatios& ratios) const;

 private:
  const Packing<Dim>& ucs_;
  const Packing<Dim>& bts_;
  LabForwardModelSettings settings_;
  std::vector<RoundTests> strength_tests_;
};

}  // namespace specimen
