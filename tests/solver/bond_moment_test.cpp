// Moment-carrying bonds (bond_moment.h) against beam theory: a bond of section A, I (J) and
// axial stiffness kn = E A / L is a short beam, so
//  - under a pure moment M its ends turn by theta = M L / (E I) = M / kb, kb = kn I / A;
//  - its largest normal stress is sigma = F / A + M Rb / I, so it breaks when
//    F + M Rb A / I = Rn (2D 3 M / Rb, 3D 4 M / Rb) and, in 3D, under a twisting moment when
//    Mt Rb A / J = Rt (2 Mt / Rb);
//  - two free particles joined by it oscillate at omega^2 = kb (1/J_i + 1/J_j), and central
//    differences turn that into sin(Omega dt / 2) = omega dt / 2 exactly.
// And the time step: the stability analysis counts the bonds' rotational springs (a run at
// 0.99 of its critical step stays bounded, one at 1.01 diverges), and the energy audit
// closes with the moment's energy.

#include "solver/bond_moment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "common/error.h"
#include "solver/regular_lattice.h"
#include "solver/simulation.h"
#include "solver/stability_limits.h"

namespace specimen {
namespace {

constexpr double kRadius = 1e-3, kNormalStiffness = 7e10, kDensity = 2000.0;
constexpr double kTensileStrength = 1e4, kShearStrength = 8e3;
constexpr double kPi = 3.14159265358979323846;

template <int Dim>
MaterialParameters BondMaterial(double radius_ratio, double kt_over_kn) {
  MaterialParameters m;
  m.normal_stiffness_n_per_m = kNormalStiffness;
  m.tangential_stiffness_n_per_m = kt_over_kn * kNormalStiffness;
  m.bond_tensile_strength_n = kTensileStrength;
  m.bond_shear_strength_n = kShearStrength;
  m.friction_coefficient = 0.5;
  m.density_kg_per_m3 = kDensity;
  m.bond_radius_ratio = radius_ratio;
  return m;
}

// Particle 0 held (translations and rotation); particle 1's translations held except along
// the bond axis x when `free_axial` (its rotation is free).
template <int Dim>
SceneOptions<Dim> PairScene(const MaterialParameters& material, bool free_axial) {
  SceneOptions<Dim> scene;
  scene.material = material;
  FixedDofs<Dim> held;
  held.name = "held";
  held.particles = {0};
  held.fix_translation.fill(true);
  held.fix_rotation = true;
  FixedDofs<Dim> guided;
  guided.name = "guided";
  guided.particles = {1};
  guided.fix_translation.fill(true);
  guided.fix_translation[0] = !free_axial;
  scene.fixed_dofs = {held, guided};
  scene.contacts.detect_new_contacts = false;
  return scene;
}

// A couple of `moment` [N m] about axis (z in 2D) on particle 1, from two opposite forces at
// opposite surface points, times `amplitude`.
template <int Dim>
void AddCouple(SceneOptions<Dim>* scene, const Vector<Dim>& axis, double moment,
               const Amplitude& amplitude) {
  // Forces f at s = +-R d with d normal to the axis: s x F = 2 R f (d x e) = moment axis.
  Vector<Dim> d = Vector<Dim>::Zero(), e = Vector<Dim>::Zero();
  if constexpr (Dim == 2) {
    d = Vector<2>(0.0, 1.0);
    e = Vector<2>(-1.0, 0.0);  // (0, 1) x (-1, 0) = +1 about z
    (void)axis;
  } else {
    d = axis.unitOrthogonal();
    e = axis.cross(d);  // d x (axis x d) = axis
  }
  const double f = moment / (2.0 * kRadius);
  for (const double sign : {1.0, -1.0}) {
    PointLoad<Dim> load;
    load.name = sign > 0 ? "couple +" : "couple -";
    load.particles = {1};
    load.application_direction = sign * d;
    load.force_n = sign * f * e;
    load.amplitude = amplitude;
    scene->point_loads.push_back(load);
  }
}

template <int Dim>
Packing<Dim> Pair() {
  if constexpr (Dim == 2) {
    return SquareLatticePacking(2, 1, kRadius);
  } else {
    return CubicLatticePacking(2, 1, 1, kRadius);
  }
}

template <int Dim>
double Inertia() {
  const double mass = Dim == 2 ? kDensity * kPi * kRadius * kRadius
                               : kDensity * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;
  return (Dim == 2 ? 0.5 : 0.4) * mass * kRadius * kRadius;
}

// Pure bending, static: theta = M / kb with kb = kn Rb^2 / 3 (2D), and the bond carries M.
TEST(BondMoment, PureBendingTurnsTheEndByMOverKb) {
  for (const double lambda : {1.0, 0.5}) {
    MaterialParameters material = BondMaterial<2>(lambda, 0.0);  // kt = 0: bending alone
    material.rotational_damping = 0.7;
    SceneOptions<2> scene = PairScene<2>(material, false);
    const double moment = 0.5;  // N m per metre, well below Rn Rb / 3
    AddCouple<2>(&scene, Vector<2>::Zero(), moment, Amplitude::Ramp(2e-5));
    Simulation<2> simulation(Pair<2>(), scene);
    ASSERT_TRUE(simulation.plan().bond_moments);
    ASSERT_TRUE(simulation.plan().rotation);
    RunOptions run;
    run.max_steps = 60000;
    simulation.Run(run);
    const double rb = lambda * kRadius;
    const double kb = kNormalStiffness * rb * rb / 3.0;
    EXPECT_NEAR(simulation.particles().rotation_angle[1], moment / kb, 1e-6 * moment / kb)
        << "lambda " << lambda;
    // The moment on particle 0 (i) is +M: it balances the couple on particle 1 (j).
    EXPECT_NEAR(simulation.contacts().bond_moment[0], moment, 1e-6 * moment);
    EXPECT_EQ(simulation.contacts().state[0], ContactState::kBonded);
  }
}

// The moment at which a bond breaks, under a slowly ramped couple, with an axial force
// `axial` [N] on particle 1 (tension positive) applied first.
template <int Dim>
double BreakingMoment(const Vector<Dim>& axis, double kt_over_kn, double axial,
                      ContactState* broken_as) {
  MaterialParameters material = BondMaterial<Dim>(1.0, kt_over_kn);
  material.rotational_damping = 0.7;
  material.translational_damping = 0.7;
  SceneOptions<Dim> scene = PairScene<Dim>(material, axial != 0.0);
  // The couple grows to 2 x the largest bending strength over 1e-2 s (about 2e4 steps): per
  // step 1e-4 of it, far slower than the bond's period (a few steps).
  const double top = 2.0 * kTensileStrength * kRadius;
  AddCouple<Dim>(&scene, axis, top, Amplitude{{{1e-3, 0.0}, {1.1e-2, 1.0}}});
  if (axial != 0.0) {
    PointLoad<Dim> pull;
    pull.name = "axial";
    pull.particles = {1};
    pull.force_n = Vector<Dim>::Unit(0) * axial;
    pull.amplitude = Amplitude::Ramp(5e-4);
    scene.point_loads.push_back(pull);
  }
  Simulation<Dim> simulation(Pair<Dim>(), scene);
  double last_moment = 0.0;
  double axial_force = 0.0;
  RunOptions run;
  run.duration_s = 1.2e-2;
  run.observe_interval = 1;
  bool done = false;
  run.observer = [&]() {
    if (done) return;
    const ContactArrays<Dim>& c = simulation.contacts();
    if (c.state[0] != ContactState::kBonded) {
      *broken_as = c.state[0];
      done = true;
      return;
    }
    last_moment = AngularNorm(c.bond_moment[0]);
    axial_force = c.normal_elastic_force[0];
  };
  simulation.Run(run);
  EXPECT_TRUE(done) << "the bond did not break";
  if (axial != 0.0) {
    EXPECT_NEAR(axial_force, axial, 1e-3 * std::abs(axial));
  }
  return last_moment;
}

// Combined load (2D): the bond breaks when F + 3 M / Rb = Rn, for F = 0 (pure bending),
// F = 0.4 Rn (tension lowers the moment capacity) and F = -0.5 Rn (compression raises it).
TEST(BondMoment, BreaksOnThePeripheralStressUnderBendingAndAxialForce) {
  for (const double axial : {0.0, 0.4 * kTensileStrength, -0.5 * kTensileStrength}) {
    ContactState state = ContactState::kBonded;
    const double moment = BreakingMoment<2>(Vector<2>::Zero(), 0.0, axial, &state);
    const double expected = (kTensileStrength - axial) * kRadius / 3.0;
    EXPECT_NEAR(moment, expected, 2e-3 * expected) << "axial force " << axial;
    EXPECT_EQ(state, ContactState::kBrokenInTension);
  }
}

// 3D: bending breaks at F + 4 M / Rb = Rn, twisting at 2 Mt / Rb = Rt.
TEST(BondMoment, ThreeDimensionalBendingAndTwistingStrengths) {
  ContactState state = ContactState::kBonded;
  const double bending = BreakingMoment<3>(Vector<3>::UnitZ(), 0.0, 0.0, &state);
  EXPECT_NEAR(bending, kTensileStrength * kRadius / 4.0, 2e-3 * kTensileStrength * kRadius / 4.0);
  EXPECT_EQ(state, ContactState::kBrokenInTension);
  const double with_tension =
      BreakingMoment<3>(Vector<3>::UnitY(), 0.0, 0.25 * kTensileStrength, &state);
  EXPECT_NEAR(with_tension, 0.75 * kTensileStrength * kRadius / 4.0,
              2e-3 * kTensileStrength * kRadius / 4.0);
  const double twisting = BreakingMoment<3>(Vector<3>::UnitX(), 0.5, 0.0, &state);
  EXPECT_NEAR(twisting, kShearStrength * kRadius / 2.0, 2e-3 * kShearStrength * kRadius / 2.0);
  EXPECT_EQ(state, ContactState::kBrokenInShear);
}

// Two free particles (translations held) turning against each other: the relative rotation
// oscillates at omega^2 = k (1/J + 1/J) (k = kb, or kw for a twist in 3D); central
// differences give sin(Omega dt / 2) = omega dt / 2. Measured from the moment's zero
// crossings over many periods; the energy audit closes.
template <int Dim>
void ExpectOscillation(const Angular<Dim>& spin, double kt_over_kn, double stiffness) {
  MaterialParameters material = BondMaterial<Dim>(1.0, kt_over_kn);
  material.bond_tensile_strength_n = std::numeric_limits<double>::infinity();
  material.bond_shear_strength_n = std::numeric_limits<double>::infinity();
  SceneOptions<Dim> scene;
  scene.material = material;
  FixedDofs<Dim> held;
  held.name = "translations";
  held.particles = {0, 1};
  held.fix_translation.fill(true);
  scene.fixed_dofs = {held};
  scene.contacts.detect_new_contacts = false;
  Simulation<Dim> simulation(Pair<Dim>(), scene);
  simulation.SetAngularVelocity(1, spin);
  const double dt = simulation.time_step_s();
  const double omega = std::sqrt(stiffness * 2.0 / Inertia<Dim>());
  const double discrete = 2.0 / dt * std::asin(0.5 * omega * dt);
  std::vector<double> crossings;
  double previous = 0.0;
  long step = 0;
  RunOptions run;
  run.max_steps = 40000;
  run.observe_interval = 1;
  run.observer = [&]() {
    const ContactArrays<Dim>& c = simulation.contacts();
    const double m = AngularDot(c.bond_moment[0], spin) / AngularNorm(spin);
    ++step;
    if (step > 1 && ((previous < 0.0) != (m < 0.0))) {
      // Linear interpolation of the crossing between the two evaluations.
      crossings.push_back((step - 1 + previous / (previous - m)) * dt);
    }
    previous = m;
  };
  simulation.Run(run);
  ASSERT_GE(crossings.size(), 20u);
  const double half_period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(kPi / half_period, discrete, 1e-4 * discrete);
  const EnergyBalance e = simulation.Energy();
  EXPECT_GT(e.contact_elastic_j + e.kinetic_j, 0.0);
  EXPECT_LT(e.RelativeImbalance(), 1e-9) << e.Imbalance();
}

TEST(BondMoment, FreeRotationalOscillationHasTheBeamFrequency) {
  const double rb = kRadius;
  ExpectOscillation<2>(1.0, 0.0, kNormalStiffness * rb * rb / 3.0);
  ExpectOscillation<3>(Vector<3>(0.0, 0.0, 1.0), 0.0, kNormalStiffness * rb * rb / 4.0);
  ExpectOscillation<3>(Vector<3>(1.0, 0.0, 0.0), 0.5, 0.5 * kNormalStiffness * rb * rb / 2.0);
}

// The stability analysis with the bonds' rotational springs. On an n x n square (2D) or
// n x n x n simple cubic (3D) block with kt = 0 the rotations decouple from the translations:
// the translational limit is that of a chain, omega^2 < 4 kn / m; each rotation component
// bends the bonds normal to it, which form n x n square grids, whose graph Laplacian has the
// largest eigenvalue 2 (2 + 2 cos(pi / n)), so omega^2 = 2 (2 + 2 cos(pi / n)) kb / J with
// kb / J = (2/3) kn / m in 2D (kb = kn R^2/3, J = m R^2/2) and (5/8) kn / m in 3D (kn R^2/4,
// 2/5 m R^2): close to 16/3 and 5 kn/m, above the translational limit. The analysis finds it,
// a run at 0.99 of it stays bounded and one at 1.01 of it diverges.
template <int Dim>
void ExpectRotationalLatticeLimit(const Packing<Dim>& block, int n) {
  SceneOptions<Dim> scene;
  scene.material = BondMaterial<Dim>(1.0, 0.0);
  scene.material.bond_tensile_strength_n = std::numeric_limits<double>::infinity();
  scene.contacts.detect_new_contacts = false;
  const double mass = Dim == 2 ? kDensity * kPi * kRadius * kRadius
                               : kDensity * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;
  const double kb_over_j = (Dim == 2 ? 2.0 / 3.0 : 5.0 / 8.0) * kNormalStiffness / mass;
  const double exact = 2.0 / std::sqrt(2.0 * (2.0 + 2.0 * std::cos(kPi / n)) * kb_over_j);
  const double translational = 2.0 / std::sqrt(4.0 * kNormalStiffness / mass);
  EXPECT_LT(exact, 0.95 * translational);
  StabilityLimitOptions options;
  const StabilityLimits s = AnalyseStabilityLimits<Dim>(block, scene, options);
  EXPECT_NEAR(s.dem_time_step_ritz_s, exact, 1e-6 * exact);
  EXPECT_LE(s.critical_time_step_s, s.dem_time_step_ritz_s);
  EXPECT_GT(s.critical_time_step_s, 0.995 * exact);  // the certificate's margin
  auto run = [&](double dt) {
    SceneOptions<Dim> o = scene;
    o.time_step.time_step_s = dt;
    o.time_step.allow_above_critical = true;
    Simulation<Dim> simulation(block, o);
    std::mt19937_64 engine(5);
    std::normal_distribution<double> gaussian;
    for (int p = 0; p < block.size(); ++p) {
      Angular<Dim> spin;
      if constexpr (Dim == 2) {
        spin = gaussian(engine);
      } else {
        spin = Vector<3>(gaussian(engine), gaussian(engine), gaussian(engine));
      }
      simulation.SetAngularVelocity(p, spin);
    }
    RunOptions run_options;
    run_options.max_steps = 3000;
    try {
      simulation.Run(run_options);
    } catch (const ComputationError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(run(0.99 * s.critical_time_step_s), "");
  EXPECT_NE(run(1.01 * exact).find("diverged"), std::string::npos);
}

TEST(BondMoment, StabilityAnalysisCountsTheRotationalSprings) {
  ExpectRotationalLatticeLimit<2>(SquareLatticePacking(24, 24, kRadius), 24);
  ExpectRotationalLatticeLimit<3>(CubicLatticePacking(10, 10, 10, kRadius), 10);
}

TEST(BondMoment, RadiusRatioIsValidated) {
  MaterialParameters m = BondMaterial<2>(1.5, 0.5);
  std::string error;
  EXPECT_FALSE(m.IsValid(&error));
  EXPECT_NE(error.find("bond_radius_ratio"), std::string::npos) << error;
  m.bond_radius_ratio = -0.1;
  EXPECT_FALSE(m.IsValid(&error));
  m.bond_radius_ratio = 0.0;
  EXPECT_TRUE(m.IsValid(&error)) << error;
}

}  // namespace
}  // namespace specimen
