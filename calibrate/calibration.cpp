#include "calibrate/calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <future>
#include <limits>
#include <sstream>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "generator/generate.h"
#include "generator/metrics.h"
#include "solver/lab_measurement.h"
#include "solver/stability_analysis.h"
#include "specimen_version.h"

namespace specimen {
namespace {

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string Percent(double relative) {
  char text[32];
  std::snprintf(text, sizeof(text), "%+.2f %%", 100.0 * relative);
  return text;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

template <int Dim>
PackingDescriptors Describe(const Packing<Dim>& packing) {
  return DescribePacking<Dim>(ComputePackingMetrics<Dim>(packing));
}

// --- Specimens --------------------------------------------------------------------------

template <int Dim>
Domain<Dim> DefaultUcsDomain() {
  if constexpr (Dim == 2) return Domain<2>::Rectangle(0.0, 0.0, 0.05, 0.05);
  else return Domain<3>::Cylinder(0.0, 0.0, 0.025, 0.0, 0.1);
}

// The Brazilian specimen matching a UCS specimen: a disc (cylinder of length D/2) whose
// diameter is the UCS specimen's width, centred on it.
template <int Dim>
Domain<Dim> BrazilianDomainFor(const Domain<Dim>& ucs) {
  const Vector<Dim> lower = ucs.Lower(), upper = ucs.Upper();
  const double diameter = upper[0] - lower[0];
  Vector<2> centre((lower[0] + upper[0]) / 2, (lower[1] + upper[1]) / 2);
  if constexpr (Dim == 2) {
    return Domain<2>::Disc(centre, diameter / 2);
  } else {
    if (ucs.shape() == DomainShape::kCylinder) centre = ucs.CircleCentre();
    const double radius = ucs.shape() == DomainShape::kCylinder ? ucs.CircleRadius() : diameter / 2;
    return Domain<3>::Cylinder(centre[0], centre[1], radius, 0.0, radius);
  }
}

// The same shape scaled by `s` about its lower corner (circles about their centre).
template <int Dim>
Domain<Dim> ScaledDomain(const Domain<Dim>& d, double s) {
  const Vector<Dim> lower = d.Lower(), upper = d.Upper();
  if constexpr (Dim == 2) {
    if (d.shape() == DomainShape::kDisc) return Domain<2>::Disc(d.CircleCentre(), s * d.CircleRadius());
    if (d.shape() == DomainShape::kRectangle)
      return Domain<2>::Rectangle(lower[0], lower[1], lower[0] + s * (upper[0] - lower[0]),
                                  lower[1] + s * (upper[1] - lower[1]));
    std::vector<Vector<2>> vertices;
    for (const Vector<2>& v : d.PolygonVertices()) vertices.push_back(lower + s * (v - lower));
    return Domain<2>::Polygon(vertices);
  } else {
    if (d.shape() == DomainShape::kCylinder)
      return Domain<3>::Cylinder(d.CircleCentre()[0], d.CircleCentre()[1], s * d.CircleRadius(), d.ZMin(),
                                 d.ZMin() + s * (d.ZMax() - d.ZMin()));
    return Domain<3>::Box(lower, lower + s * (upper - lower));
  }
}

template <int Dim>
Packing<Dim> Generate(const Domain<Dim>& domain, int count, double mean_radius, const SpecimenPlan<Dim>& plan,
                      const std::string& what) {
  GeneratorOptions options = DefaultGeneratorOptions<Dim>();
  if (count > 0) options.particle_count = count;
  else options.mean_radius = mean_radius;
  options.radius_ratio = plan.radius_ratio;
  options.node_size_spread = std::min(options.node_size_spread, plan.radius_ratio);
  options.seed = plan.seed;
  options.num_threads = plan.threads;
  if (plan.progress)
    options.progress = [&](double f, const std::string& m) { plan.progress(f, what + ": " + m); };
  GeneratorSummary summary;
  return GeneratePacking<Dim>(domain, options, &summary);
}

// --- Maps -------------------------------------------------------------------------------

nlohmann::json ProtocolJson(const LabTestOptions& t) {
  nlohmann::json j = {{"loading_rate_group", t.loading_rate_group},
          {"platen_speed_m_per_s", t.platen_speed_m_per_s},
          {"post_peak_stress_fraction", t.post_peak_stress_fraction},
          {"modulus_window", {t.modulus_window_low, t.modulus_window_high}},
          {"local_damping", t.local_damping},
          {"dashpot_ratio", t.dashpot_ratio},
          {"scale_density", t.scale_density},
          {"platen_stiffness_ratio", t.platen_stiffness_ratio},
          {"platen_friction", t.platen_friction},
          {"pause_kinetic_energy_ratio", t.pause_kinetic_energy_ratio},
          {"max_pause_transits", t.max_pause_transits},
          {"velocity_ramp_transits", t.velocity_ramp_transits},
          {"strain_boundary_margin", t.strain_boundary_margin}};
  // Only when used, so that maps stored before inertia scaling existed keep their key.
  if (t.mass_scaling_budget > 0.0) j["mass_scaling_budget"] = t.mass_scaling_budget;
  if (t.time_step_safety_factor != LabTestOptions().time_step_safety_factor)
    j["time_step_safety_factor"] = t.time_step_safety_factor;
  return j;
}

nlohmann::json SweepSpecimenJson(const PackingDescriptors& ucs, const PackingDescriptors& bts, std::uint64_t seed,
                                 const std::string& ucs_domain, const std::string& bts_domain) {
  // Rounded descriptors: the same generation on another machine hashes alike.
  auto round = [](double v, int digits) {
    const double f = std::pow(10.0, digits - 1 - std::floor(std::log10(std::abs(v) + 1e-300)));
    return std::round(v * f) / f;
  };
  return {{"ucs_domain", ucs_domain}, {"bts_domain", bts_domain}, {"seed", seed},
          {"ucs_particles", ucs.particles}, {"bts_particles", bts.particles},
          {"ucs_porosity", round(ucs.porosity, 3)}, {"ucs_coordination", round(ucs.coordination, 3)}};
}

// Largest and smallest of the nu surface and the largest strength ratio over the box.
ModelReach ReachOf(const StoredMaps& stored) {
  ModelReach reach;
  reach.built = true;
  const MapSet& maps = stored.maps;
  const int n = static_cast<int>(maps.inputs.size());
  const Eigen::VectorXd lower = maps.Lower(), upper = maps.Upper();
  const int per_axis = n <= 2 ? 41 : (n == 3 ? 17 : 9);
  reach.poisson_min = std::numeric_limits<double>::infinity();
  reach.poisson_max = -reach.poisson_min;
  std::vector<int> index(n, 0);
  for (;;) {
    Eigen::VectorXd x(n);
    for (int k = 0; k < n; ++k) x[k] = lower[k] + (upper[k] - lower[k]) * index[k] / (per_axis - 1);
    const double nu = maps.poisson_ratio.Evaluate(x);
    reach.poisson_min = std::min(reach.poisson_min, nu);
    reach.poisson_max = std::max(reach.poisson_max, nu);
    const double t = maps.tensile_group.Evaluate(x);
    if (t > 0) reach.strength_ratio_max = std::max(reach.strength_ratio_max, maps.compressive_group.Evaluate(x) / t);
    int k = 0;
    while (k < n && ++index[k] == per_axis) index[k++] = 0;
    if (k == n) break;
  }
  for (const SweepPoint& p : stored.points)
    if (p.ok) {
      reach.poisson_max_measured = std::max(reach.poisson_max_measured, p.poisson_ratio);
      reach.strength_ratio_max_measured =
          std::max(reach.strength_ratio_max_measured, p.ucs_pa / p.tensile_strength_pa);
    }
  return reach;
}

// kn/(Ep l) at rho(B) = max_spectral_radius for nu_p on a packing (stability_analysis.h).
template <int Dim>
double AdmissibleParticleCompliance(const Packing<Dim>& packing, double kn, double density, double nu_p,
                                    PlaneModel plane_model, double max_spectral_radius) {
  SceneOptions<Dim> scene;
  scene.material.normal_stiffness_n_per_m = kn;
  scene.material.tangential_stiffness_n_per_m = 0.0;
  scene.material.density_kg_per_m3 = density;
  scene.material.plane_model = plane_model;
  const double length = Dim == 2 ? 1.0 : VolumeMeanRadius<Dim>(packing.radii);
  scene.material.particle_youngs_modulus_pa = kn / (0.01 * length);
  scene.material.particle_poisson_ratio = nu_p;
  StabilityOptions options;
  options.max_spectral_radius = max_spectral_radius;
  options.locate_mode = false;
  const StabilitySummary s = AnalyseStability<Dim>(packing, scene, options);
  return s.recommended_kn_over_ep;
}

// The stored verification on a specimen equivalent to `specimen` whose measured nu and
// strength ratio are closest to the target (weights as the inversion's); null if none.
const VerifiedPoint* ClosestVerifiedPoint(const StoredMaps& stored, const TargetMaterial& target,
                                          const PackingDescriptors& specimen) {
  const InversionOptions weights;
  const VerifiedPoint* best = nullptr;
  double best_error = std::numeric_limits<double>::infinity();
  for (const VerifiedPoint& v : stored.verified) {
    if (!MapsMatchPacking(v.specimen, specimen, nullptr)) continue;
    const double e_nu = v.poisson_ratio / target.poisson_ratio - 1.0;
    const double e_ratio = (v.compressive_group / v.tensile_group) / target.StrengthRatio() - 1.0;
    const double error = weights.poisson_weight * e_nu * e_nu + weights.strength_ratio_weight * e_ratio * e_ratio;
    if (error < best_error) best_error = error, best = &v;
  }
  return best;
}

// The default design with `levels` on kt/kn and one fewer (at least 3) on the other axes.
SweepDesign WithLevels(SweepDesign design, int levels) {
  if (levels <= 0) return design;
  for (SweepAxis& axis : design.axes)
    axis.levels = axis.ratio == MicroRatio::kStiffnessRatio ? levels : std::max(3, levels - 1);
  return design;
}

struct Measured {
  LabTestResult ucs, bts;
};

// UCS and BTS at once (two threads), one solver thread each.
template <int Dim>
Measured RunPair(const CalibrationSpecimens<Dim>& s, const MaterialParameters& material,
                 const CalibrationOptions& options, const std::string& label) {
  LabTestOptions test = options.test;
  test.num_threads = 1;
  test.check_quasi_static = false;
  test.record_snapshots = true;
  test.progress = nullptr;
  if (test.strain_limit == 0.0) test.strain_limit = 0.05;  // as the sweep (map_sweep.cpp)
  LabTestOptions ucs_test = test, bts_test = test;
  ucs_test.kind = LabTestKind::kUniaxialCompression;
  bts_test.kind = LabTestKind::kBrazilian;
  if (options.progress)
    ucs_test.progress = [&](double f, const std::string& m) { options.progress(f, label + " UCS: " + m); };
  auto bts = std::async(std::launch::async, [&]() { return RunLabTest<Dim>(s.bts, material, bts_test); });
  Measured m;
  m.ucs = RunLabTest<Dim>(s.ucs, material, ucs_test);
  m.bts = bts.get();
  return m;
}

// The verification's E and nu: secants over [low, high] x the target UCS, the stresses at
// which the rock's own E and nu were measured, rather than x the specimen's peak. A bonded
// specimen's peak is path dependent by 1-4 %, and where damage starts below the window's end
// the secant nu follows that end steeply: 2D DDEM, target nu 0.27, two rounds with equal
// parameters gave peaks 109.5 and 114.3 MPa and nu 0.273 and 0.287; on the second curve the
// window of the first peak gives 0.274. At the target's stresses E and nu vary smoothly with
// the parameters. When the specimen fails below the window's end, its own peak is used.
template <int Dim>
ElasticConstantsMeasured ElasticAtTargetStresses(const LabTestResult& ucs, double target_ucs_pa,
                                                 const LabTestOptions& test, bool* at_target) {
  CurvePeak reference = FindPeak(ucs.curve, test.post_peak_stress_fraction);
  reference.control = target_ucs_pa;  // UCS: the control quantity is the axial stress
  const ElasticConstantsMeasured e = SecantElasticConstants<Dim>(ucs.curve, reference, Dim - 1, test.modulus_window_low,
                                                                 test.modulus_window_high);
  *at_target = e.measured;
  return e.measured ? e : ucs.elastic;
}

}  // namespace

const char* CalibrationModelName(CalibrationModel model) {
  switch (model) {
    case CalibrationModel::kRigid: return "rigid";
    case CalibrationModel::kDeformable: return "ddem";
    case CalibrationModel::kAutomatic: return "auto";
  }
  return "?";
}

bool ParseCalibrationModel(const std::string& name, CalibrationModel* model) {
  for (CalibrationModel m : {CalibrationModel::kRigid, CalibrationModel::kDeformable, CalibrationModel::kAutomatic})
    if (name == CalibrationModelName(m)) {
      *model = m;
      return true;
    }
  return false;
}

template <int Dim>
bool SpecimenPlan<Dim>::IsValid(std::string* error) const {
  std::ostringstream out;
  if (ucs_particles < 0 || ucs_particles > 2000000)
    out << "ucs_particles = " << ucs_particles << ", allowed 0 (default) to 2,000,000";
  else if (!(sweep_fraction > 0.0 && sweep_fraction <= 1.0))
    out << "sweep_fraction = " << sweep_fraction << ", allowed (0, 1]";
  else if (!(radius_ratio >= 1.0 && radius_ratio <= 100.0))
    out << "radius_ratio = " << radius_ratio << ", allowed [1, 100]";
  else if (threads < 1 || threads > 256)
    out << "threads = " << threads << ", allowed 1 to 256";
  if (out.str().empty() && !ucs_domain.empty()) {
    try {
      const Domain<Dim> d = Domain<Dim>::Parse(ucs_domain);
      const bool ok = Dim == 2 ? d.shape() == DomainShape::kRectangle
                               : (d.shape() == DomainShape::kCylinder || d.shape() == DomainShape::kBox);
      if (!ok)
        out << "ucs_domain '" << ucs_domain << "': a UCS specimen is a rectangle (2D), a cylinder or a box (3D)";
    } catch (const InputError& e) {
      out << "ucs_domain: " << e.what();
    }
  }
  if (error) *error = out.str();
  return out.str().empty();
}

template <int Dim>
CalibrationSpecimens<Dim> MakeCalibrationSpecimens(const SpecimenPlan<Dim>& plan) {
  std::string error;
  if (!plan.IsValid(&error)) throw InputError(error);
  const Domain<Dim> ucs_domain = plan.ucs_domain.empty() ? DefaultUcsDomain<Dim>() : Domain<Dim>::Parse(plan.ucs_domain);
  const int count = plan.ucs_particles > 0 ? plan.ucs_particles : (Dim == 2 ? 5000 : 20000);
  Packing<Dim> ucs = Generate<Dim>(ucs_domain, count, 0.0, plan, "UCS specimen");
  const double mean_radius = VolumeMeanRadius<Dim>(ucs.radii);
  const Domain<Dim> bts_domain = BrazilianDomainFor(ucs_domain);
  Packing<Dim> bts = Generate<Dim>(bts_domain, 0, mean_radius, plan, "Brazilian specimen");
  std::ostringstream text;
  text << "UCS " << ucs_domain.ToShortText() << " (" << ucs.size() << " particles), Brazilian " << bts_domain.ToShortText()
       << " (" << bts.size() << ")";
  if (plan.sweep_fraction >= 1.0) {
    text << "; maps on the same specimens; seed " << plan.seed;
    CalibrationSpecimens<Dim> s(ucs, bts, ucs, bts);
    s.description = text.str();
    return s;
  }
  const double scale = std::pow(plan.sweep_fraction, 1.0 / Dim);
  const Domain<Dim> sweep_ucs_domain = ScaledDomain(ucs_domain, scale);
  const Domain<Dim> sweep_bts_domain = ScaledDomain(bts_domain, scale);
  Packing<Dim> sweep_ucs = Generate<Dim>(sweep_ucs_domain, 0, mean_radius, plan, "map UCS specimen");
  Packing<Dim> sweep_bts = Generate<Dim>(sweep_bts_domain, 0, mean_radius, plan, "map Brazilian specimen");
  text << "; maps on UCS " << sweep_ucs_domain.ToShortText() << " (" << sweep_ucs.size() << "), Brazilian "
       << sweep_bts_domain.ToShortText() << " (" << sweep_bts.size() << "); seed " << plan.seed;
  CalibrationSpecimens<Dim> s(std::move(ucs), std::move(bts), std::move(sweep_ucs), std::move(sweep_bts));
  s.description = text.str();
  return s;
}

CalibrationOptions::CalibrationOptions() { test.scale_density = true; }

bool CalibrationOptions::IsValid(std::string* error) const {
  std::ostringstream out;
  std::string inner;
  if (max_total_degree < 1 || max_total_degree > 4)
    out << "max_total_degree = " << max_total_degree << ", allowed 1 to 4";
  else if (sweep_levels != 0 && (sweep_levels < 3 || sweep_levels > 12))
    out << "sweep_levels = " << sweep_levels << ", allowed 0 (default) or 3 to 12";
  else if (!(particle_poisson_ratio > -1.0 && particle_poisson_ratio < 0.5))
    out << "particle_poisson_ratio = " << particle_poisson_ratio << ", allowed (-1, 0.5)";
  else if (!(friction_coefficient >= 0.0 && friction_coefficient <= 10.0))
    out << "friction_coefficient = " << friction_coefficient << ", allowed [0, 10]";
  else if (workers < 0 || workers > 256)
    out << "workers = " << workers << ", allowed 0 (all hardware threads) to 256";
  else if (!(max_spectral_radius > 0.0 && max_spectral_radius < 1.0))
    out << "max_spectral_radius = " << max_spectral_radius << ", allowed (0, 1)";
  else if (max_verification_rounds < 1 || max_verification_rounds > 20)
    out << "max_verification_rounds = " << max_verification_rounds << ", allowed 1 to 20";
  else if (!(tolerance_youngs > 0 && tolerance_poisson > 0 && tolerance_ucs > 0 && tolerance_tensile > 0 &&
             tolerance_youngs < 1 && tolerance_poisson < 1 && tolerance_ucs < 1 && tolerance_tensile < 1))
    out << "tolerances (E " << tolerance_youngs << ", nu " << tolerance_poisson << ", UCS " << tolerance_ucs
        << ", sigma_t " << tolerance_tensile << "): each allowed (0, 1)";
  else if (!rigid_design.axes.empty() && !rigid_design.IsValid(&inner))
    out << "rigid " << inner;
  else if (!deformable_design.axes.empty() && !deformable_design.IsValid(&inner))
    out << "deformable " << inner;
  else if (!test.IsValid(&inner))
    out << inner;
  if (error) *error = out.str();
  return out.str().empty();
}

template <int Dim>
CalibrationSummary CalibrateToMaterial(const CalibrationSpecimens<Dim>& specimens, const TargetMaterial& target,
                                       const CalibrationOptions& options) {
  const auto start = Clock::now();
  std::string error;
  if (!target.IsValid(&error)) throw InputError(error);
  if (!options.IsValid(&error)) throw InputError(error);

  CalibrationSummary summary;
  summary.dimension = Dim;
  summary.target = target;
  summary.model_requested = CalibrationModelName(options.model);
  summary.ucs_descriptors = Describe(specimens.ucs);
  summary.bts_descriptors = Describe(specimens.bts);
  const PackingDescriptors sweep_ucs = Describe(specimens.sweep_ucs);
  const PackingDescriptors sweep_bts = Describe(specimens.sweep_bts);
  const double group_length = Dim == 2 ? 1.0 : summary.ucs_descriptors.mean_radius;
  const PlaneModel plane_model = PlaneModel::kPlaneStrain;

  // Reference constants of the sweep, from the groups of Labra's 2D verification (Psi_E about
  // 0.25, Psi_c about 0.7): near the target, so the peaks come well within the strain limit.
  const double reference_kn = NormalStiffnessFromElasticGroup(sweep_ucs, target.youngs_modulus_pa, 0.25);
  const double reference_rn = BondStrengthFromStrengthGroup(sweep_ucs, target.ucs_pa, 0.7);

  // --- 1. Maps --------------------------------------------------------------------------
  const nlohmann::json protocol = ProtocolJson(options.test);
  const nlohmann::json sweep_specimen =
      SweepSpecimenJson(sweep_ucs, sweep_bts, specimens.sweep_ucs.seed, specimens.sweep_ucs.domain.ToText(),
                        specimens.sweep_bts.domain.ToText());
  const int workers = options.workers > 0 ? options.workers
                                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));

  auto obtain_maps = [&](bool deformable, const SweepDesign& design, const std::string& label) {
    StoredMaps stored;
    const std::string key = MapKey(Dim, deformable, design, protocol, sweep_specimen, options.max_total_degree);
    std::string path;
    if (!options.maps_directory.empty())
      path = (std::filesystem::path(options.maps_directory) / MapFileName(Dim, deformable, key)).string();
    if (options.reuse_maps && !path.empty() && std::filesystem::exists(path)) {
      stored = LoadStoredMaps(path);
      std::string why;
      if (stored.dimension == Dim && stored.deformable == deformable &&
          MapsMatchPacking(stored.ucs_descriptors, summary.ucs_descriptors, &why)) {
        summary.maps_reused = true;
        summary.maps_path = path;
        return stored;
      }
      summary.notes.push_back("stored maps " + path + " not reused: " + why);
    }
    MapSweepOptions sweep_options;
    sweep_options.normal_stiffness_n_per_m = reference_kn;
    sweep_options.bond_tensile_strength_n = reference_rn;
    sweep_options.density_kg_per_m3 = target.density_kg_per_m3;
    sweep_options.plane_model = plane_model;
    sweep_options.test = options.test;
    sweep_options.workers = workers;
    if (!path.empty()) {
      std::filesystem::create_directories(options.maps_directory);
      sweep_options.journal_path = path + ".journal";
    }
    if (options.progress)
      sweep_options.progress = [&](double f, const std::string& m) { options.progress(f, label + ": " + m); };
    const auto sweep_start = Clock::now();
    const MapSweep sweep = RunMapSweep<Dim>(specimens.sweep_ucs, specimens.sweep_bts, design, sweep_options);
    summary.sweep_seconds += SecondsSince(sweep_start);
    stored.dimension = Dim;
    stored.deformable = deformable;
    stored.code_version = kVersion;
    stored.created_utc = UtcNow();
    stored.key = key;
    stored.specimen = sweep_specimen;
    stored.protocol = protocol;
    stored.ucs_descriptors = sweep.ucs_descriptors;
    stored.bts_descriptors = sweep.bts_descriptors;
    stored.design = design;
    stored.max_total_degree = options.max_total_degree;
    stored.points = sweep.points;
    stored.sweep_seconds = sweep.seconds;
    if (sweep.failed_points > 0)
      summary.notes.push_back(std::to_string(sweep.failed_points) + " of " + std::to_string(sweep.points.size()) +
                              " " + label + " points failed and were left out of the fit");
    stored.maps = FitMaps(sweep, design, options.max_total_degree);
    if (!path.empty()) {
      SaveStoredMaps(stored, path);
      std::filesystem::remove(sweep_options.journal_path);
      summary.maps_path = path;
    }
    return stored;
  };

  auto load_given_maps = [&]() {
    StoredMaps stored = LoadStoredMaps(options.maps_file);
    std::string why;
    if (stored.dimension != Dim)
      throw InputError("maps " + options.maps_file + " are " + std::to_string(stored.dimension) + "D, the calibration is " +
                       std::to_string(Dim) + "D");
    if (!MapsMatchPacking(stored.ucs_descriptors, summary.ucs_descriptors, &why))
      throw InputError("maps " + options.maps_file + " were built for another packing: " + why);
    summary.maps_reused = true;
    summary.maps_path = options.maps_file;
    return stored;
  };

  double admissible = 0.0;
  auto deformable_design = [&]() {
    admissible = AdmissibleParticleCompliance<Dim>(specimens.sweep_ucs, reference_kn, target.density_kg_per_m3,
                                                   options.particle_poisson_ratio, plane_model,
                                                   options.max_spectral_radius);
    summary.admissible_particle_compliance = admissible;
    if (!options.deformable_design.axes.empty()) return options.deformable_design;
    return WithLevels(DefaultSweepDesign(true, options.particle_poisson_ratio, admissible, options.friction_coefficient),
                      options.sweep_levels);
  };

  StoredMaps chosen;
  if (!options.maps_file.empty()) {
    chosen = load_given_maps();
    summary.model_used = chosen.deformable ? "ddem" : "rigid";
    summary.model_reason = "maps given";
    (chosen.deformable ? summary.deformable_reach : summary.rigid_reach) = ReachOf(chosen);
    if (chosen.deformable)
      admissible = AdmissibleParticleCompliance<Dim>(specimens.sweep_ucs, reference_kn, target.density_kg_per_m3,
                                                     chosen.design.fixed.particle_poisson_ratio, plane_model,
                                                     options.max_spectral_radius);
  } else {
    StoredMaps rigid;
    if (options.model != CalibrationModel::kDeformable) {
      const SweepDesign design = options.rigid_design.axes.empty()
                                     ? WithLevels(DefaultSweepDesign(false, 0.0, 0.0, options.friction_coefficient),
                                                  options.sweep_levels)
                                     : options.rigid_design;
      rigid = obtain_maps(false, design, "rigid maps");
      summary.rigid_reach = ReachOf(rigid);
    }
    bool use_deformable = options.model == CalibrationModel::kDeformable;
    if (options.model == CalibrationModel::kAutomatic) {
      const double margin = 0.5 * options.tolerance_poisson * target.poisson_ratio;
      use_deformable = target.poisson_ratio > summary.rigid_reach.poisson_max - margin ||
                       target.poisson_ratio < summary.rigid_reach.poisson_min + margin;
      char reason[240];
      std::snprintf(reason, sizeof(reason), "target nu %.4g %s the rigid-particle range [%.4g, %.4g] on this packing",
                    target.poisson_ratio, use_deformable ? "is outside" : "lies within",
                    summary.rigid_reach.poisson_min, summary.rigid_reach.poisson_max);
      summary.model_reason = reason;
    } else {
      summary.model_reason = "requested";
    }
    if (use_deformable) {
      const SweepDesign design = deformable_design();
      chosen = obtain_maps(true, design, "deformable maps");
      summary.deformable_reach = ReachOf(chosen);
      summary.model_used = "ddem";
    } else {
      chosen = rigid;
      summary.model_used = "rigid";
    }
  }
  summary.maps = chosen;

  // --- 2. Inversion ---------------------------------------------------------------------
  InversionOptions inversion;
  inversion.honour = options.honour;
  inversion.relative_tolerance = 0.25 * options.tolerance_poisson;
  if (chosen.deformable) {
    const double limit = admissible;
    inversion.admissible_particle_compliance = [limit](double) { return limit; };
  }
  summary.inversion = InvertMaps(chosen.maps, summary.ucs_descriptors, target, inversion);
  // A verification stored with the maps on an equivalent specimen (map_store.h) whose
  // measured nu and sigma_c/sigma_t are close to the target is a better start than the maps:
  // its ratios were measured on a real specimen, and kn, Rn follow from its measured groups
  // exactly (E ~ kn, strengths ~ Rn at fixed ratios). The maps' slopes are good guides but
  // their offsets do not transfer between points (damage in the secant window).
  if (const VerifiedPoint* stored = ClosestVerifiedPoint(chosen, target, summary.ucs_descriptors)) {
    if (std::abs(stored->poisson_ratio / target.poisson_ratio - 1.0) <= 3.0 * options.tolerance_poisson) {
      InversionResult& r = summary.inversion;
      r.ratios = stored->ratios;
      r.normal_stiffness = NormalStiffnessFromElasticGroup(summary.ucs_descriptors, target.youngs_modulus_pa,
                                                           stored->elastic_group);
      r.tangential_stiffness = r.ratios.tangential_to_normal_stiffness * r.normal_stiffness;
      const bool compressive = r.strength_ratio_reached || options.honour == HonouredStrength::kCompressive;
      r.bond_tensile_strength =
          compressive ? BondStrengthFromStrengthGroup(summary.ucs_descriptors, target.ucs_pa, stored->compressive_group)
                      : BondStrengthFromStrengthGroup(summary.bts_descriptors, target.tensile_strength_pa,
                                                      stored->tensile_group);
      r.bond_shear_strength = r.ratios.shear_to_tensile_strength * r.bond_tensile_strength;
      if (r.ratios.normal_stiffness_to_particle > 0)
        r.particle_youngs_modulus = r.normal_stiffness / (r.ratios.normal_stiffness_to_particle * group_length);
      summary.transfer_corrected = true;
      char note[300];
      std::snprintf(note, sizeof(note),
                    "started from a verification stored with the maps (nu %.4f, sigma_c/sigma_t %.3f measured on an "
                    "equivalent specimen) instead of the maps' prediction",
                    stored->poisson_ratio,
                    stored->compressive_group / stored->tensile_group *
                        (summary.bts_descriptors.SolidCoordination() / summary.bts_descriptors.CharacteristicArea()) /
                        (summary.ucs_descriptors.SolidCoordination() / summary.ucs_descriptors.CharacteristicArea()));
      summary.notes.push_back(note);
    }
  }
  summary.tensile_honoured = summary.inversion.strength_ratio_reached;
  for (const std::string& note : summary.inversion.notes) summary.notes.push_back(note);

  // --- 3. Verification and correction ---------------------------------------------------
  MicroRatios ratios = summary.inversion.ratios;
  double kn = summary.inversion.normal_stiffness;
  double rn = summary.inversion.bond_tensile_strength;
  // 3D: the inversion's Ep assumes l = 1 m; MaterialAt uses the group length.
  const HonouredStrength honoured = summary.inversion.strength_ratio_reached ? HonouredStrength::kCompressive
                                                                           : options.honour;
  const Eigen::VectorXd lower = chosen.maps.Lower(), upper = chosen.maps.Upper();
  auto at = [&](const MicroRatios& r) {
    const std::vector<double> x = chosen.maps.InputsOf(r);
    return Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())).eval();
  };

  Measured last;
  for (int round = 1; round <= options.max_verification_rounds; ++round) {
    VerificationRound v;
    v.round = round;
    v.ratios = ratios;
    v.material = MaterialAt(ratios, kn, rn, target.density_kg_per_m3, plane_model, group_length);
    const auto round_start = Clock::now();
    last = RunPair<Dim>(specimens, v.material, options,
                        "verification " + std::to_string(round) + "/" + std::to_string(options.max_verification_rounds));
    v.seconds = SecondsSince(round_start);
    v.ucs_peak_reached = last.ucs.peak_reached;
    v.bts_peak_reached = last.bts.peak_reached;
    if (!last.ucs.elastic.measured || !last.ucs.peak_reached || !last.bts.peak_reached)
      throw ComputationError("verification round " + std::to_string(round) + ": the " +
                             (!last.bts.peak_reached && last.ucs.peak_reached ? "Brazilian" : "UCS") +
                             " test reached its strain limit without a peak");
    const ElasticConstantsMeasured elastic =
        ElasticAtTargetStresses<Dim>(last.ucs, target.ucs_pa, options.test, &v.window_at_target);
    v.youngs_modulus_pa = elastic.youngs_modulus_pa;
    v.poisson_ratio = elastic.poisson_ratio;
    v.own_peak_youngs_modulus_pa = last.ucs.elastic.youngs_modulus_pa;
    v.own_peak_poisson_ratio = last.ucs.elastic.poisson_ratio;
    v.ucs_pa = last.ucs.peak_stress_pa;
    v.tensile_strength_pa = last.bts.tensile_strength_pa;
    v.error_youngs = v.youngs_modulus_pa / target.youngs_modulus_pa - 1.0;
    v.error_poisson = v.poisson_ratio / target.poisson_ratio - 1.0;
    v.error_ucs = v.ucs_pa / target.ucs_pa - 1.0;
    v.error_tensile = v.tensile_strength_pa / target.tensile_strength_pa - 1.0;
    if (round == 1) {
      summary.transfer_error_youngs = v.youngs_modulus_pa / summary.inversion.youngs_modulus - 1.0;
      summary.transfer_error_poisson = v.poisson_ratio / summary.inversion.poisson_ratio - 1.0;
      summary.transfer_error_ucs = v.ucs_pa / summary.inversion.ucs - 1.0;
      summary.transfer_error_tensile = v.tensile_strength_pa / summary.inversion.tensile_strength - 1.0;
    }
    const bool poisson_ok = std::abs(v.error_poisson) <= options.tolerance_poisson;
    const bool strength_ok = honoured == HonouredStrength::kCompressive
                                 ? std::abs(v.error_ucs) <= options.tolerance_ucs
                                 : std::abs(v.error_tensile) <= options.tolerance_tensile;
    bool tensile_ok = !summary.tensile_honoured || std::abs(v.error_tensile) <= options.tolerance_tensile;
    const bool others_ok = std::abs(v.error_youngs) <= options.tolerance_youngs && poisson_ok && strength_ok;
    summary.rounds.push_back(v);
    // The corrections of the ratios (header comment, step 3), applied below when the loop
    // goes on: nu by kt/kn (and kn/(Ep l)), sigma_c / sigma_t by Rt/Rn.
    std::optional<PoissonCorrection> poisson_correction, ratio_correction;
    if (!poisson_ok) {
      std::vector<PoissonRound> history;
      for (const VerificationRound& r : summary.rounds) history.push_back({r.ratios, r.poisson_ratio});
      poisson_correction = CorrectPoisson(chosen.maps, history, target.poisson_ratio);
    }
    if (!tensile_ok) {
      std::vector<StrengthRatioRound> history;
      for (const VerificationRound& r : summary.rounds) history.push_back({r.ratios, r.ucs_pa / r.tensile_strength_pa});
      ratio_correction = CorrectStrengthRatio(chosen.maps, poisson_correction ? poisson_correction->next : ratios,
                                              history, target.StrengthRatio());
      // Both strengths honoured, but Rt/Rn cannot move sigma_c / sigma_t towards the target
      // (at the end of the maps' box, or not an input of the maps): the ratio is out of reach
      // on this specimen, though the maps' specimens promised it. sigma_t is then reported,
      // not corrected: rounds spent on it would change nothing.
      if (ratio_correction->unremoved_share >= 0.99) {
        summary.tensile_honoured = false;
        tensile_ok = true;
        std::ostringstream note;
        note << "sigma_c / sigma_t = " << target.StrengthRatio() << " is not reachable on this specimen: round "
             << round << " measured " << v.ucs_pa / v.tensile_strength_pa << " with Rt/Rn "
             << v.ratios.shear_to_tensile_strength
             << ", and the maps do not let Rt/Rn move further towards it (the end of their box, or not one of their inputs); "
                "sigma_t is reported, no longer corrected ("
             << Percent(v.error_tensile) << ")";
        summary.notes.push_back(note.str());
      }
    }
    summary.converged = others_ok && tensile_ok;
    if (summary.converged || round == options.max_verification_rounds) break;

    // Corrections (header comment, step 3).
    std::ostringstream what;
    MicroRatios next = ratios;
    if (poisson_correction) {
      next = poisson_correction->next;
      what << poisson_correction->what;
    }
    // Both strengths honoured: Rt/Rn holds sigma_c / sigma_t (Rn then follows the UCS).
    if (!tensile_ok) {
      next = ratio_correction->next;
      what << ratio_correction->what;
    }
    // How E/kn and strength/Rn change with the ratio change: from the last two rounds when
    // kt/kn moved between them (measured on this specimen), else from the maps.
    const Eigen::VectorXd x_old = at(ratios), x_new = at(next);
    const bool compressive = honoured == HonouredStrength::kCompressive;
    const ResponseSurface& strength_map = compressive ? chosen.maps.compressive_group : chosen.maps.tensile_group;
    double elastic_change = chosen.maps.elastic_group.Evaluate(x_new) / chosen.maps.elastic_group.Evaluate(x_old);
    double strength_change = strength_map.Evaluate(x_new) / strength_map.Evaluate(x_old);
    const size_t n = summary.rounds.size();
    const double dx_next = next.tangential_to_normal_stiffness - ratios.tangential_to_normal_stiffness;
    if (n >= 2 && dx_next != 0.0) {
      const VerificationRound& a = summary.rounds[n - 2];
      const double dx = v.ratios.tangential_to_normal_stiffness - a.ratios.tangential_to_normal_stiffness;
      if (std::abs(dx) > 1e-6) {
        auto secant_change = [&](double value_a, double value_b) {  // of value per unit of its scale
          const double slope = (value_b - value_a) / dx;
          const double predicted = value_b + slope * dx_next;
          return predicted > 0.0 ? std::clamp(predicted / value_b, 0.5, 2.0) : 1.0;
        };
        elastic_change = secant_change(a.youngs_modulus_pa / a.material.normal_stiffness_n_per_m,
                                       v.youngs_modulus_pa / v.material.normal_stiffness_n_per_m);
        strength_change =
            compressive ? secant_change(a.ucs_pa / a.material.bond_tensile_strength_n,
                                        v.ucs_pa / v.material.bond_tensile_strength_n)
                        : secant_change(a.tensile_strength_pa / a.material.bond_tensile_strength_n,
                                        v.tensile_strength_pa / v.material.bond_tensile_strength_n);
        // The secant is along kt/kn; a move of Rt/Rn in the same round adds the maps' part.
        MicroRatios kt_only = next;
        kt_only.shear_to_tensile_strength = ratios.shear_to_tensile_strength;
        strength_change *= strength_map.Evaluate(x_new) / strength_map.Evaluate(at(kt_only));
      }
    }
    const double new_kn = kn * (target.youngs_modulus_pa / v.youngs_modulus_pa) / elastic_change;
    const double strength_factor = compressive ? target.ucs_pa / v.ucs_pa
                                               : target.tensile_strength_pa / v.tensile_strength_pa;
    const double new_rn = rn * strength_factor / strength_change;
    what << "kn x " << new_kn / kn << ", Rn x " << new_rn / rn;
    summary.rounds.back().correction = what.str();
    kn = new_kn;
    rn = new_rn;
    ratios = next;
  }
  const VerificationRound& final_round = summary.rounds.back();
  summary.material = final_round.material;
  summary.final_ucs = last.ucs;
  summary.final_bts = last.bts;
  // Keep what the real specimen measured with the maps (the next calibration starts near).
  {
    VerifiedPoint v;
    v.ratios = final_round.ratios;
    v.specimen = summary.ucs_descriptors;
    v.poisson_ratio = final_round.poisson_ratio;
    v.elastic_group = ElasticGroup(summary.ucs_descriptors, final_round.youngs_modulus_pa,
                                   final_round.material.normal_stiffness_n_per_m);
    v.compressive_group = StrengthGroup(summary.ucs_descriptors, final_round.ucs_pa,
                                        final_round.material.bond_tensile_strength_n);
    v.tensile_group = StrengthGroup(summary.bts_descriptors, final_round.tensile_strength_pa,
                                    final_round.material.bond_tensile_strength_n);
    summary.maps.verified.push_back(v);
    constexpr size_t kMaxVerified = 50;
    if (summary.maps.verified.size() > kMaxVerified)
      summary.maps.verified.erase(summary.maps.verified.begin());
    if (!summary.maps_path.empty() && options.maps_file.empty()) SaveStoredMaps(summary.maps, summary.maps_path);
  }
  if (!summary.converged)
    summary.notes.push_back("the verification budget (" + std::to_string(options.max_verification_rounds) +
                            " rounds) was spent before every honoured target was within tolerance");

  // --- 4. Stability of the final set ----------------------------------------------------
  {
    SceneOptions<Dim> scene;
    scene.material = summary.material;
    scene.material.density_kg_per_m3 = last.ucs.density_used_kg_per_m3;
    scene.material.translational_damping = scene.material.rotational_damping = options.test.local_damping;
    scene.material.normal_dashpot_ratio = scene.material.tangential_dashpot_ratio = options.test.dashpot_ratio;
    scene.material.mass_scaling_budget = options.test.mass_scaling_budget;  // as the tests ran
    StabilityOptions stability;
    stability.max_spectral_radius = options.max_spectral_radius;
    stability.proposed_time_step_s = last.ucs.time_step_s;
    stability.locate_mode = false;
    const StabilitySummary s = AnalyseStability<Dim>(specimens.ucs, scene, stability);
    summary.stability_verdict = s.verdict;
    summary.stability_binding_limit = s.binding_limit;
    summary.stability_margin_percent = s.margin_percent;
    summary.stability_message = s.verdict_message;
    summary.critical_time_step_s = s.critical_time_step_s;
    summary.time_step_s = s.judged_time_step_s;
    summary.spectral_radius = s.spectral_radius;
  }
  summary.seconds = SecondsSince(start);
  return summary;
}

// --- Reports ----------------------------------------------------------------------------

std::string CalibrationSummary::BriefReport() const {
  char line[400];
  if (rounds.empty()) return "calibration: no verification run\n";
  const VerificationRound& v = rounds.back();
  std::snprintf(line, sizeof(line),
                "%dD %s calibration to '%s': E %s, nu %s, UCS %s, sigma_t %s%s after %zu verification round%s; "
                "stability %s; %.1f s",
                dimension, model_used.c_str(), target.name.c_str(), Percent(v.error_youngs).c_str(),
                Percent(v.error_poisson).c_str(), Percent(v.error_ucs).c_str(), Percent(v.error_tensile).c_str(),
                tensile_honoured ? "" : " (not honoured)", rounds.size(), rounds.size() == 1 ? "" : "s",
                stability_verdict.c_str(), seconds);
  return line;
}

std::string CalibrationSummary::FullReport() const {
  std::ostringstream out;
  char line[400];
  auto row = [&](const char* label, const std::string& value) {
    std::snprintf(line, sizeof(line), "  %-38s %s\n", label, value.c_str());
    out << line;
  };
  auto num = [](const char* format, double value) {
    char text[64];
    std::snprintf(text, sizeof(text), format, value);
    return std::string(text);
  };
  out << "Calibration to material (" << dimension << "D)\n";
  row("target", target.name);
  row("model", model_used + " (requested " + model_requested + "; " + model_reason + ")");
  row("UCS specimen", std::to_string(ucs_descriptors.particles) + " particles, porosity " +
                          num("%.4f", ucs_descriptors.porosity) + ", nc " + num("%.3f", ucs_descriptors.coordination));
  row("Brazilian specimen", std::to_string(bts_descriptors.particles) + " particles, porosity " +
                                num("%.4f", bts_descriptors.porosity));
  out << "maps\n";
  row("file", maps_path.empty() ? "(not stored)" : maps_path);
  row("reused", maps_reused ? "yes (built by " + maps.code_version + ", " + maps.created_utc + ")" : "no, built now");
  int ok = 0;
  for (const SweepPoint& p : maps.points) ok += p.ok ? 1 : 0;
  row("sweep points (succeeded / total)", std::to_string(ok) + " / " + std::to_string(maps.points.size()) + " on " +
                                             std::to_string(maps.ucs_descriptors.particles) + " + " +
                                             std::to_string(maps.bts_descriptors.particles) + " particles");
  row("sweep wall time", num("%.1f s", maps_reused ? maps.sweep_seconds : sweep_seconds) +
                             (maps_reused ? " (when built)" : ""));
  row("fit error nu (leave-one-out RMS)", num("%.4f", maps.maps.poisson_ratio.leave_one_out_rms()));
  // Relative fit errors: leave-one-out RMS over the mean group value of the sweep.
  auto relative_fit = [&](const ResponseSurface& surface, double SweepPoint::*group) {
    double sum = 0.0;
    int count = 0;
    for (const SweepPoint& p : maps.points)
      if (p.ok) sum += std::abs(p.*group), ++count;
    return num("%.2f %%", count > 0 && sum > 0 ? 100.0 * surface.leave_one_out_rms() * count / sum : 0.0);
  };
  row("fit error Psi_E / Psi_c / Psi_t (rel.)",
      relative_fit(maps.maps.elastic_group, &SweepPoint::elastic_group) + " / " +
          relative_fit(maps.maps.compressive_group, &SweepPoint::compressive_group) + " / " +
          relative_fit(maps.maps.tensile_group, &SweepPoint::tensile_group));
  if (rigid_reach.built)
    row("rigid particles: nu reach", num("%.4f", rigid_reach.poisson_min) + " to " + num("%.4f", rigid_reach.poisson_max) +
                                         " (largest measured " + num("%.4f", rigid_reach.poisson_max_measured) +
                                         "), sigma_c/sigma_t up to " + num("%.2f", rigid_reach.strength_ratio_max_measured));
  if (deformable_reach.built)
    row("DDEM: nu reach", num("%.4f", deformable_reach.poisson_min) + " to " + num("%.4f", deformable_reach.poisson_max) +
                              " (largest measured " + num("%.4f", deformable_reach.poisson_max_measured) +
                              ") with kn/(Ep l) <= " + num("%.4g", admissible_particle_compliance));
  out << inversion.FullReport();
  out << "verification (target / achieved / error)\n";
  for (const VerificationRound& v : rounds) {
    std::snprintf(line, sizeof(line),
                  "  round %d: E %.4g GPa (%s), nu %.4f (%s), UCS %.4g MPa (%s), sigma_t %.4g MPa (%s), %.0f s\n",
                  v.round, v.youngs_modulus_pa / 1e9, Percent(v.error_youngs).c_str(), v.poisson_ratio,
                  Percent(v.error_poisson).c_str(), v.ucs_pa / 1e6, Percent(v.error_ucs).c_str(),
                  v.tensile_strength_pa / 1e6, Percent(v.error_tensile).c_str(), v.seconds);
    out << line;
    std::snprintf(line, sizeof(line), "           E, nu over %s; over the specimen's own peak: E %.4g GPa, nu %.4f\n",
                  v.window_at_target ? "the window x the target UCS" : "the window x the peak (failed below it)",
                  v.own_peak_youngs_modulus_pa / 1e9, v.own_peak_poisson_ratio);
    out << line;
    if (!v.correction.empty()) out << "           correction: " << v.correction << "\n";
  }
  if (!rounds.empty()) {
    const VerificationRound& v = rounds.back();
    std::snprintf(line, sizeof(line), "  %-10s %14s %14s %10s\n", "", "target", "achieved", "error");
    out << line;
    auto compare = [&](const char* name, double t, double a, double e, const char* unit, double scale) {
      std::snprintf(line, sizeof(line), "  %-10s %10.4g %-3s %10.4g %-3s %10s\n", name, t / scale, unit, a / scale, unit,
                    Percent(e).c_str());
      out << line;
    };
    compare("E", target.youngs_modulus_pa, v.youngs_modulus_pa, v.error_youngs, "GPa", 1e9);
    compare("nu", target.poisson_ratio, v.poisson_ratio, v.error_poisson, "", 1.0);
    compare("UCS", target.ucs_pa, v.ucs_pa, v.error_ucs, "MPa", 1e6);
    compare("sigma_t", target.tensile_strength_pa, v.tensile_strength_pa, v.error_tensile, "MPa", 1e6);
  }
  row("transfer error of the map specimens", "E " + Percent(transfer_error_youngs) + ", nu " +
                                                 Percent(transfer_error_poisson) + ", UCS " +
                                                 Percent(transfer_error_ucs) + ", sigma_t " +
                                                 Percent(transfer_error_tensile));
  row("started from a stored verification", transfer_corrected ? "yes" : "no");
  row("converged", converged ? "yes" : "no");
  out << "parameters\n";
  row("kn, kt [N/m]", num("%.6g", material.normal_stiffness_n_per_m) + ", " + num("%.6g", material.tangential_stiffness_n_per_m));
  row("Rn, Rt [N]", num("%.6g", material.bond_tensile_strength_n) + ", " + num("%.6g", material.bond_shear_strength_n));
  row("mu", num("%.4g", material.friction_coefficient));
  row("Ep [Pa], nu_p", material.particle_youngs_modulus_pa ? num("%.6g", *material.particle_youngs_modulus_pa) + ", " +
                                                                 num("%.4g", material.particle_poisson_ratio)
                                                           : "rigid particles");
  row("density [kg/m^3]", num("%.6g", material.density_kg_per_m3) + " (scaled in the tests: " +
                              num("%.6g", final_ucs.density_used_kg_per_m3) + ")");
  out << "stability (UCS specimen, final set)\n";
  row("verdict", stability_verdict + " (binding: " + stability_binding_limit + ", margin " +
                     num("%.1f %%", stability_margin_percent) + ")");
  row("time step used / critical", num("%.4g s", time_step_s) + " / " + num("%.4g s", critical_time_step_s));
  if (material.particle_youngs_modulus_pa) row("rho(B)", num("%.4f", spectral_radius));
  for (const std::string& note : notes) out << "  note: " << note << "\n";
  row("wall time", num("%.1f s", seconds));
  return out.str();
}

nlohmann::json CalibrationSummary::ToJson() const {
  nlohmann::json j;
  j["dimension"] = dimension;
  j["target"] = TargetMaterialToJson(target);
  j["model"] = {{"requested", model_requested}, {"used", model_used}, {"reason", model_reason}};
  j["specimens"] = {{"ucs", DescriptorsToJson(ucs_descriptors)}, {"bts", DescriptorsToJson(bts_descriptors)}};
  auto reach = [](const ModelReach& r) {
    return nlohmann::json{{"built", r.built},
                          {"poisson_min", r.poisson_min},
                          {"poisson_max", r.poisson_max},
                          {"poisson_max_measured", r.poisson_max_measured},
                          {"strength_ratio_max", r.strength_ratio_max},
                          {"strength_ratio_max_measured", r.strength_ratio_max_measured}};
  };
  j["maps"] = {{"file", maps_path},
               {"reused", maps_reused},
               {"code_version", maps.code_version},
               {"created_utc", maps.created_utc},
               {"sweep_points", maps.points.size()},
               {"sweep_seconds", sweep_seconds},
               {"fit_leave_one_out_rms",
                {{"poisson_ratio", maps.maps.poisson_ratio.leave_one_out_rms()},
                 {"elastic_group", maps.maps.elastic_group.leave_one_out_rms()},
                 {"compressive_group", maps.maps.compressive_group.leave_one_out_rms()},
                 {"tensile_group", maps.maps.tensile_group.leave_one_out_rms()}}},
               {"rigid_reach", reach(rigid_reach)},
               {"deformable_reach", reach(deformable_reach)},
               {"admissible_kn_over_ep_l", admissible_particle_compliance}};
  j["inversion"] = inversion.ToJson();
  j["verification"] = nlohmann::json::array();
  for (const VerificationRound& v : rounds)
    j["verification"].push_back({{"round", v.round},
                                 {"kn", v.material.normal_stiffness_n_per_m},
                                 {"kt", v.material.tangential_stiffness_n_per_m},
                                 {"rn", v.material.bond_tensile_strength_n},
                                 {"rt", v.material.bond_shear_strength_n},
                                 {"youngs_modulus_pa", v.youngs_modulus_pa},
                                 {"poisson_ratio", v.poisson_ratio},
                                 {"elastic_window_at_target_ucs", v.window_at_target},
                                 {"own_peak_window", {{"youngs_modulus_pa", v.own_peak_youngs_modulus_pa},
                                                      {"poisson_ratio", v.own_peak_poisson_ratio}}},
                                 {"ucs_pa", v.ucs_pa},
                                 {"tensile_strength_pa", v.tensile_strength_pa},
                                 {"relative_errors",
                                  {{"youngs_modulus", v.error_youngs},
                                   {"poisson_ratio", v.error_poisson},
                                   {"ucs", v.error_ucs},
                                   {"tensile_strength", v.error_tensile}}},
                                 {"seconds", v.seconds},
                                 {"correction", v.correction}});
  j["transfer_error"] = {{"youngs_modulus", transfer_error_youngs},
                         {"poisson_ratio", transfer_error_poisson},
                         {"ucs", transfer_error_ucs},
                         {"tensile_strength", transfer_error_tensile}};
  j["transfer_corrected"] = transfer_corrected;
  j["converged"] = converged;
  j["tensile_honoured"] = tensile_honoured;
  nlohmann::json parameters = {{"normal_stiffness_n_per_m", material.normal_stiffness_n_per_m},
                               {"tangential_stiffness_n_per_m", material.tangential_stiffness_n_per_m},
                               {"bond_tensile_strength_n", material.bond_tensile_strength_n},
                               {"bond_shear_strength_n", material.bond_shear_strength_n},
                               {"friction_coefficient", material.friction_coefficient},
                               {"density_kg_per_m3", material.density_kg_per_m3}};
  if (material.particle_youngs_modulus_pa) {
    parameters["particle_youngs_modulus_pa"] = *material.particle_youngs_modulus_pa;
    parameters["particle_poisson_ratio"] = material.particle_poisson_ratio;
  }
  j["parameters"] = parameters;
  j["stability"] = {{"verdict", stability_verdict},
                    {"binding_limit", stability_binding_limit},
                    {"margin_percent", stability_margin_percent},
                    {"message", stability_message},
                    {"critical_time_step_s", critical_time_step_s},
                    {"time_step_s", time_step_s},
                    {"spectral_radius", spectral_radius}};
  j["notes"] = notes;
  j["seconds"] = seconds;
  j["code_version"] = kVersion;
  return j;
}

template struct SpecimenPlan<2>;
template struct SpecimenPlan<3>;
template CalibrationSpecimens<2> MakeCalibrationSpecimens<2>(const SpecimenPlan<2>&);
template CalibrationSpecimens<3> MakeCalibrationSpecimens<3>(const SpecimenPlan<3>&);
template CalibrationSummary CalibrateToMaterial<2>(const CalibrationSpecimens<2>&, const TargetMaterial&,
                                                   const CalibrationOptions&);
template CalibrationSummary CalibrateToMaterial<3>(const CalibrationSpecimens<3>&, const TargetMaterial&,
                                                   const CalibrationOptions&);

}  // namespace specimen
