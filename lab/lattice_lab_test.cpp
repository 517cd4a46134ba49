#include "lab/lattice_lab_test.h"

#include "lab/brazilian_jaws.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "common/error.h"
#include "lab/lab_measurement.h"
#include "solver/lattice_packing.h"
#include "solver/lattice_stability.h"
#include "common/format.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A maximum of the control this much above the largest sampled one is sampled (relative).
constexpr double kPeakResolution = 2e-3;

// Node sets of the specimen: the platen nodes, the sides, the nodes held in x.
struct Supports {
  std::vector<int> top, bottom, left, right, held_x;
};

Supports RectangleSupports(const PackingLattice& p, const Domain<2>& domain) {
  Supports s;
  const Vector<2> lo = domain.Lower(), hi = domain.Upper();
  const double tol = 1e-9 * domain.SmallestExtent();
  int corner = -1;
  for (int i = p.particle_nodes; i < p.node_count(); ++i) {
    const Vector<2>& x = p.nodes[i];
    const bool bottom = x.y() < lo.y() + tol, top = x.y() > hi.y() - tol;
    if (bottom) s.bottom.push_back(i);
    if (top) s.top.push_back(i);
    if (x.x() < lo.x() + tol) s.left.push_back(i);
    if (x.x() > hi.x() - tol) s.right.push_back(i);
    // The bottom node nearest the middle is held in x: the sides then move apart
    // symmetrically (a held corner would take the confinement's transient on one side).
    const double middle = 0.5 * (lo.x() + hi.x());
    if (bottom && (corner < 0 || std::abs(x.x() - middle) < std::abs(p.nodes[corner].x() - middle))) corner = i;
  }
  if (s.top.empty() || s.bottom.empty() || s.left.empty() || s.right.empty() || corner < 0)
    throw InputError("the lattice specimen has no surface nodes on a side of its rectangle");
  s.held_x.push_back(corner);
  return s;
}

Supports DiscSupports(const PackingLattice& p, const Domain<2>& domain) {
  Supports s;
  const Vector<2> centre = domain.CircleCentre();
  int north = -1, south = -1;
  for (int i = p.particle_nodes; i < p.node_count(); ++i) {
    const double y = p.nodes[i].y() - centre.y();
    if (y > 0.0) s.top.push_back(i);
    else s.bottom.push_back(i);
    if (north < 0 || p.nodes[i].y() > p.nodes[north].y()) north = i;
    if (south < 0 || p.nodes[i].y() < p.nodes[south].y()) south = i;
  }
  if (north < 0 || south < 0 || north == south) throw InputError("the lattice disc has no surface nodes");
  s.held_x = {north, south};
  return s;
}

// A Brazilian jaw with a loading arc: the surface nodes within alpha of its pole, each pressed
// along its inward normal n_i with the share w_i of the jaw's force that its arc length has
// (uniform radial pressure, Hondros 1959). The jaw's force follows a penalty on its
// penetration travel C - sum w_i n_i . u_i, C = sum w_i cos theta_i (a rigid jaw moved by
// `travel` along y moves the arc at theta_i by travel cos theta_i along n_i).
struct Jaw {
  std::vector<int> nodes;
  std::vector<double> weights;       // sum 1
  std::vector<Vector<2>> inward;     // unit normals towards the centre
  double reach = 0.0;                // C
};

// The jaws of a loading arc 2 alpha (radians) on the disc's surface nodes: north, south.
std::array<Jaw, 2> ArcJaws(const PackingLattice& p, const Domain<2>& domain, double alpha) {
  const Vector<2> centre = domain.CircleCentre();
  // Each surface node's arc length share: half the angular gap to its neighbours.
  std::vector<std::pair<double, int>> around;
  for (int i = p.particle_nodes; i < p.node_count(); ++i) {
    const Vector<2> r = p.nodes[i] - centre;
    around.push_back({std::atan2(r.y(), r.x()), i});
  }
  std::sort(around.begin(), around.end());
  const int m = static_cast<int>(around.size());
  std::array<Jaw, 2> jaws;
  for (int k = 0; k < m; ++k) {
    const double before = around[(k + m - 1) % m].first, after = around[(k + 1) % m].first;
    double gap = after - before;
    if (gap <= 0.0) gap += 2.0 * kPi;
    const int i = around[k].second;
    const Vector<2> r = p.nodes[i] - centre;
    const int side = r.y() > 0.0 ? 0 : 1;
    const double from_pole = std::atan2(std::abs(r.x()), std::abs(r.y()));
    if (from_pole > alpha) continue;
    jaws[side].nodes.push_back(i);
    jaws[side].weights.push_back(0.5 * gap);
    jaws[side].inward.push_back(-r / r.norm());
  }
  for (Jaw& jaw : jaws) {
    if (jaw.nodes.empty()) throw InputError("the loading arc holds no surface node of the lattice disc");
    double total = 0.0;
    for (double w : jaw.weights) total += w;
    for (size_t k = 0; k < jaw.nodes.size(); ++k) {
      jaw.weights[k] /= total;
      jaw.reach += jaw.weights[k] * std::abs(jaw.inward[k].y());
    }
  }
  return jaws;
}

// Area averages of the triangles' stress and strain (Voigt), and the failed counts.
struct Averages {
  Eigen::Vector3d stress = Eigen::Vector3d::Zero(), strain = Eigen::Vector3d::Zero();
};

Eigen::Matrix3d Tensor(const Eigen::Vector3d& voigt, bool engineering_shear) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(0, 0) = voigt[0];
  m(1, 1) = voigt[1];
  m(0, 1) = m(1, 0) = engineering_shear ? 0.5 * voigt[2] : voigt[2];
  return m;
}

// The edges between two particle nodes with the triangles on each side, for the snapshots.
struct EdgeMap {
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 2>> triangles;  // -1: none
};

EdgeMap ParticleEdges(const PackingLattice& p) {
  std::map<std::pair<int, int>, std::array<int, 2>> found;
  const TriangleLattice& lattice = p.triangles;
  for (int k = 0; k < lattice.size(); ++k)
    for (int e = 0; e < 3; ++e) {
      const int a = lattice.nodes[k][e], b = lattice.nodes[k][(e + 1) % 3];
      if (a >= p.particle_nodes || b >= p.particle_nodes) continue;
      auto [it, inserted] = found.try_emplace(std::minmax(a, b), std::array<int, 2>{k, -1});
      if (!inserted) it->second[1] = k;
    }
  EdgeMap map;
  for (const auto& [edge, sides] : found) {
    map.edges.push_back({edge.first, edge.second});
    map.triangles.push_back(sides);
  }
  return map;
}

// The particle nodes and their edges at one moment: an edge is broken as the first failed
// triangle beside it failed (shear before tension when both sides failed differently).
LabSnapshot Snapshot(const std::string& label, double time_s, const PackingLattice& p, const EdgeMap& edges,
                     const std::vector<Vector<2>>& u, const std::vector<TriangleFailure>& failure) {
  LabSnapshot s;
  s.recorded = true;
  s.label = label;
  s.time_s = time_s;
  for (int i = 0; i < p.particle_nodes; ++i) {
    s.position.emplace_back(p.nodes[i].x() + u[i].x(), p.nodes[i].y() + u[i].y(), 0.0);
    s.displacement.emplace_back(u[i].x(), u[i].y(), 0.0);
  }
  s.bonds = edges.edges;
  for (const auto& sides : edges.triangles) {
    ContactState state = ContactState::kBonded;
    for (int k : sides) {
      if (k < 0) continue;
      if (failure[k] == TriangleFailure::kShear) state = ContactState::kBrokenInShear;
      if (failure[k] == TriangleFailure::kTension && state == ContactState::kBonded) state = ContactState::kBrokenInTension;
    }
    s.bond_state.push_back(state);
  }
  return s;
}

}  // namespace

bool LatticeMaterial::IsValid(std::string* error) const {
  if (!elasticity.IsPositiveDefinite()) {
    *error = "the lattice's elasticity matrix D is not positive definite (check E, nu)";
    return false;
  }
  if (!(density_kg_per_m3 > 0.0 && std::isfinite(density_kg_per_m3))) {
    *error = "density = " + Number(density_kg_per_m3) + ": must be positive [kg/m^3]";
    return false;
  }
  return strength.IsValid(error);
}

bool LatticeProtocol::IsValid(std::string* error) const {
  if (!(platen_zone_share >= 0.0 && platen_zone_share <= 0.3)) {
    *error = "platen_zone = " + std::to_string(platen_zone_share) + ": must be in [0, 0.3] (share of the diameter)";
    return false;
  }
  if (!(loading_arc_deg >= 0.0 && loading_arc_deg <= 60.0)) {
    *error = "loading_arc = " + Number(loading_arc_deg) + ": must be in [0, 60] (degrees, the jaw's arc 2 alpha)";
    return false;
  }
  if (!(local_damping >= 0.0 && local_damping < 1.0)) {
    *error = "local_damping = " + Number(local_damping) + ": must be in [0, 1)";
    return false;
  }
  for (const auto& [name, share] : {std::pair<const char*, double>{"compression_wave_share", compression_wave_share},
                                    {"brazilian_wave_share", brazilian_wave_share}})
    if (!(share >= 0.0 && share <= 1.0)) {
      *error = std::string(name) + " = " + Number(share) + ": must be in [0, 1] (0: the loading-rate group as given)";
      return false;
    }
  return true;
}

namespace {

// The test at `rate_factor` x the platen speed of the options and the protocol (1, or 0.5 for
// the quasi-static check); the inputs are checked by RunLatticeLabTest.
LabTestResult RunLatticeTestAtRate(const Packing<2>& packing, const LatticeMaterial& material,
                                   const LabTestOptions& options, const LatticeProtocol& protocol,
                                   double rate_factor) {
  // `ucs`: a rectangle between platens, unconfined or (confined) with the confining stress
  // on its sides; else the Brazilian disc.
  const bool confined = options.kind == LabTestKind::kConfinedCompression;
  const bool ucs = options.kind == LabTestKind::kUniaxialCompression || confined;
  if (!ucs && options.kind != LabTestKind::kBrazilian)
    throw InputError(std::string("test kind '") + LabTestKindName(options.kind) +
                     "': the lattice model runs the ucs, biaxial and brazilian tests");
  const Domain<2>& domain = packing.domain;
  if (ucs && domain.shape() != DomainShape::kRectangle)
    throw InputError(std::string("the lattice ") + LabTestKindName(options.kind) +
                     " test needs a rectangle specimen, not a " + domain.ShapeName());
  if (!ucs && domain.shape() != DomainShape::kDisc)
    throw InputError("the lattice Brazilian test needs a disc specimen, not a " + domain.ShapeName());
  const auto start = std::chrono::steady_clock::now();

  PackingLatticeSummary lattice_summary;
  const PackingLattice specimen = BuildPackingLattice(packing, material.elasticity, 1.0, {}, &lattice_summary);
  const TriangleLattice& lattice = specimen.triangles;
  const int n = specimen.node_count();
  const std::vector<double> mass = LumpedMasses(lattice, n, material.density_kg_per_m3);
  const Supports supports = ucs ? RectangleSupports(specimen, domain) : DiscSupports(specimen, domain);
  const PlaneElasticity& d = material.elasticity;
  const double bulk = AreaBulkModulus(d);

  // Geometry and rate.
  const double height = ucs ? domain.Upper().y() - domain.Lower().y() : 2.0 * domain.CircleRadius();
  const double width = ucs ? domain.Upper().x() - domain.Lower().x() : 2.0 * domain.CircleRadius();
  const double wave_speed = std::sqrt(d.d22 / material.density_kg_per_m3);
  // The group, capped so that the platens' wave stress d22 g stays a small share of the
  // weaker strength of the triangles (LatticeProtocol).
  double group = options.loading_rate_group;
  const double wave_share = ucs ? protocol.compression_wave_share : protocol.brazilian_wave_share;
  const double weaker = std::min(material.strength.tensile_strength_pa, material.strength.cohesion_pa);
  if (wave_share > 0.0) group = std::min(group, wave_share * weaker / d.d22);
  // (A platen speed given is used as it is, uncapped.)
  const double speed =
      rate_factor * (options.platen_speed_m_per_s > 0.0 ? options.platen_speed_m_per_s : group * wave_speed);
  const double transit = height / wave_speed;
  const double ramp = options.velocity_ramp_transits * transit;
  const double strain_limit = options.strain_limit > 0.0 ? options.strain_limit : 0.02;
  // Brazilian platens: a penalty of E' s per contacting node (compression only); a jaw with a
  // loading arc gets E' s per node of its arc (against its penetration).
  const double platen_stiffness = d.d22;
  const double arc_half_angle = 0.5 * protocol.loading_arc_deg * kPi / 180.0;
  const bool arc = !ucs && arc_half_angle > 0.0;
  const std::array<Jaw, 2> jaws = arc ? ArcJaws(specimen, domain, arc_half_angle) : std::array<Jaw, 2>{};
  std::array<double, 2> jaw_stiffness{0.0, 0.0};
  for (int j = 0; arc && j < 2; ++j)
    jaw_stiffness[j] = platen_stiffness * static_cast<double>(jaws[j].nodes.size());

  // Time step: the lattice's certified limit, with the platen penalty added by Weyl's
  // inequality (lambda_max(A + B) <= lambda_max(A) + lambda_max(B)).
  LanczosOptions lanczos;
  lanczos.num_threads = options.num_threads;
  const LatticeStability stability = AnalyseLatticeStability(lattice, mass, lanczos);
  double omega_squared = stability.omega_max_squared;
  if (!ucs) {
    double lightest = std::numeric_limits<double>::infinity();
    for (int i = specimen.particle_nodes; i < n; ++i)
      if (mass[i] > 0.0) lightest = std::min(lightest, mass[i]);
    double platens = platen_stiffness / lightest;
    // A jaw couples its nodes by the rank-one K (w n)(w n)^T: lambda_max(M^-1 K) <= K sum w_i^2 / m_i.
    if (arc) {
      platens = 0.0;
      for (int j = 0; j < 2; ++j) {
        double sum = 0.0;
        for (size_t k = 0; k < jaws[j].nodes.size(); ++k)
          sum += jaws[j].weights[k] * jaws[j].weights[k] / mass[jaws[j].nodes[k]];
        platens = std::max(platens, jaw_stiffness[j] * sum);
      }
    }
    omega_squared += platens;
  }
  const double critical = 2.0 / std::sqrt(omega_squared);
  const double dt = options.time_step_safety_factor * critical;

  LabTestResult result;
  result.dimension = 2;
  result.kind = options.kind;
  result.domain = domain.ToText();
  result.particles = packing.size();
  result.bonds = lattice.size();
  result.porosity = NominalPorosity<2>(domain, packing.radii);
  result.mean_radius_m = VolumeMeanRadius<2>(packing.radii);
  result.density_used_kg_per_m3 = material.density_kg_per_m3;
  result.height_m = height;
  result.width_m = width;
  result.loading_rate_group = speed / wave_speed;
  result.platen_speed_m_per_s = speed;
  result.strain_rate_per_s = 2.0 * speed / height;
  result.time_step_s = dt;
  result.critical_time_step_s = critical;
  result.strain_limit = strain_limit;
  result.stages = {"lattice_forces", "triangle_failure",
                   ucs ? "glued_platens" : arc ? "pressure_jaws" : "penalty_platens", "local_damping",
                   "central_differences"};

  std::vector<char> prescribed_y(n, 0), held_x(n, 0);
  if (ucs) {
    for (int i : supports.top) prescribed_y[i] = 1;
    for (int i : supports.bottom) prescribed_y[i] = 1;
  }
  for (int i : supports.held_x) held_x[i] = 1;

  std::vector<Vector<2>> u(n, Vector<2>::Zero()), v(n, Vector<2>::Zero()), f(n);
  std::vector<TriangleFailure> failure(lattice.size(), TriangleFailure::kIntact);
  // Brazilian: the triangles within the platen zones stay elastic (header comment).
  std::vector<char> breakable(lattice.size(), 1);
  if (!ucs) {
    const double zone = protocol.platen_zone_share * 2.0 * domain.CircleRadius();
    const Vector<2> c = domain.CircleCentre();
    const Vector<2> north(c.x(), c.y() + domain.CircleRadius()), south(c.x(), c.y() - domain.CircleRadius());
    for (int k = 0; k < lattice.size(); ++k)
      for (int i : lattice.nodes[k])
        if ((specimen.nodes[i] - north).norm() < zone || (specimen.nodes[i] - south).norm() < zone) breakable[k] = 0;
  }
  std::vector<Eigen::Vector3d> stress(lattice.size(), Eigen::Vector3d::Zero());
  double travel = 0.0;  // of each platen
  long broken_tension = 0, broken_shear = 0;
  const double alpha = protocol.local_damping;
  // Brazilian platens start at the extreme surface nodes (the bonded tests place their walls
  // at the extreme particles), so both touch from the start.
  double platen_top0 = 0.0, platen_bottom0 = 0.0;
  if (!ucs) {
    platen_top0 = specimen.nodes[supports.held_x[0]].y();
    platen_bottom0 = specimen.nodes[supports.held_x[1]].y();
  }
  double peak = 0.0;
  double previous_control = 0.0;  // of the last step
  bool rising = false;            // the control rose over the last step
  double last_maximum_sampled = 0.0;  // the maximum whose falling step was last sampled
  int peak_index = -1;

  const EdgeMap edges = options.record_snapshots ? ParticleEdges(specimen) : EdgeMap{};
  // Confined: sigma_3 on the side surface nodes, as forces over each node's share of its side
  // (half the distance to its neighbours along it), raised over one ramp before the platens
  // move (consolidation), then held.
  const double sigma_3 = confined ? options.confining_stress_pa : 0.0;
  const double consolidation = confined ? ramp : 0.0;
  std::vector<std::pair<int, double>> side_load;  // node, x force at full sigma_3
  if (confined) {
    for (const std::vector<int>* side : {&supports.left, &supports.right}) {
      std::vector<int> nodes = *side;
      std::sort(nodes.begin(), nodes.end(),
                [&](int a, int b) { return specimen.nodes[a].y() < specimen.nodes[b].y(); });
      const double sign = side == &supports.left ? 1.0 : -1.0;  // inwards
      for (size_t k = 0; k < nodes.size(); ++k) {
        const double below = k > 0 ? specimen.nodes[nodes[k - 1]].y() : specimen.nodes[nodes[k]].y();
        const double above = k + 1 < nodes.size() ? specimen.nodes[nodes[k + 1]].y() : specimen.nodes[nodes[k]].y();
        side_load.push_back({nodes[k], sign * sigma_3 * 0.5 * (above - below) * lattice.thickness_m});
      }
    }
  }
  const double steps_needed =
      std::ceil((strain_limit * height / 2.0 + speed * ramp + speed * consolidation) / (speed * dt)) + 10.0;
  // The budget, before any step; with the half-rate repeat, that run's twice as many steps too
  // (refused now rather than after the first run).
  const double budget = options.check_quasi_static ? 2.0 * steps_needed : steps_needed;
  if (!(budget <= static_cast<double>(options.max_steps)))
    throw InputError(StepBudgetRefusal(budget, strain_limit, speed, dt, options.max_steps,
                                       options.check_quasi_static
                                           ? "; the count is of the test and its half-rate repeat (quasi_static_check)"
                                           : ""));
  const long max_steps = static_cast<long>(steps_needed);
  // The energy audit: triangles' V sigma:eps / 2 (particle_elastic), the Brazilian platens'
  // penalty (contact_elastic), the platens' work, local damping, and the energy of each
  // triangle at the step it failed (breakage_release).
  EnergyBalance audit;
  auto kinetic_energy = [&]() {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += 0.5 * mass[i] * v[i].squaredNorm();
    return sum;
  };
  long step = 0;
  for (; step < max_steps; ++step) {
    const double t = step * dt, loading = t - consolidation;
    const double advance = loading <= 0.0 ? 0.0 : dt * speed * std::min(1.0, ramp > 0.0 ? loading / ramp : 1.0);
    travel += advance;
    std::fill(f.begin(), f.end(), Vector<2>::Zero());
    double elastic = 0.0, platen_elastic = 0.0;
    // Triangles: the natural law while intact, the pressure after failure.
    for (int k = 0; k < lattice.size(); ++k) {
      if (failure[k] != TriangleFailure::kIntact) {
        stress[k] = AddFailedTriangleForces(lattice, k, bulk, u, &f);
        elastic += 0.5 * stress[k][0] * stress[k][0] / bulk * lattice.areas[k] * lattice.thickness_m;
        continue;
      }
      const std::array<int, 3>& nodes = lattice.nodes[k];
      std::array<Vector<2>, 3> direction;
      const Eigen::Vector3d h = EdgeStretches(lattice, k, u, &direction);
      const Eigen::Vector3d edge_force = lattice.stiffness[k] * h;
      Eigen::Vector3d s = Eigen::Vector3d::Zero();
      for (int e = 0; e < 3; ++e) {
        const Vector<2> pull = edge_force[e] * direction[e];
        f[nodes[e]] += pull;
        f[nodes[(e + 1) % 3]] -= pull;
        const double length = lattice.rest_lengths[k][e] + h[e];
        s += edge_force[e] * length *
             Eigen::Vector3d(direction[e].x() * direction[e].x(), direction[e].y() * direction[e].y(),
                             direction[e].x() * direction[e].y());
      }
      stress[k] = s / (lattice.areas[k] * lattice.thickness_m);
      const double energy = 0.5 * h.dot(edge_force);
      elastic += energy;
      // Failure applies from the next step (the forces of this one are already summed).
      if (!breakable[k]) continue;
      failure[k] = FailureOf(stress[k], material.strength);
      if (failure[k] != TriangleFailure::kIntact) {
        // Released: the energy it held less what its pressure keeps at the same strain.
        const Eigen::Vector3d strain = TriangleStrain(lattice, k, u);
        const double compaction = std::min(0.0, strain[0] + strain[1]);
        audit.breakage_release_j +=
            energy - 0.5 * bulk * compaction * compaction * lattice.areas[k] * lattice.thickness_m;
      }
      if (failure[k] == TriangleFailure::kTension) ++broken_tension;
      if (failure[k] == TriangleFailure::kShear) ++broken_shear;
    }
    // Platens.
    double force_top = 0.0, force_bottom = 0.0;
    if (ucs) {
      for (int i : supports.top) force_top += f[i].y();
      for (int i : supports.bottom) force_bottom -= f[i].y();
    } else if (arc) {
      for (int j = 0; j < 2; ++j) {
        const Jaw& jaw = jaws[j];
        double penetration = travel * jaw.reach;
        for (size_t k = 0; k < jaw.nodes.size(); ++k)
          penetration -= jaw.weights[k] * jaw.inward[k].dot(u[jaw.nodes[k]]);
        if (penetration <= 0.0) continue;
        const double force = jaw_stiffness[j] * penetration;
        for (size_t k = 0; k < jaw.nodes.size(); ++k)
          f[jaw.nodes[k]] += jaw.weights[k] * force * jaw.inward[k];
        (j == 0 ? force_top : force_bottom) += force * jaw.reach;
        platen_elastic += 0.5 * jaw_stiffness[j] * penetration * penetration;
      }
    } else {
      const double top = platen_top0 - travel, bottom = platen_bottom0 + travel;
      for (int i : supports.top) {
        const double y = specimen.nodes[i].y() + u[i].y();
        if (y > top) {
          f[i].y() -= platen_stiffness * (y - top);
          force_top += platen_stiffness * (y - top);
          platen_elastic += 0.5 * platen_stiffness * (y - top) * (y - top);
        }
      }
      for (int i : supports.bottom) {
        const double y = specimen.nodes[i].y() + u[i].y();
        if (y < bottom) {
          f[i].y() += platen_stiffness * (bottom - y);
          force_bottom += platen_stiffness * (bottom - y);
          platen_elastic += 0.5 * platen_stiffness * (bottom - y) * (bottom - y);
        }
      }
    }
    // Confinement, and its work on the side nodes.
    if (confined) {
      const double share = consolidation > 0.0 ? std::min(1.0, t / consolidation) : 1.0;
      for (const auto& [i, force] : side_load) {
        f[i].x() += share * force;
        audit.wall_work_j += share * force * v[i].x() * dt;
      }
    }
    // Damped central differences (local damping: alpha |F| against the velocity).
    for (int i = 0; i < n; ++i) {
      if (!(mass[i] > 0.0)) continue;
      for (int a = 0; a < 2; ++a) {
        if ((a == 0 && held_x[i]) || (a == 1 && prescribed_y[i])) continue;
        const double drag = alpha * std::abs(f[i][a]) * (v[i][a] > 0.0 ? 1.0 : v[i][a] < 0.0 ? -1.0 : 0.0);
        const double before = v[i][a];
        v[i][a] += dt * (f[i][a] - drag) / mass[i];
        u[i][a] += dt * v[i][a];
        audit.damping_dissipation_j += drag * 0.5 * (before + v[i][a]) * dt;
      }
    }
    if (ucs) {
      for (int i : supports.top) u[i].y() = -travel;
      for (int i : supports.bottom) u[i].y() = travel;
    }
    // The platens' work on the specimen: their compressive reactions over this step's advance.
    audit.wall_work_j += (force_top + force_bottom) * advance;
    audit.particle_elastic_j = elastic;
    audit.contact_elastic_j = platen_elastic;
    if (!std::isfinite(force_top + force_bottom))
      throw ComputationError("the lattice test diverged at step " + std::to_string(step) + " (platen force not finite)");

    // The peak is resolved to the step, not to the sample interval: a sample is also taken at
    // the first step that falls after a maximum of the control more than kPeakResolution above
    // the largest sampled one (the control itself is known at every step).
    const double control_now =
        ucs ? 0.5 * (force_top + force_bottom) / width - sigma_3 : 0.5 * (force_top + force_bottom);
    bool past_maximum = false;
    if (t > ramp + consolidation) {
      past_maximum = control_now < previous_control && rising &&
                     previous_control > (1.0 + kPeakResolution) * std::max(peak, last_maximum_sampled);
      if (past_maximum) last_maximum_sampled = previous_control;
      rising = control_now > previous_control;
    }
    previous_control = control_now;
    if (!(step % options.sample_interval_steps == 0 || past_maximum)) continue;
    LabCurvePoint point;
    point.step = step;
    point.time_s = t;
    Averages mean;
    double area = 0.0;
    for (int k = 0; k < lattice.size(); ++k) {
      mean.stress += lattice.areas[k] * stress[k];
      mean.strain += lattice.areas[k] * TriangleStrain(lattice, k, u);
      area += lattice.areas[k];
    }
    mean.stress /= area;
    mean.strain /= area;
    point.stress_pa = Tensor(mean.stress, false);
    point.strain = Tensor(mean.strain, true);
    point.volume_m3 = area * lattice.thickness_m;
    point.boundary_strain = 2.0 * travel / height;
    point.platen_force_n = 0.5 * (force_top + force_bottom);
    point.axial_stress_pa = -mean.stress[1];
    point.lateral_stress_pa = -mean.stress[0];
    point.control = ucs ? point.platen_force_n / width - sigma_3 : point.platen_force_n;  // deviator when confined
    point.broken_in_tension = broken_tension;
    point.broken_in_shear = broken_shear;
    audit.kinetic_j = point.kinetic_energy_j = kinetic_energy();
    point.elastic_energy_j = audit.Elastic();
    point.external_work_j = audit.ExternalWork();
    point.dissipated_j = audit.Dissipated();
    result.curve.push_back(point);
    // The peak after the ramp (the first contact of the platens rings during it).
    if (t > ramp + consolidation && point.control > peak) {
      peak = point.control;
      peak_index = static_cast<int>(result.curve.size()) - 1;
      if (options.record_snapshots) result.peak_snapshot = Snapshot("peak", t, specimen, edges, u, failure);
    }
    // Past the ramp: stop once the control has fallen far enough below its peak.
    if (peak_index >= 3 && point.control <= options.post_peak_stress_fraction * peak) {
      result.termination = LabTermination::kPostPeak;
      break;
    }
    if (options.progress && result.curve.size() % 20 == 0)
      options.progress(std::min(1.0, point.boundary_strain / strain_limit),
                       "lattice " + std::string(LabTestKindName(options.kind)) + ": strain " +
                           Number(point.boundary_strain));
  }
  result.steps = step;
  result.simulated_time_s = step * dt;
  if (options.record_snapshots) result.end_snapshot = Snapshot("end", step * dt, specimen, edges, u, failure);
  result.broken_in_tension = broken_tension;
  result.broken_in_shear = broken_shear;
  audit.kinetic_j = kinetic_energy();
  result.energy = audit;
  // The peak after the ramp (FindPeak over the whole curve would take the ringing of the
  // first contact for it).
  CurvePeak found;
  found.index = peak_index;
  found.control = peak;
  for (int k = peak_index + 1; peak_index >= 0 && k < static_cast<int>(result.curve.size()); ++k)
    found.confirmed |= result.curve[k].control <= options.post_peak_stress_fraction * peak;
  result.peak_reached = found.confirmed;
  std::ostringstream message;
  if (result.termination == LabTermination::kPostPeak) {
    message << "the control fell to " << options.post_peak_stress_fraction << " of its peak";
  } else {
    message << "strain limit " << strain_limit << " reached" << (found.confirmed ? "" : " without a peak");
  }
  result.termination_message = message.str();
  if (found.index >= 0) {
    const LabCurvePoint& at = result.curve[found.index];
    result.peak_control = at.control;
    result.peak_force_n = at.platen_force_n;
    result.strain_at_peak = -at.strain(1, 1);
    result.boundary_strain_at_peak = at.boundary_strain;
    if (ucs) {
      result.peak_stress_pa = at.control + sigma_3;  // sigma_1
      result.confining_stress_pa = sigma_3;
      result.elastic = SecantElasticConstants<2>(result.curve, found, 1, options.modulus_window_low,
                                                 options.modulus_window_high);
      result.linear_elastic = LinearPortionElasticConstants<2>(result.curve, 1, options.linear_portion_low);
    } else {
      // The centre's tensile stress at the peak (Hondros 1959; k = 1 for a point load, Labra (4.38)).
      const double k = HondrosFactor(arc ? protocol.loading_arc_deg : 0.0);
      result.tensile_strength_factor = k;
      result.loading_arc_deg = arc ? protocol.loading_arc_deg : 0.0;
      result.tensile_strength_pa = k * 2.0 * at.platen_force_n / (kPi * height * lattice.thickness_m);
      result.peak_stress_pa = result.tensile_strength_pa;
    }
  }
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace

LabTestResult RunLatticeLabTest(const Packing<2>& packing, const LatticeMaterial& material,
                                const LabTestOptions& options, const LatticeProtocol& protocol) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (!protocol.IsValid(&error)) throw InputError(error);
  if (!material.IsValid(&error)) throw InputError(error);
  LabTestResult result = RunLatticeTestAtRate(packing, material, options, protocol, 1.0);
  if (options.check_quasi_static) {
    LabTestOptions half = options;
    half.check_quasi_static = false;
    half.record_snapshots = false;
    half.progress = nullptr;
    const LabTestResult slow = RunLatticeTestAtRate(packing, material, half, protocol, 0.5);
    result.quasi_static = CompareAtHalfRate(options, result, slow);
    result.wall_seconds += slow.wall_seconds;
  }
  return result;
}

}  // namespace specimen
