// The forward model of the calibration (calibrate/lab_forward_model.h): a run the solver
// refuses at micro parameters the calibration chose is the calibration's own failure.

#include "calibrate/lab_forward_model.h"

#include <gtest/gtest.h>

#include <string>

#include "common/error.h"
#include "generator/generate.h"

namespace specimen {
namespace {

// kn/(Ep l) far past the DDEM convergence bound: the solver refuses the scene (InputError), and
// the forward model reports it as a ComputationError (status 4), naming the chosen point.
TEST(LabForwardModel, ARefusedChosenPointIsAComputationFailure) {
  GeneratorOptions g = DefaultGeneratorOptions<2>();
  g.particle_count = 200;
  g.seed = 3;
  const Packing<2> ucs = GeneratePacking<2>(Domain<2>::Rectangle(0.0, 0.0, 0.01, 0.01), g, nullptr);
  const Packing<2> bts = GeneratePacking<2>(Domain<2>::Disc(Vector<2>(0.005, 0.005), 0.005), g, nullptr);
  LabForwardModelSettings settings;
  settings.density_kg_per_m3 = 2600.0;
  settings.workers = 1;
  LabForwardModel<2> model(ucs, bts, settings);
  ElasticQuery query;
  query.normal_stiffness = 1e10;
  query.ratios.tangential_to_normal_stiffness = 0.3;
  query.ratios.friction_coefficient = 0.5;
  query.ratios.normal_stiffness_to_particle = 50.0;
  query.ratios.particle_poisson_ratio = 0.45;
  try {
    model.MeasureElastic({query});
    FAIL() << "a point past the convergence bound was run";
  } catch (const ComputationError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("failure of the calibration"), std::string::npos) << message;
    EXPECT_NE(message.find("kn/(Ep l) 50"), std::string::npos) << message;
  } catch (const InputError& e) {
    FAIL() << "reported as bad input: " << e.what();
  }
}

}  // namespace
}  // namespace specimen
