#include "calibrate/calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <limits>
#include <sstream>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/ranks.h"
#include "generator/generate.h"
#include "generator/metrics.h"
#include "calibrate/lab_forward_model.h"
#include "lab/lab_measurement.h"
#include "stability/stability_analysis.h"
#include "specimen_version.h"

namespace specimen {
namespace {

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

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
          {"strain_boundary_margin", t.strain_boundary_margin},
          // E and nu of the maps and of the calibration (intact_elastic.h).
          {"elastic_reading", {{"run", "UCS, unbreakable bonds, strain 1.5e-3"},
                               {"linear_portion_low", t.linear_portion_low}}}};
  // Only when used, so that maps stored before inertia scaling existed keep their key.
  if (t.mass_scaling_budget > 0.0) j["mass_scaling_budget"] = t.mass_scaling_budget;
  if (t.time_step_safety_factor != LabTestOptions().time_step_safety_factor)
    j["time_step_safety_factor"] = t.time_step_safety_factor;
  if (t.loading_arc_deg > 0.0) j["loading_arc_deg"] = t.loading_arc_deg;  // flat platens: as before
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

// kn/(Ep l) at rho(B) = max_spectral_radius for nu_p on a packing (stability_analysis.h).
template <int Dim>
double AdmissibleParticleCompliance(const Packing<Dim>& packing, double kn, double density, double nu_p,
                                    PlaneModel plane_model, double max_spectral_radius, double bond_range) {
  SceneOptions<Dim> scene;
  scene.material.normal_stiffness_n_per_m = kn;
  scene.material.tangential_stiffness_n_per_m = 0.0;
  scene.material.density_kg_per_m3 = density;
  scene.material.plane_model = plane_model;
  const double length = Dim == 2 ? 1.0 : VolumeMeanRadius<Dim>(packing.radii);
  scene.material.particle_youngs_modulus_pa = kn / (0.01 * length);
  scene.material.particle_poisson_ratio = nu_p;
  scene.material.bond_range = bond_range;  // the bonds at range are links of the DDEM iteration too
  StabilityOptions options;
  options.max_spectral_radius = max_spectral_radius;
  options.locate_mode = false;
  const StabilitySummary s = AnalyseStability<Dim>(packing, scene, options);
  return s.recommended_kn_over_ep;
}

// The default design with `levels` on kt/kn and one fewer (at least 3) on the other axes.
SweepDesign WithLevels(SweepDesign design, int levels) {
  if (levels <= 0) return design;
  for (SweepAxis& axis : design.axes)
    axis.levels = axis.ratio == MicroRatio::kStiffnessRatio ? levels : std::max(3, levels - 1);
  return design;
}

// A default design with its kt/kn box replaced (CalibrationOptions::stiffness_ratio_lower,
// upper; both 0 keeps it).
SweepDesign WithStiffnessBox(SweepDesign design, double lower, double upper) {
  if (lower == 0.0 && upper == 0.0) return design;
  for (SweepAxis& axis : design.axes)
    if (axis.ratio == MicroRatio::kStiffnessRatio) axis.lower = lower, axis.upper = upper;
  return design;
}

// A number every rank must agree on (a bound that sets the design, and so the sweep's points
// and the maps' key), computed on rank 0 and sent to the others: one computation, and the
// same bits everywhere even if it ran threads whose order is not reproducible.
template <typename Compute>
double OnRankZero(Compute compute) {
  return Broadcast(Rank() == 0 ? compute() : 0.0);
}

// Which reach is better when neither model reaches the target: the one that reaches nu,
// then the one whose strength ratio is possible, then the smaller gap of the ratio.
// Progress of the loop (its own fraction) and of the test running in it (within the share
// of a strength round), as one display.
struct ProgressRelay {
  ProgressCallback out;
  double share = 0.0, span = 0.0;
  std::string label;
  void Loop(double fraction, const std::string& message) {
    share = fraction, label = message;
    if (out) out(fraction, message);
  }
  void Test(double fraction, const std::string& message) const {
    if (out) out(share + span * fraction, label + " - " + message);
  }
};
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
  else if (!(stiffness_ratio_lower == 0.0 && stiffness_ratio_upper == 0.0) &&
           !(stiffness_ratio_lower > 0.0 && stiffness_ratio_lower < stiffness_ratio_upper &&
             stiffness_ratio_upper <= 1.0))
    out << "stiffness_ratio_lower, upper = " << stiffness_ratio_lower << ", " << stiffness_ratio_upper
        << ": the kt/kn box, allowed 0 < lower < upper <= 1 (both 0: the default box)";
  else if (!(particle_poisson_ratio > -1.0 && particle_poisson_ratio < 0.5))
    out << "particle_poisson_ratio = " << particle_poisson_ratio << ", allowed (-1, 0.5)";
  else if (!(friction_coefficient >= 0.0 && friction_coefficient <= 10.0))
    out << "friction_coefficient = " << friction_coefficient << ", allowed [0, 10]";
  else if (anchor_levels != 2 && anchor_levels != 3)
    out << "anchor_levels = " << anchor_levels << ", allowed 2 or 3";
  else if (anchor_levels != 2 && !maps_file.empty())
    out << "anchor_levels = " << anchor_levels << " with a given maps file: its anchors are read as stored "
        << "(anchors are completed in the maps directory only); allowed 2";
  else if (!(bond_range >= 1.0 && bond_range <= 1.5))
    out << "bond_range = " << bond_range << ", allowed [1, 1.5]";
  else if (workers < 0 || workers > 256)
    out << "workers = " << workers << ", allowed 0 (all hardware threads) to 256";
  else if (!(max_spectral_radius > 0.0 && max_spectral_radius < 1.0))
    out << "max_spectral_radius = " << max_spectral_radius << ", allowed (0, 1)";
  else if (max_verification_rounds < 1 || max_verification_rounds > 20)
    out << "max_verification_rounds = " << max_verification_rounds << ", allowed 1 to 20";
  else if (max_elastic_runs < 4 || max_elastic_runs > 100)
    out << "max_elastic_runs = " << max_elastic_runs << ", allowed 4 to 100";
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
  const bool separate_map_specimens = specimens.sweep_ucs.size() != specimens.ucs.size() ||
                                      specimens.sweep_bts.size() != specimens.bts.size();
  // Reference kn of the stability bound (any: the bound is on kn/(Ep l)).
  const double reference_kn = NormalStiffnessFromElasticGroup(sweep_ucs, target.youngs_modulus_pa, 0.25);

  // --- 1. Maps --------------------------------------------------------------------------
  const nlohmann::json protocol = ProtocolJson(options.test);
  const nlohmann::json sweep_specimen =
      SweepSpecimenJson(sweep_ucs, sweep_bts, specimens.sweep_ucs.seed, specimens.sweep_ucs.domain.ToText(),
                        specimens.sweep_bts.domain.ToText());
  const int workers = options.workers > 0 ? options.workers
                                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));

  // Reference constants of a sweep on `ucs`, from the groups of Labra's 2D verification
  // (Psi_E about 0.25, Psi_c about 0.7): near the target, so the peaks come well within the
  // strain limit and the time step and rate are realistic.
  auto sweep_options_for = [&](const PackingDescriptors& ucs, const std::string& label) {
    MapSweepOptions o;
    o.normal_stiffness_n_per_m = NormalStiffnessFromElasticGroup(ucs, target.youngs_modulus_pa, 0.25);
    o.bond_tensile_strength_n = BondStrengthFromStrengthGroup(ucs, target.ucs_pa, 0.7);
    o.density_kg_per_m3 = target.density_kg_per_m3;
    o.plane_model = plane_model;
    o.test = options.test;
    o.workers = workers;
    if (options.progress)
      o.progress = [&options, label](double f, const std::string& m) { options.progress(f, label + ": " + m); };
    return o;
  };

  // The transfer anchors of the maps' design (map_sweep.h) that `stored` lacks for these real
  // specimens (anchors of an equivalent specimen count, MapsMatchPacking, as the surrogate
  // takes them): the same tests on the real specimens, stored with the maps. Returns how many
  // were measured.
  auto measure_anchors = [&](StoredMaps* stored, const std::string& path, const std::string& label) {
    if (!separate_map_specimens) return 0;
    auto same = [](const MicroRatios& a, const MicroRatios& b) {
      for (MicroRatio r : {MicroRatio::kStiffnessRatio, MicroRatio::kStrengthRatio, MicroRatio::kFriction,
                           MicroRatio::kParticleCompliance, MicroRatio::kParticlePoisson})
        if (std::abs(RatioValue(a, r) - RatioValue(b, r)) > 1e-9 * (1.0 + std::abs(RatioValue(b, r)))) return false;
      return true;
    };
    std::vector<MicroRatios> missing;
    for (const MicroRatios& r : TransferAnchorPoints(stored->design, options.anchor_levels)) {
      bool present = false;
      for (const VerifiedPoint& v : stored->verified)
        present = present || (v.origin == "anchor" && same(v.ratios, r) &&
                              MapsMatchPacking(v.specimen, summary.ucs_descriptors, nullptr));
      if (!present) missing.push_back(r);
    }
    if (missing.empty()) return 0;
    MapSweepOptions anchor_options = sweep_options_for(summary.ucs_descriptors, label + ", transfer anchors");
    if (!path.empty()) anchor_options.journal_path = path + ".anchors.journal";
    const MapSweep anchors = RunSweepPoints<Dim>(specimens.ucs, specimens.bts, missing, anchor_options);
    int measured = 0;
    for (const SweepPoint& p : anchors.points) {
      if (!p.ok) continue;
      VerifiedPoint v;
      v.ratios = p.ratios;
      v.specimen = summary.ucs_descriptors;
      v.poisson_ratio = p.poisson_ratio;
      v.elastic_group = p.elastic_group;
      v.compressive_group = p.compressive_group;
      v.tensile_group = p.tensile_group;
      v.origin = "anchor";
      stored->verified.insert(stored->verified.begin() + measured, v);  // anchors first, as built
      ++measured;
    }
    if (Rank() == 0) RemoveSweepJournals(anchor_options.journal_path);
    return measured;
  };

  // The maps of one model, reused or built; *where is their file (empty: not stored) and
  // *reused whether they were found there. With --model auto both models' maps may be
  // obtained: only the chosen model's file takes the calibration's runs at the end.
  auto obtain_maps = [&](bool deformable, const SweepDesign& design, const std::string& label, std::string* where,
                         bool* reused) {
    StoredMaps stored;
    *reused = false;
    where->clear();
    const std::string key = MapKey(Dim, deformable, design, protocol, sweep_specimen, options.max_total_degree);
    std::string path;
    if (!options.maps_directory.empty()) {
      path = (std::filesystem::path(options.maps_directory) / MapFileName(Dim, deformable, key)).string();
      if (options.reuse_maps) {
        const std::string found = FindStoredMapFile(options.maps_directory, Dim, deformable, key);
        if (!found.empty()) path = found;
      }
    }
    if (options.reuse_maps && !path.empty() && std::filesystem::exists(path)) {
      stored = LoadStoredMaps(path);
      std::string why;
      if (stored.dimension != Dim)
        why = "the file holds " + std::to_string(stored.dimension) + "D maps";
      else if (stored.deformable != deformable)
        why = std::string("the file holds the maps of ") + (stored.deformable ? "DDEM" : "rigid particles");
      if (why.empty() && MapsMatchPacking(stored.ucs_descriptors, sweep_ucs, &why)) {
        *reused = true;
        *where = path;
        // Anchors the stored maps lack: anchor_levels 3 on maps built with 2, or real
        // specimens other than those the maps were anchored on.
        const auto start = Clock::now();
        if (measure_anchors(&stored, path, label) > 0) {
          const double seconds = SecondsSince(start);
          stored.sweep_seconds += seconds;
          summary.sweep_seconds += seconds;
          if (Rank() == 0) SaveStoredMaps(stored, path);
        }
        return stored;
      }
      summary.notes.push_back("stored maps " + path + " not reused: " + why);
    }
    MapSweepOptions sweep_options = sweep_options_for(sweep_ucs, label);
    if (!path.empty()) {
      // Rank 0 writes every file of the store; the other ranks only their sweep journals,
      // after the sweep's first exchange (so after this).
      if (Rank() == 0) std::filesystem::create_directories(options.maps_directory);
      sweep_options.journal_path = path + ".journal";
    }
    const auto sweep_start = Clock::now();
    const MapSweep sweep = RunMapSweep<Dim>(specimens.sweep_ucs, specimens.sweep_bts, design, sweep_options);
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
    if (sweep.failed_points > 0)
      summary.notes.push_back(std::to_string(sweep.failed_points) + " of " + std::to_string(sweep.points.size()) +
                              " " + label + " points failed and were left out of the fit");
    stored.maps = FitMaps(sweep, design, options.max_total_degree);
    measure_anchors(&stored, path, label);
    stored.sweep_seconds = SecondsSince(sweep_start);
    summary.sweep_seconds += stored.sweep_seconds;
    if (!path.empty()) {
      if (Rank() == 0) {
        SaveStoredMaps(stored, path);
        RemoveSweepJournals(sweep_options.journal_path);
      }
      *where = path;
    }
    return stored;
  };

  auto load_given_maps = [&]() {
    StoredMaps stored = LoadStoredMaps(options.maps_file);
    std::string why;
    if (!stored.protocol.contains("elastic_reading"))
      throw InputError("maps " + options.maps_file + " were built by an older version that read E and nu as secants "
                       "over 1-50 % of the peak (damage included); build them again (--no-reuse)");
    if (stored.dimension != Dim)
      throw InputError("maps " + options.maps_file + " are " + std::to_string(stored.dimension) + "D, the calibration is " +
                       std::to_string(Dim) + "D");
    if (!MapsMatchPacking(stored.ucs_descriptors, sweep_ucs, &why))
      throw InputError("maps " + options.maps_file + " were built for another packing: " + why);
    summary.maps_reused = true;
    summary.maps_path = options.maps_file;
    return stored;
  };

  // The DDEM bound kn/(Ep l) at rho(B) = max, at the maps' nu_p: on the map specimen for the
  // design's box, on the real specimens (both) for the calibration.
  auto admissible_on_real = [&](double nu_p) {
    return OnRankZero([&] { return std::min(AdmissibleParticleCompliance<Dim>(specimens.ucs, reference_kn, target.density_kg_per_m3, nu_p,
                                                      plane_model, options.max_spectral_radius, options.bond_range),
                    AdmissibleParticleCompliance<Dim>(specimens.bts, reference_kn, target.density_kg_per_m3, nu_p,
                                                      plane_model, options.max_spectral_radius, options.bond_range)); });
  };
  auto deformable_design = [&]() {
    if (!options.deformable_design.axes.empty()) return options.deformable_design;
    // Both map specimens run every point: the bound of either may be the lower one.
    const double bound = OnRankZero([&] {
      return std::min(AdmissibleParticleCompliance<Dim>(specimens.sweep_ucs, reference_kn, target.density_kg_per_m3,
                                                        options.particle_poisson_ratio, plane_model,
                                                        options.max_spectral_radius, options.bond_range),
                      AdmissibleParticleCompliance<Dim>(specimens.sweep_bts, reference_kn, target.density_kg_per_m3,
                                                        options.particle_poisson_ratio, plane_model,
                                                        options.max_spectral_radius, options.bond_range));
    });
    SweepDesign d = WithStiffnessBox(
        WithLevels(DefaultSweepDesign(true, options.particle_poisson_ratio, bound, options.friction_coefficient),
                   options.sweep_levels),
        options.stiffness_ratio_lower, options.stiffness_ratio_upper);
    d.fixed.bond_range = options.bond_range;
    return d;
  };
  auto rigid_design = [&]() {
    if (!options.rigid_design.axes.empty()) return options.rigid_design;
    SweepDesign d = WithStiffnessBox(
        WithLevels(DefaultSweepDesign(false, 0.0, 0.0, options.friction_coefficient), options.sweep_levels),
        options.stiffness_ratio_lower, options.stiffness_ratio_upper);
    d.fixed.bond_range = options.bond_range;
    return d;
  };

  // --- 2. The loop on the real specimens: its forward model, one solver per model ---------
  ProgressRelay relay;
  relay.out = options.progress;
  relay.span = 0.85 / options.max_verification_rounds;
  LabForwardModelSettings settings;
  settings.protocol = options.test;
  settings.density_kg_per_m3 = target.density_kg_per_m3;
  settings.plane_model = plane_model;
  settings.group_length_m = group_length;
  settings.workers = std::min(2, workers);
  if (options.progress) settings.progress = [&relay](double f, const std::string& m) { relay.Test(f, m); };
  LabForwardModel<Dim> model(specimens.ucs, specimens.bts, settings);

  auto make_solver = [&](const StoredMaps& maps, double admissible, int* stored) {
    CalibrationSurrogate surrogate(maps.maps, summary.ucs_descriptors, summary.bts_descriptors);
    surrogate.SetSweepGrid(SweepGrid(maps.design, maps.points));
    *stored = 0;
    for (const VerifiedPoint& v : maps.verified)
      if (MapsMatchPacking(v.specimen, summary.ucs_descriptors, nullptr)) {
        surrogate.AddMeasurement(v.ToMeasurement(summary.ucs_descriptors, summary.bts_descriptors), /*stored=*/true);
        ++*stored;
      }
    CalibrationSolverOptions o;
    o.tolerance_youngs = options.tolerance_youngs;
    o.tolerance_poisson = options.tolerance_poisson;
    o.tolerance_ucs = options.tolerance_ucs;
    o.tolerance_tensile = options.tolerance_tensile;
    o.max_strength_rounds = options.max_verification_rounds;
    o.max_elastic_runs = options.max_elastic_runs;
    o.honour = options.honour;
    o.admissible_particle_compliance = maps.deformable ? admissible : 0.0;
    o.progress = [&relay](double f, const std::string& m) { relay.Loop(f, m); };
    return std::make_unique<CalibrationSolver>(std::move(surrogate), target, o, &model);
  };

  StoredMaps chosen;
  std::unique_ptr<CalibrationSolver> solver;
  if (!options.maps_file.empty()) {
    chosen = load_given_maps();
    summary.model_used = chosen.deformable ? "ddem" : "rigid";
    summary.model_reason = "maps given";
    if (chosen.deformable)
      summary.admissible_particle_compliance = admissible_on_real(chosen.design.fixed.particle_poisson_ratio);
    solver = make_solver(chosen, summary.admissible_particle_compliance, &summary.stored_measurements);
    (chosen.deformable ? summary.deformable_reach : summary.rigid_reach) = solver->AssessReach();
  } else {
    StoredMaps rigid, deformable;
    std::string rigid_path, deformable_path;
    bool rigid_reused = false, deformable_reused = false;
    std::unique_ptr<CalibrationSolver> rigid_solver, deformable_solver;
    int rigid_stored = 0, deformable_stored = 0;
    if (options.model != CalibrationModel::kDeformable) {
      rigid = obtain_maps(false, rigid_design(), "rigid maps", &rigid_path, &rigid_reused);
      rigid_solver = make_solver(rigid, 0.0, &rigid_stored);
      summary.rigid_reach = rigid_solver->AssessReach();
    }
    const bool rigid_reaches = rigid_solver && !summary.rigid_reach.declared_out_of_reach();
    // Within the rigid surfaces' interval, or only within the tolerance or their transfer
    // uncertainty beyond it (the rounds would then measure it): a marginal target goes to
    // DDEM when DDEM holds it inside its own interval (a DDEM twin: sigma_c / sigma_t 17.5 at nu 0.211, the rigid
    // surfaces' end 16.9 at the rigid limit of nu, measured 12.6 there).
    auto inside = [&](const CalibrationReach& r) {  // the interval itself, no tolerance slack
      return r.reachable() && target.StrengthRatio() >= r.strength_ratio_min &&
             target.StrengthRatio() <= r.strength_ratio_max;
    };
    const bool rigid_inside = rigid_solver && inside(summary.rigid_reach);
    // Neither reaches: the one whose nearest point lies fewer tolerances away (the Nevada Test
    // Site basalt, nu 0.32: DDEM 0.313 at most, rigid particles 0.214).
    auto miss = [&](const CalibrationReach& r) {
      return r.Miss(target, options.tolerance_poisson, options.tolerance_tensile);
    };
    bool use_deformable = options.model == CalibrationModel::kDeformable;
    bool marginal = false;
    if (use_deformable || (options.model == CalibrationModel::kAutomatic && !rigid_inside)) {
      deformable = obtain_maps(true, deformable_design(), "deformable maps", &deformable_path, &deformable_reused);
      summary.admissible_particle_compliance = admissible_on_real(deformable.design.fixed.particle_poisson_ratio);
      deformable_solver = make_solver(deformable, summary.admissible_particle_compliance, &deformable_stored);
      summary.deformable_reach = deformable_solver->AssessReach();
      if (options.model == CalibrationModel::kAutomatic) {
        marginal = rigid_reaches;
        use_deformable = rigid_reaches ? inside(summary.deformable_reach)
                                       : !summary.deformable_reach.declared_out_of_reach() ||
                                             miss(summary.deformable_reach) < miss(summary.rigid_reach);
      }
    }
    char reason[480];
    const CalibrationReach& r = summary.rigid_reach;
    const CalibrationReach& d = summary.deformable_reach;
    if (options.model != CalibrationModel::kAutomatic) {
      std::snprintf(reason, sizeof(reason), "requested");
    } else if (marginal && use_deformable) {
      std::snprintf(reason, sizeof(reason),
                    "rigid particles reach sigma_c/sigma_t %.3g at nu %.4g only beyond their maps' interval "
                    "(%.3g to %.3g), within the tolerance or the transfer uncertainty; DDEM holds it inside "
                    "its interval (%.3g to %.3g)",
                    target.StrengthRatio(), target.poisson_ratio, r.strength_ratio_min, r.strength_ratio_max,
                    d.strength_ratio_min, d.strength_ratio_max);
    } else if (rigid_reaches) {
      std::snprintf(reason, sizeof(reason),
                    "rigid particles reach nu %.4g (measured %.4g to %.4g) and sigma_c/sigma_t %.3g (%.3g to %.3g "
                    "at that nu)",
                    target.poisson_ratio, r.poisson_min, r.poisson_max, target.StrengthRatio(), r.strength_ratio_min,
                    r.strength_ratio_max);
    } else {
      char closer[160] = "DDEM does";
      if (d.declared_out_of_reach())
        std::snprintf(closer, sizeof(closer), "neither does DDEM; %s comes closer (%.3g tolerances away, against %.3g)",
                      use_deformable ? "DDEM" : "rigid particles", use_deformable ? miss(d) : miss(r),
                      use_deformable ? miss(r) : miss(d));
      std::snprintf(reason, sizeof(reason),
                    "rigid particles do not reach nu %.4g and sigma_c/sigma_t %.3g together (nu %.4g to %.4g; "
                    "ratio %.3g to %.3g at nu %.4g); %s",
                    target.poisson_ratio, target.StrengthRatio(), r.poisson_min, r.poisson_max, r.strength_ratio_min,
                    r.strength_ratio_max, r.nearest_poisson, closer);
    }
    summary.model_reason = reason;
    summary.model_used = use_deformable ? "ddem" : "rigid";
    chosen = use_deformable ? deformable : rigid;
    summary.maps_path = use_deformable ? deformable_path : rigid_path;
    summary.maps_reused = use_deformable ? deformable_reused : rigid_reused;
    solver = use_deformable ? std::move(deformable_solver) : std::move(rigid_solver);
    summary.stored_measurements = use_deformable ? deformable_stored : rigid_stored;
  }
  summary.maps = chosen;

  // --- 3, 4. The elastic and strength stages ------------------------------------------
  summary.solution = solver->Solve();
  const CalibrationSolution& solution = summary.solution;
  summary.converged = solution.converged;
  summary.tensile_honoured = solution.tensile_honoured;
  summary.gave_up = !solution.reach.given_up.empty();
  // The reach of the model used, as the strength stage left it (measured since).
  CalibrationReach& used_reach = summary.model_used == "ddem" ? summary.deformable_reach : summary.rigid_reach;
  summary.reach_before_rounds = used_reach;
  used_reach = solution.reach;
  const bool has_result = solution.best_round >= 0;
  summary.best_round = has_result ? solution.rounds[solution.best_round].round : 0;
  const auto& tests = model.strength_tests();  // one per round, failed ones included
  for (size_t k = 0; k < solution.rounds.size(); ++k) {
    const StrengthRound& r = solution.rounds[k];
    VerificationRound v;
    v.round = r.round;
    v.failed = r.failed;
    v.failure = r.failure;
    v.material = tests[k].material;
    v.ratios = r.ratios;
    v.youngs_modulus_pa = r.elastic_youngs_modulus_pa;
    v.poisson_ratio = r.elastic_poisson_ratio;
    v.ucs_pa = r.measured.ucs_pa;
    v.tensile_strength_pa = r.measured.tensile_strength_pa;
    v.own_peak_youngs_modulus_pa = r.measured.secant_youngs_modulus_pa;
    v.own_peak_poisson_ratio = r.measured.secant_poisson_ratio;
    v.error_youngs = v.youngs_modulus_pa / target.youngs_modulus_pa - 1.0;
    v.error_poisson = v.poisson_ratio / target.poisson_ratio - 1.0;
    v.error_ucs = r.error_ucs;
    v.error_tensile = r.error_tensile;
    v.predicted_ucs_pa = r.predicted_ucs_pa;
    v.predicted_tensile_strength_pa = r.predicted_tensile_strength_pa;
    v.accepted = r.accepted;
    v.seconds = r.measured.seconds;
    v.correction = r.step;
    summary.rounds.push_back(v);
  }
  // With no round measured, the parameters are the elastic set's (Rn and Rt unknown: 0).
  const typename LabForwardModel<Dim>::RoundTests* best = has_result ? &tests[solution.best_round] : nullptr;
  summary.material = has_result ? best->material : model.MaterialFor(solution.normal_stiffness, 0.0, solution.ratios);
  if (has_result) {
    summary.final_ucs = best->ucs;
    summary.final_bts = best->bts;
    summary.final_bts_rank = best->bts_rank;
  }
  summary.notes.push_back(solution.reach.Describe(target));
  for (const std::string& note : solution.notes) summary.notes.push_back(note);
  if (has_result && !summary.converged && !summary.gave_up)
    summary.notes.push_back("the budget (" + std::to_string(options.max_verification_rounds) +
                            " strength rounds) was spent before every honoured target was within tolerance");

  // Every run on the real specimens is a measurement of the true map: stored with the maps,
  // the next calibration on this specimen starts from surfaces corrected by it.
  {
    for (const ElasticRun& run : solution.elastic_runs) {
      VerifiedPoint v;
      v.ratios = run.query.ratios;
      v.specimen = summary.ucs_descriptors;
      v.poisson_ratio = run.measured.poisson_ratio;
      v.elastic_group = ElasticGroup(summary.ucs_descriptors, run.measured.youngs_modulus_pa, run.query.normal_stiffness);
      summary.maps.verified.push_back(v);
    }
    for (const StrengthRound& r : solution.rounds) {  // strengths only: the elastic runs are above
      if (r.failed) continue;  // nothing measured
      VerifiedPoint v;
      v.ratios = r.ratios;
      v.specimen = summary.ucs_descriptors;
      v.compressive_group = StrengthGroup(summary.ucs_descriptors, r.measured.ucs_pa, r.bond_tensile_strength);
      v.tensile_group = StrengthGroup(summary.bts_descriptors, r.measured.tensile_strength_pa, r.bond_tensile_strength);
      summary.maps.verified.push_back(v);
    }
    // The anchors stay; of the calibrations' runs the newest are kept.
    constexpr size_t kMaxCalibrationPoints = 200;
    size_t calibration_points = 0;
    for (const VerifiedPoint& v : summary.maps.verified) calibration_points += v.origin == "anchor" ? 0 : 1;
    size_t skip = calibration_points > kMaxCalibrationPoints ? calibration_points - kMaxCalibrationPoints : 0;
    std::vector<VerifiedPoint> kept;
    for (const VerifiedPoint& v : summary.maps.verified) {
      if (v.origin != "anchor" && skip > 0) {
        --skip;
        continue;
      }
      kept.push_back(v);
    }
    summary.maps.verified = kept;
    if (!summary.maps_path.empty() && options.maps_file.empty() && Rank() == 0)
      SaveStoredMaps(summary.maps, summary.maps_path);
  }

  // --- 5. Stability of the final set ----------------------------------------------------
  // On rank 0, which holds the final UCS test and writes the outputs (ranks.h); the others
  // leave it unjudged.
  if (Rank() != 0) {
    summary.stability_verdict = "not judged";
    summary.stability_binding_limit = "-";
    summary.stability_message = "judged on rank 0";
  } else if (!has_result) {
    summary.stability_verdict = "not judged";
    summary.stability_binding_limit = "-";
    summary.stability_message = "no strength round measured: no final set";
  } else {
    SceneOptions<Dim> scene;
    scene.material = summary.material;
    scene.material.density_kg_per_m3 = best->ucs.density_used_kg_per_m3;
    scene.material.translational_damping = scene.material.rotational_damping = options.test.local_damping;
    scene.material.normal_dashpot_ratio = scene.material.tangential_dashpot_ratio = options.test.dashpot_ratio;
    scene.material.mass_scaling_budget = options.test.mass_scaling_budget;  // as the tests ran
    StabilityOptions stability;
    stability.max_spectral_radius = options.max_spectral_radius;
    stability.proposed_time_step_s = best->ucs.time_step_s;
    stability.locate_mode = false;
    const StabilitySummary s = AnalyseStability<Dim>(specimens.ucs, scene, stability);
    summary.stability_judged = true;
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

template struct SpecimenPlan<2>;
template struct SpecimenPlan<3>;
template CalibrationSpecimens<2> MakeCalibrationSpecimens<2>(const SpecimenPlan<2>&);
template CalibrationSpecimens<3> MakeCalibrationSpecimens<3>(const SpecimenPlan<3>&);
template CalibrationSummary CalibrateToMaterial<2>(const CalibrationSpecimens<2>&, const TargetMaterial&,
                                                   const CalibrationOptions&);
template CalibrationSummary CalibrateToMaterial<3>(const CalibrationSpecimens<3>&, const TargetMaterial&,
                                                   const CalibrationOptions&);

}  // namespace specimen
