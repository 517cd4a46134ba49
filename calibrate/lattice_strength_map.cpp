#include "calibrate/lattice_strength_map.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>

#include "calibrate/map_store.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/format.h"
#include "specimen_version.h"

namespace specimen {
namespace {

constexpr const char* kFormat = "specimen-lattice-map 1";
constexpr double kReferenceCohesion = 30e6;  // Pa; the points are per unit c
constexpr double kRowMatch = 0.005;          // a nu this close to a row is on it
constexpr double kRowGap = 0.1;              // rows further apart do not interpolate nu

bool Ascending(const std::vector<double>& v) {
  for (size_t i = 1; i < v.size(); ++i)
    if (!(v[i] > v[i - 1])) return false;
  return !v.empty();
}

// 2 cos(phi) / (1 - sin(phi)): the triangles' Mohr-Coulomb UCS per unit cohesion.
double MohrCoulombUcsPerCohesion(double phi_deg) { return LatticeStrength{1.0, 1.0, phi_deg}.TriangleCompressiveStrength(); }
// The index i with grid[i] <= x <= grid[i + 1] (x clamped to the grid) and the weight of i + 1.
std::pair<size_t, double> Cell(const std::vector<double>& grid, double x) {
  if (grid.size() == 1) return {0, 0.0};
  x = std::clamp(x, grid.front(), grid.back());
  size_t i = std::upper_bound(grid.begin(), grid.end(), x) - grid.begin();
  i = std::clamp<size_t>(i, 1, grid.size() - 1) - 1;
  return {i, (x - grid[i]) / (grid[i + 1] - grid[i])};
}

}  // namespace

LatticeRoundModel LatticeTestsOn(const Packing<2>& ucs, const Packing<2>& bts, const LabTestOptions& test,
                                 const LatticeProtocol& protocol) {
  if (ucs.domain.shape() != DomainShape::kRectangle)
    throw InputError("the lattice UCS specimen must be a rectangle, not a " + ucs.domain.ShapeName());
  if (bts.domain.shape() != DomainShape::kDisc)
    throw InputError("the lattice Brazilian specimen must be a disc, not a " + bts.domain.ShapeName());
  return [&ucs, &bts, test, protocol](const LatticeMaterial& material, int round) {
    LabTestOptions ucs_test = test, bts_test = test;
    ucs_test.kind = LabTestKind::kUniaxialCompression;
    bts_test.kind = LabTestKind::kBrazilian;
    ucs_test.progress = bts_test.progress = nullptr;
    auto bts_run =
        std::async(std::launch::async, [&]() { return RunLatticeLabTest(bts, material, bts_test, protocol); });
    const LabTestResult u = RunLatticeLabTest(ucs, material, ucs_test, protocol);
    const LabTestResult b = bts_run.get();
    if (!u.peak_reached || !b.peak_reached)
      throw ComputationError(std::string("lattice round ") + std::to_string(round) + ": the " +
                             (!u.peak_reached ? "UCS" : "Brazilian") + " test " +
                             (!u.peak_reached ? u.termination_message : b.termination_message));
    LatticeRoundMeasurement m;
    m.ucs_pa = u.peak_stress_pa;
    m.bts_pa = b.tensile_strength_pa;
    m.youngs_modulus_pa = u.linear_elastic.youngs_modulus_pa;
    m.poisson_ratio = u.linear_elastic.poisson_ratio;
    m.critical_time_step_s = u.critical_time_step_s;
    return m;
  };
}

// --- Design -------------------------------------------------------------------------------

bool LatticeMapDesign::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    *error = "lattice map design: " + what;
    return false;
  };
  if (!Ascending(poisson_ratios) || poisson_ratios.front() < 0.0 || poisson_ratios.back() >= 0.5)
    return fail("poisson_ratios must ascend within [0, 0.5)");
  if (!Ascending(friction_angles_deg) || friction_angles_deg.front() < 0.0 || friction_angles_deg.back() > 60.0)
    return fail("friction_angles_deg must ascend within [0, 60] degrees");
  if (!Ascending(tensile_over_cohesion) || tensile_over_cohesion.front() <= 0.0)
    return fail("tensile_over_cohesion must ascend and be > 0");
  if (!(cohesion_over_modulus > 0.0 && cohesion_over_modulus <= 0.01))
    return fail("cohesion_over_modulus = " + Number(cohesion_over_modulus) + ": must be in (0, 0.01]");
  return true;
}

nlohmann::json LatticeMapDesign::ToJson() const {
  return {{"poisson_ratios", poisson_ratios},
          {"friction_angles_deg", friction_angles_deg},
          {"tensile_over_cohesion", tensile_over_cohesion},
          {"cohesion_over_modulus", cohesion_over_modulus}};
}

LatticeMapDesign LatticeMapDesign::FromJson(const nlohmann::json& j) {
  LatticeMapDesign d;
  d.poisson_ratios = j.at("poisson_ratios").get<std::vector<double>>();
  d.friction_angles_deg = j.at("friction_angles_deg").get<std::vector<double>>();
  d.tensile_over_cohesion = j.at("tensile_over_cohesion").get<std::vector<double>>();
  d.cohesion_over_modulus = j.at("cohesion_over_modulus").get<double>();
  return d;
}

std::vector<double> LatticeMapDesign::RowsFor(double nu) const {
  for (double row : poisson_ratios)
    if (std::abs(row - nu) <= kRowMatch) return {row};
  if (nu < poisson_ratios.front() || nu > poisson_ratios.back()) return {nu};  // its own row
  const auto [i, w] = Cell(poisson_ratios, nu);
  (void)w;
  return {poisson_ratios[i], poisson_ratios[i + 1]};
}

// --- The map --------------------------------------------------------------------------------

const LatticeMapPoint* LatticeStrengthMap::Find(double nu, double phi_deg, double s) const {
  for (const LatticeMapPoint& q : points)
    if (std::abs(q.poisson_ratio - nu) < 1e-9 && std::abs(q.friction_angle_deg - phi_deg) < 1e-9 &&
        std::abs(q.tensile_over_cohesion / s - 1.0) < 1e-9)
      return &q;
  return nullptr;
}

std::vector<double> LatticeStrengthMap::Rows() const {
  // A row is present when every (phi, s) pair of the design has its point.
  std::vector<double> rows;
  for (double nu : design.poisson_ratios) {
    bool complete = true;
    for (double phi : design.friction_angles_deg)
      for (double s : design.tensile_over_cohesion) complete = complete && Find(nu, phi, s) != nullptr;
    if (complete) rows.push_back(nu);
  }
  return rows;
}

bool LatticeStrengthMap::Covers(double nu, std::string* why) const {
  const std::vector<double> rows = Rows();
  for (double row : rows)
    if (std::abs(row - nu) <= kRowMatch) return true;
  const auto above = std::upper_bound(rows.begin(), rows.end(), nu);
  if (above != rows.begin() && above != rows.end() && *above - *(above - 1) <= kRowGap + 1e-9) return true;
  if (why) {
    std::string present;
    for (double row : rows) present += (present.empty() ? "" : ", ") + Number(row);
    *why = "no rows around nu " + Number(nu) + " (rows present: " + (present.empty() ? "none" : present) + ")";
  }
  return false;
}

LatticeMapPoint LatticeStrengthMap::At(double nu, double phi_deg, double s) const {
  const std::vector<double> rows = Rows();
  if (!Covers(nu)) throw InputError("the lattice map does not cover nu " + Number(nu));
  auto row_value = [&](double row) {
    // Bilinear in (phi, ln s) of the logarithms of the two strengths.
    const auto [ip, wp] = Cell(design.friction_angles_deg, phi_deg);
    std::vector<double> log_s(design.tensile_over_cohesion.size());
    for (size_t k = 0; k < log_s.size(); ++k) log_s[k] = std::log(design.tensile_over_cohesion[k]);
    const auto [is, ws] = Cell(log_s, std::log(s));
    double u = 0.0, b = 0.0;
    for (int dp = 0; dp < 2; ++dp)
      for (int ds = 0; ds < 2; ++ds) {
        const double w = (dp ? wp : 1.0 - wp) * (ds ? ws : 1.0 - ws);
        if (w == 0.0) continue;
        const double phi = design.friction_angles_deg[std::min(ip + dp, design.friction_angles_deg.size() - 1)];
        const double sk = design.tensile_over_cohesion[std::min(is + ds, log_s.size() - 1)];
        const LatticeMapPoint* q = Find(row, phi, sk);
        if (!q) throw InputError("the lattice map lacks its point nu " + Number(row) + ", phi " + Number(phi) +
                                 ", sigma_t/c " + Number(sk));
        u += w * std::log(q->ucs_over_cohesion);
        b += w * std::log(q->bts_over_tensile);
      }
    return std::pair<double, double>(u, b);
  };
  std::pair<double, double> value;
  const auto on = std::find_if(rows.begin(), rows.end(), [&](double r) { return std::abs(r - nu) <= kRowMatch; });
  if (on != rows.end()) {
    value = row_value(*on);
  } else {
    const auto above = std::upper_bound(rows.begin(), rows.end(), nu);
    const double r0 = *(above - 1), r1 = *above, w = (nu - r0) / (r1 - r0);
    const auto v0 = row_value(r0), v1 = row_value(r1);
    value = {(1 - w) * v0.first + w * v1.first, (1 - w) * v0.second + w * v1.second};
  }
  LatticeMapPoint p;
  p.poisson_ratio = nu;
  p.friction_angle_deg = phi_deg;
  p.tensile_over_cohesion = s;
  p.ucs_over_cohesion = std::exp(value.first);
  p.bts_over_tensile = std::exp(value.second);
  return p;
}

nlohmann::json LatticeStrengthMap::ToJson() const {
  nlohmann::json j = {{"format", kFormat},
                      {"model", "lattice"},
                      {"code_version", code_version},
                      {"created_utc", created_utc},
                      {"ucs_specimen", DescriptorsToJson(ucs_descriptors)},
                      {"bts_specimen", DescriptorsToJson(bts_descriptors)},
                      {"protocol", protocol},
                      {"design", design.ToJson()},
                      {"build_seconds", build_seconds},
                      {"points", nlohmann::json::array()}};
  for (const LatticeMapPoint& q : points)
    j["points"].push_back({{"poisson_ratio", q.poisson_ratio},
                           {"friction_angle_deg", q.friction_angle_deg},
                           {"tensile_over_cohesion", q.tensile_over_cohesion},
                           {"ucs_over_cohesion", q.ucs_over_cohesion},
                           {"bts_over_tensile", q.bts_over_tensile},
                           {"seconds", q.seconds}});
  return j;
}

LatticeStrengthMap LatticeStrengthMap::FromJson(const nlohmann::json& j, const std::string& source) {
  LatticeStrengthMap m;
  try {
    if (j.at("format").get<std::string>() != kFormat)
      throw InputError(source + ": format '" + j.at("format").get<std::string>() + "', expected '" + kFormat + "'");
    m.code_version = j.at("code_version").get<std::string>();
    m.created_utc = j.at("created_utc").get<std::string>();
    m.ucs_descriptors = DescriptorsFromJson(j.at("ucs_specimen"));
    m.bts_descriptors = DescriptorsFromJson(j.at("bts_specimen"));
    m.protocol = j.at("protocol");
    m.design = LatticeMapDesign::FromJson(j.at("design"));
    m.build_seconds = j.value("build_seconds", 0.0);
    for (const auto& q : j.at("points")) {
      LatticeMapPoint p;
      p.poisson_ratio = q.at("poisson_ratio").get<double>();
      p.friction_angle_deg = q.at("friction_angle_deg").get<double>();
      p.tensile_over_cohesion = q.at("tensile_over_cohesion").get<double>();
      p.ucs_over_cohesion = q.at("ucs_over_cohesion").get<double>();
      p.bts_over_tensile = q.at("bts_over_tensile").get<double>();
      p.seconds = q.value("seconds", 0.0);
      if (!(p.ucs_over_cohesion > 0.0 && p.bts_over_tensile > 0.0))
        throw InputError(source + ": a point's strengths must be > 0");
      m.points.push_back(p);
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source + ": malformed lattice map: " + e.what());
  }
  std::string error;
  if (!m.design.IsValid(&error)) throw InputError(source + ": " + error);
  return m;
}

nlohmann::json LatticeMapProtocol(const LabTestOptions& test, const LatticeProtocol& protocol) {
  return {{"loading_rate_group", test.loading_rate_group},
          {"velocity_ramp_transits", test.velocity_ramp_transits},
          {"post_peak_stress_fraction", test.post_peak_stress_fraction},
          {"strain_limit", test.strain_limit},
          {"platen_zone_share", protocol.platen_zone_share},
          {"loading_arc_deg", protocol.loading_arc_deg},
          {"local_damping", protocol.local_damping},
          {"compression_wave_share", protocol.compression_wave_share},
          {"brazilian_wave_share", protocol.brazilian_wave_share}};
}

void MeasureLatticeMapRows(const std::vector<double>& rows, const LatticeRoundModel& measure,
                           const ProgressCallback& progress, LatticeStrengthMap* map) {
  std::string error;
  if (!map->design.IsValid(&error)) throw InputError(error);
  for (double nu : rows)
    if (!(nu >= 0.0 && nu < 0.5)) throw InputError("lattice map: row nu = " + Number(nu) + ": must be in [0, 0.5)");
  const auto start = std::chrono::steady_clock::now();
  const LatticeMapDesign& d = map->design;
  const size_t total = rows.size() * d.friction_angles_deg.size() * d.tensile_over_cohesion.size();
  std::vector<LatticeMapPoint> measured;
  for (double nu : rows)
    for (double phi : d.friction_angles_deg)
      for (double s : d.tensile_over_cohesion) {
        LatticeMaterial material;
        material.elasticity = IsotropicPlaneElasticity(kReferenceCohesion / d.cohesion_over_modulus, nu,
                                                       PlaneModel::kPlaneStrain);
        material.density_kg_per_m3 = 2600.0;  // quasi-static: the strengths do not depend on it
        material.strength = {s * kReferenceCohesion, kReferenceCohesion, phi};
        if (progress)
          progress(static_cast<double>(measured.size()) / total,
                   "lattice map: nu " + Number(nu) + ", phi " + Number(phi) + ", sigma_t/c " + Number(s));
        const auto point_start = std::chrono::steady_clock::now();
        LatticeRoundMeasurement r;
        try {
          r = measure(material, static_cast<int>(measured.size()) + 1);
        } catch (const std::runtime_error& e) {  // also a test's refusal of its step budget: not the user's input
          throw ComputationError("lattice map point nu " + Number(nu) + ", phi " + Number(phi) + ", sigma_t/c " +
                                 Number(s) + ": " + e.what());
        }
        LatticeMapPoint q;
        q.poisson_ratio = nu;
        q.friction_angle_deg = phi;
        q.tensile_over_cohesion = s;
        q.ucs_over_cohesion = r.ucs_pa / kReferenceCohesion;
        q.bts_over_tensile = r.bts_pa / (s * kReferenceCohesion);
        q.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - point_start).count();
        measured.push_back(q);
      }
  // Only complete rows reach the map: an interrupted build leaves it as it was.
  auto& points = map->points;
  points.erase(std::remove_if(points.begin(), points.end(),
                              [&](const LatticeMapPoint& q) {
                                return std::any_of(rows.begin(), rows.end(), [&](double nu) {
                                  return std::abs(q.poisson_ratio - nu) < 1e-12;
                                });
                              }),
               points.end());
  points.insert(points.end(), measured.begin(), measured.end());
  std::vector<double>& design_rows = map->design.poisson_ratios;
  for (double nu : rows)
    if (std::none_of(design_rows.begin(), design_rows.end(), [&](double r) { return std::abs(r - nu) < 1e-12; }))
      design_rows.push_back(nu);
  std::sort(design_rows.begin(), design_rows.end());
  map->build_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  map->code_version = kVersion;
  map->created_utc = UtcNow();
}

// --- Reach and start ------------------------------------------------------------------------

LatticeMapStart StartFromMap(const LatticeStrengthMap& map, const TargetMaterial& target) {
  std::string why;
  const double nu = target.poisson_ratio;
  if (!map.Covers(nu, &why)) throw InputError("the lattice map: " + why);
  const std::vector<double>& angles = map.design.friction_angles_deg;
  std::vector<double> phis;
  if (target.friction_angle_deg) {
    const double phi = *target.friction_angle_deg;
    if (phi < angles.front() - 1e-9 || phi > angles.back() + 1e-9)
      throw InputError("the lattice map: friction_angle " + Number(phi) + " lies outside its angles " +
                       Number(angles.front()) + "-" + Number(angles.back()) + " degrees");
    phis = {phi};
  } else {
    for (double phi = angles.front(); phi <= angles.back() + 1e-9; phi += 0.5) phis.push_back(phi);
    // 30 degrees (the rounds' default) first, then outwards.
    std::stable_sort(phis.begin(), phis.end(),
                     [](double a, double b) { return std::abs(a - 30.0) < std::abs(b - 30.0); });
  }
  const std::vector<double>& grid = map.design.tensile_over_cohesion;
  constexpr int kSamples = 241;
  const double ls0 = std::log(grid.front()), ls1 = std::log(grid.back());
  auto log_s_at = [&](int k) { return ls0 + (ls1 - ls0) * k / (kSamples - 1); };
  const double goal = std::log(target.StrengthRatio());

  LatticeMapStart start;
  start.ratio_low = std::numeric_limits<double>::infinity();
  start.ratio_high = 0.0;
  double nearest_gap = std::numeric_limits<double>::infinity(), nearest_phi = phis.front(), nearest_ls = ls0;
  bool found = false;
  double root_phi = 0.0, root_ls = 0.0;
  for (double phi : phis) {
    std::vector<double> g(kSamples);  // ln ratio - ln target
    for (int k = 0; k < kSamples; ++k) {
      const double ratio = map.At(nu, phi, std::exp(log_s_at(k))).StrengthRatio();
      start.ratio_low = std::min(start.ratio_low, ratio);
      start.ratio_high = std::max(start.ratio_high, ratio);
      g[k] = std::log(ratio) - goal;
      if (std::abs(g[k]) < nearest_gap - 1e-12) {
        nearest_gap = std::abs(g[k]);
        nearest_phi = phi;
        nearest_ls = log_s_at(k);
      }
    }
    if (found) continue;  // the interval over every angle is still wanted
    // The closed-form start's s: the target's sigma_t over the c of the Mohr-Coulomb UCS.
    const double ls_closed =
        std::clamp(std::log(target.tensile_strength_pa * MohrCoulombUcsPerCohesion(phi) / target.ucs_pa), ls0, ls1);
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k + 1 < kSamples; ++k) {
      const bool last_is_root = k + 2 == kSamples && g[k + 1] == 0.0;
      if ((g[k] > 0.0) == (g[k + 1] > 0.0) && g[k] != 0.0 && !last_is_root) continue;
      const double ls = last_is_root    ? log_s_at(k + 1)
                        : g[k] == g[k + 1] ? log_s_at(k)
                                           : log_s_at(k) + (log_s_at(k + 1) - log_s_at(k)) * g[k] / (g[k] - g[k + 1]);
      if (std::abs(ls - ls_closed) < best) {
        best = std::abs(ls - ls_closed);
        root_ls = ls;
      }
    }
    if (best < std::numeric_limits<double>::infinity()) {
      found = true;
      root_phi = phi;
    }
  }
  start.reachable = found;
  start.friction_angle_deg = found ? root_phi : nearest_phi;
  const double ls = found ? root_ls : nearest_ls;
  const LatticeMapPoint at = map.At(nu, start.friction_angle_deg, std::exp(ls));
  start.cohesion_pa = target.ucs_pa / at.ucs_over_cohesion;
  start.tensile_strength_pa = std::exp(ls) * start.cohesion_pa;
  start.predicted_ucs_pa = target.ucs_pa;
  start.predicted_bts_pa = start.tensile_strength_pa * at.bts_over_tensile;
  // d ln sigma_B / d ln sigma_t at fixed c = 1 + d ln(sigma_B / sigma_t) / d ln s.
  const double h = 0.05;
  const double lo = std::max(ls - h, ls0), hi = std::min(ls + h, ls1);
  if (hi > lo)
    start.tensile_slope = 1.0 + (std::log(map.At(nu, start.friction_angle_deg, std::exp(hi)).bts_over_tensile) -
                                 std::log(map.At(nu, start.friction_angle_deg, std::exp(lo)).bts_over_tensile)) /
                                    (hi - lo);
  char text[600];
  const std::string angles_text =
      target.friction_angle_deg ? "at the target's friction angle " + Number(*target.friction_angle_deg) + " degrees"
                                : "over friction angles " + Number(angles.front()) + "-" + Number(angles.back()) +
                                      " degrees";
  if (found)
    std::snprintf(text, sizeof text,
                  "the lattice map puts UCS / sigma_t %.3g within reach at nu %.3g (%.3g-%.3g %s, triangle sigma_t/c "
                  "%.3g-%.3g): start at phi %.3g, sigma_t/c %.3g (c %.4g MPa, sigma_t %.4g MPa)",
                  target.StrengthRatio(), nu, start.ratio_low, start.ratio_high, angles_text.c_str(), grid.front(),
                  grid.back(), start.friction_angle_deg, std::exp(ls), start.cohesion_pa / 1e6,
                  start.tensile_strength_pa / 1e6);
  else
    std::snprintf(text, sizeof text,
                  "UCS / sigma_t %.3g is out of the lattice's reach at nu %.3g on these specimens: the map gives "
                  "%.3g-%.3g %s (triangle sigma_t/c %.3g-%.3g); the nearest, %.3g, at phi %.3g, sigma_t/c %.3g: "
                  "sigma_t is given up, the UCS honoured",
                  target.StrengthRatio(), nu, start.ratio_low, start.ratio_high, angles_text.c_str(), grid.front(),
                  grid.back(), target.StrengthRatio() * std::exp(std::log(at.StrengthRatio()) - goal),
                  start.friction_angle_deg, std::exp(ls));
  start.statement = text;
  return start;
}

// --- Files ------------------------------------------------------------------------------

void SaveLatticeStrengthMap(const LatticeStrengthMap& map, const std::string& path) {
  const std::string text = map.ToJson().dump(1);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text << "\n"; });
}

int MergeLatticeMapRows(const LatticeStrengthMap& stored, LatticeStrengthMap* map) {
  if (stored.design.friction_angles_deg != map->design.friction_angles_deg ||
      stored.design.tensile_over_cohesion != map->design.tensile_over_cohesion ||
      stored.design.cohesion_over_modulus != map->design.cohesion_over_modulus)
    return 0;  // another grid: its rows are not rows of this map
  const std::vector<double> present = map->Rows();
  int added = 0;
  for (double nu : stored.Rows()) {
    if (std::find(present.begin(), present.end(), nu) != present.end()) continue;
    // An incomplete row of `map` at this nu is replaced by the stored complete one.
    std::vector<LatticeMapPoint>& points = map->points;
    points.erase(std::remove_if(points.begin(), points.end(),
                                [nu](const LatticeMapPoint& q) { return q.poisson_ratio == nu; }),
                 points.end());
    for (const LatticeMapPoint& q : stored.points)
      if (q.poisson_ratio == nu) {
        points.push_back(q);
        map->build_seconds += q.seconds;
      }
    std::vector<double>& rows = map->design.poisson_ratios;
    if (std::find(rows.begin(), rows.end(), nu) == rows.end()) {
      rows.push_back(nu);
      std::sort(rows.begin(), rows.end());
    }
    ++added;
  }
  return added;
}

LatticeStrengthMap LoadLatticeStrengthMap(const std::string& path) {
  if (std::filesystem::is_directory(path)) throw FileError("the lattice map " + path + " is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw FileError("cannot read the lattice map " + path);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError("the lattice map " + path + " is not valid JSON (truncated or not a map)");
  return LatticeStrengthMap::FromJson(j, path);
}

std::string LatticeMapFileName(const PackingDescriptors& ucs, const PackingDescriptors& bts,
                               const nlohmann::json& protocol) {
  // Descriptors with 6 significant digits: their last digits differ between machines.
  auto rounded = [](const PackingDescriptors& d) {
    char text[200];
    std::snprintf(text, sizeof text, "%d %d %.6g %.6g %.6g", d.dimension, d.particles, d.porosity, d.coordination,
                  d.radius_ratio);
    return std::string(text);
  };
  const nlohmann::json identity = {{"format", kFormat}, {"ucs", rounded(ucs)}, {"bts", rounded(bts)},
                                   {"protocol", protocol}};
  return "maps_2d_lattice_" + MapIdentityHash(identity.dump()) + ".json";
}

bool LatticeMapMatches(const LatticeStrengthMap& map, const PackingDescriptors& ucs, const PackingDescriptors& bts,
                       const nlohmann::json& protocol, std::string* why) {
  std::string text;
  auto count_differs = [&](const PackingDescriptors& built_on, const PackingDescriptors& d, const char* which) {
    if (d.particles > 0 && std::abs(static_cast<double>(built_on.particles) / d.particles - 1.0) <= 0.1) return false;
    text = std::string(which) + " specimen: " + std::to_string(d.particles) + " particles, the map's " +
           std::to_string(built_on.particles) + " (more than 10 % apart)";
    return true;
  };
  if (!MapsMatchPacking(map.ucs_descriptors, ucs, &text)) text = "UCS specimen: " + text;
  else if (!MapsMatchPacking(map.bts_descriptors, bts, &text)) text = "Brazilian specimen: " + text;
  else if (count_differs(map.ucs_descriptors, ucs, "UCS") || count_differs(map.bts_descriptors, bts, "Brazilian")) {
  } else if (map.protocol != protocol) {
    text = "the tests' protocol differs (map: " + map.protocol.dump() + ")";
  }
  if (why) *why = text;
  return text.empty();
}

std::string FindLatticeStrengthMap(const std::string& directory, const PackingDescriptors& ucs,
                                   const PackingDescriptors& bts, const nlohmann::json& protocol) {
  namespace fs = std::filesystem;
  const fs::path named = fs::path(directory) / LatticeMapFileName(ucs, bts, protocol);
  std::vector<fs::path> candidates;
  if (fs::exists(named)) candidates.push_back(named);
  std::error_code error;
  if (fs::is_directory(directory, error)) {
    std::vector<fs::path> others;
    for (const fs::directory_entry& e : fs::directory_iterator(directory, error)) {
      const std::string name = e.path().filename().string();
      if (e.is_regular_file() && name.rfind("maps_2d_lattice_", 0) == 0 && e.path().extension() == ".json" &&
          e.path() != named)
        others.push_back(e.path());
    }
    std::sort(others.begin(), others.end());  // the same choice on every machine
    candidates.insert(candidates.end(), others.begin(), others.end());
  }
  for (const fs::path& p : candidates) {
    try {
      if (LatticeMapMatches(LoadLatticeStrengthMap(p.string()), ucs, bts, protocol, nullptr)) return p.string();
    } catch (const std::exception&) {
      // Not a readable lattice map: not a candidate.
    }
  }
  return {};
}

}  // namespace specimen
