#include "solver/stability_network.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "common/error.h"
#include "solver/bond_moment.h"
#include "solver/bond_range.h"
#include "solver/neighbour_search.h"
#include "solver/particles.h"

namespace specimen {

namespace {

// Loops shorter than this run on one thread (as the solver's passes).
constexpr int kParallelItems = 4096;

// sym(n (x) f) in the compact form of vector_algebra.h.
inline SymmetricTensor<2> SymmetricOuter(const Vector<2>& n, const Vector<2>& f) {
  return SymmetricTensor<2>(n.x() * f.x(), n.y() * f.y(), 0.5 * (n.x() * f.y() + n.y() * f.x()));
}
inline SymmetricTensor<3> SymmetricOuter(const Vector<3>& n, const Vector<3>& f) {
  SymmetricTensor<3> t;
  t << n.x() * f.x(), n.y() * f.y(), n.z() * f.z(), 0.5 * (n.y() * f.z() + n.z() * f.y()),
      0.5 * (n.x() * f.z() + n.z() * f.x()), 0.5 * (n.x() * f.y() + n.y() * f.x());
  return t;
}

// theta x s for an angular quantity (about z in 2D).
inline Vector<2> RotationCross(double theta, const Vector<2>& s) { return Cross(theta, s); }
inline Vector<3> RotationCross(const Vector<3>& theta, const Vector<3>& s) {
  return theta.cross(s);
}

}  // namespace

template <int Dim>
LinearisedNetwork<Dim>::LinearisedNetwork(const Packing<Dim>& packing,
                                          const SceneOptions<Dim>& scene, double wall_reach_m) {
  std::string error;
  if (!scene.IsValid(&error)) throw InputError(error);
  num_threads_ = scene.num_threads;
  // Validate in the caller's numbering (BuildParticles checks radii and centres).
  const int count = BuildParticles<Dim>(packing, scene.material, false).size();
  for (const auto& pair : packing.contacts)
    if (pair[0] < 0 || pair[0] >= count || pair[1] < 0 || pair[1] >= count || pair[0] == pair[1])
      throw InputError("packing contact (" + std::to_string(pair[0]) + ", " +
                       std::to_string(pair[1]) + ") does not join two distinct particles of [0, " +
                       std::to_string(count - 1) + "]");
  for (const FixedDofs<Dim>& fixed : scene.fixed_dofs)
    for (const int p : fixed.particles)
      if (p < 0 || p >= count)
        throw InputError("fixed dofs \"" + fixed.name + "\": particle index " + std::to_string(p) +
                         " is outside [0, " + std::to_string(count - 1) + "]");
  for (const WallOptions<Dim>& wall : scene.walls)
    for (const int p : wall.jaw_particles)
      if (p < 0 || p >= count)
        throw InputError("wall \"" + wall.name + "\" jaw_particles: particle index " + std::to_string(p) +
                         " is outside [0, " + std::to_string(count - 1) + "]");

  // Internally the particles are renumbered along a Z-order (Morton) curve of cells of about
  // two mean radii: the products then read the unknowns of neighbours from nearby memory.
  const double cell = 2.0 * VolumeMeanRadius<Dim>(packing.radii);
  Vector<Dim> lower = packing.centres[0];
  for (const Vector<Dim>& x : packing.centres) lower = lower.cwiseMin(x);
  std::vector<std::pair<std::uint64_t, int>> keys(count);
  for (int p = 0; p < count; ++p) {
    std::uint64_t key = 0;
    for (int axis = 0; axis < Dim; ++axis) {
      const std::uint64_t c = static_cast<std::uint64_t>(
          std::min(2.0e6, std::floor((packing.centres[p][axis] - lower[axis]) / cell)));
      for (int bit = 0; bit < 21; ++bit) key |= ((c >> bit) & 1ULL) << (Dim * bit + axis);
    }
    keys[p] = {key, p};
  }
  std::sort(keys.begin(), keys.end());
  original_index_.resize(count);
  internal_index_.resize(count);
  std::vector<int>& internal = internal_index_;
  for (int k = 0; k < count; ++k) {
    original_index_[k] = keys[k].second;
    internal[keys[k].second] = k;
  }
  Packing<Dim> sorted(packing.domain);
  sorted.centres.resize(count);
  sorted.radii.resize(count);
  for (int k = 0; k < count; ++k) {
    sorted.centres[k] = packing.centres[original_index_[k]];
    sorted.radii[k] = packing.radii[original_index_[k]];
  }
  sorted.contacts = packing.contacts;
  for (auto& pair : sorted.contacts) pair = {internal[pair[0]], internal[pair[1]]};
  SceneOptions<Dim> sorted_scene = scene;
  for (FixedDofs<Dim>& fixed : sorted_scene.fixed_dofs)
    for (int& p : fixed.particles) p = internal[p];
  for (WallOptions<Dim>& wall : sorted_scene.walls)
    for (int& p : wall.jaw_particles) p = internal[p];
  Build(sorted, sorted_scene, wall_reach_m);
}

template <int Dim>
void LinearisedNetwork<Dim>::Build(const Packing<Dim>& packing, const SceneOptions<Dim>& scene,
                                   double wall_reach_m) {
  const MaterialParameters& material = scene.material;

  // 1. Particles: radius, mass, volume.
  const ParticleArrays<Dim> particles = BuildParticles<Dim>(packing, material, false);
  const int count = particles.size();
  radius_ = particles.radius;
  mass_ = particles.mass;
  volume_.resize(count);
  for (int p = 0; p < count; ++p) volume_[p] = ParticleVolume<Dim>(radius_[p]);

  // 2. The packing's pairs (validated by the constructor) and the pairs within the bonds'
  // interaction range, as the Simulation bonds them (bond_range.h).
  const std::vector<std::array<int, 2>> pairs = BondCandidatePairs(packing, material.bond_range);
  const double kn = material.normal_stiffness_n_per_m, kt = material.tangential_stiffness_n_per_m;
  auto add_link = [&](int i, int j, const Vector<Dim>& normal, double normal_k,
                      double tangential_k) {
    link_i_.push_back(i);
    link_j_.push_back(j);
    link_normal_.push_back(normal);
    link_kn_.push_back(normal_k);
    link_kt_.push_back(tangential_k);
    link_root_kn_.push_back(std::sqrt(normal_k));
    link_root_kt_.push_back(std::sqrt(tangential_k));
  };
  std::vector<int> links_of(count, 0);
  for (const auto& [i, j] : pairs) {
    const Vector<Dim> branch = packing.centres[j] - packing.centres[i];
    const double distance = branch.norm();
    if (!(distance > 0.0))
      throw InputError("particles " + std::to_string(original_index_[i]) + " and " +
                       std::to_string(original_index_[j]) +
                       " of a packing contact have the same centre");
    add_link(i, j, branch / distance, kn, kt);
    ++links_of[i];
    ++links_of[j];
  }
  contact_links_ = link_count();
  tangential_ = kt > 0.0;
  // Moment-carrying bonds: every pair of the list counted as a bond (on the safe side, as
  // for the normal springs above).
  bending_ = material.bonds_carry_moments() && contact_links_ > 0;
  if (bending_) {
    link_kb_.resize(contact_links_);
    link_kw_.resize(contact_links_);
    for (int c = 0; c < contact_links_; ++c) {
      const BondSection<Dim> section = BondSectionOf<Dim>(
          radius_[link_i_[c]], radius_[link_j_[c]], material.bond_radius_ratio, kn, kt);
      link_kb_[c] = section.bending_stiffness;
      link_kw_[c] = section.twisting_stiffness;
    }
  }

  // 3. Walls: particles touching (gap <= tolerance x R) link to ground or to the wall's node.
  const double tolerance = scene.contacts.bond_gap_tolerance;
  std::vector<int> undamped_links;
  constexpr double kMassRadiusOverInertia = Dim == 2 ? 2.0 : 2.5;
  for (const WallOptions<Dim>& wall : scene.walls) {
    const Vector<Dim> normal = wall.normal.normalized();
    const bool friction = wall.friction();
    const double wall_kt = friction ? wall.tangential_stiffness_n_per_m : 0.0;
    tangential_ = tangential_ || wall_kt > 0.0;
    int node = -1;
    if (wall.drive == WallDrive::kForce) {
      node = static_cast<int>(wall_dof_.size());
      wall_dof_.push_back(-1);
      wall_normal_.push_back(normal);
      wall_node_links_.emplace_back();
    }
    if (wall.conforming()) {
      // A jaw's K w w^T is bounded by the spring K w_k on each of its particles along n_k
      // (walls.h); frictionless and velocity-driven: to ground.
      for (size_t j = 0; j < wall.jaw_particles.size(); ++j) {
        const int p = wall.jaw_particles[j];
        const double k = wall.JawStiffness() * wall.jaw_weights[j];
        undamped_links.push_back(link_count());  // a jaw has no dashpot
        add_link(p, -1, Vector<Dim>(-wall.jaw_inward[j]), k, 0.0);
        ++links_of[p];
        ++wall_links_;
        if (wall_stiffness_.empty()) wall_stiffness_.assign(count, 0.0);
        wall_stiffness_[original_index_[p]] += k;
      }
      continue;
    }
    for (int p = 0; p < count; ++p) {
      const double gap = (packing.centres[p] - wall.point).dot(normal) - radius_[p];
      if (wall_reach_m >= 0.0 ? gap >= wall_reach_m : gap > tolerance * radius_[p]) continue;
      if (node >= 0) wall_node_links_[node].push_back(link_count());
      // The contact normal points from the particle to the wall.
      add_link(p, node >= 0 ? -2 - node : -1, -normal, wall.normal_stiffness_n_per_m, wall_kt);
      ++links_of[p];
      ++wall_links_;
      if (wall_stiffness_.empty()) wall_stiffness_.assign(count, 0.0);
      wall_stiffness_[original_index_[p]] +=
          wall.normal_stiffness_n_per_m +
          wall.tangential_stiffness_n_per_m * (1.0 + kMassRadiusOverInertia);
    }
  }

  // 4. Rattlers: one link to the nearest neighbour within the neighbour-search skin.
  bool any_rattler = false;
  for (int p = 0; p < count; ++p) any_rattler = any_rattler || links_of[p] == 0;
  if (any_rattler && count > 1) {
    const double skin = scene.contacts.search_skin * VolumeMeanRadius<Dim>(radius_);
    CandidateSearch<Dim> search;
    std::vector<std::array<int, 2>> candidates;
    search.FindPairs(packing.centres, radius_, skin, &candidates);
    std::vector<int> nearest(count, -1);
    std::vector<double> nearest_gap(count, std::numeric_limits<double>::infinity());
    for (const auto& [i, j] : candidates) {
      const double gap = packing.Gap(i, j);
      for (const int p : {i, j}) {
        if (links_of[p] != 0 || gap >= nearest_gap[p]) continue;
        nearest_gap[p] = gap;
        nearest[p] = p == i ? j : i;
      }
    }
    for (int p = 0; p < count; ++p) {
      if (links_of[p] != 0) continue;
      if (nearest[p] < 0) {
        ++rattlers_alone_;
        continue;
      }
      const int i = std::min(p, nearest[p]), j = std::max(p, nearest[p]);
      const Vector<Dim> branch = packing.centres[j] - packing.centres[i];
      if (!(branch.norm() > 0.0)) continue;
      add_link(i, j, branch.normalized(), kn, kt);
      ++rattler_links_;
    }
  }
  rotation_ = tangential_ || bending_;

  // Dashpots, as the solver's contact and wall laws (tangential ones only with kt > 0).
  const int links = link_count();
  link_cn_.assign(links, 0.0);
  link_ct_.assign(links, 0.0);
  const double xi_n = material.normal_dashpot_ratio;
  const double xi_t = kt > 0.0 ? material.tangential_dashpot_ratio : 0.0;
  dashpots_ = xi_n > 0.0 || xi_t > 0.0;
  if (dashpots_) {
    for (int c = 0; c < links; ++c) {
      const int i = link_i_[c], j = link_j_[c];
      const double reduced_mass = j >= 0 ? mass_[i] * mass_[j] / (mass_[i] + mass_[j]) : mass_[i];
      link_cn_[c] = 2.0 * xi_n * std::sqrt(link_kn_[c] * reduced_mass);
      if (j >= 0) link_ct_[c] = 2.0 * xi_t * std::sqrt(link_kt_[c] * reduced_mass);
    }
    for (const int c : undamped_links) link_cn_[c] = 0.0;
  }

  // 5. Degrees of freedom, without the prescribed axes.
  std::vector<std::array<bool, kNodeDofs>> removed(count);
  for (auto& r : removed) r.fill(false);
  for (const FixedDofs<Dim>& fixed : scene.fixed_dofs) {
    for (const int p : fixed.particles) {
      for (int axis = 0; axis < Dim; ++axis)
        if (fixed.fix_translation[axis]) removed[p][axis] = true;
      if (fixed.fix_rotation)
        for (int axis = Dim; axis < kNodeDofs; ++axis) removed[p][axis] = true;
    }
  }
  dof_.resize(count);
  const double inverse_inertia_factor = Dim == 2 ? 2.0 : 2.5;  // 1/J = this / (m R^2)
  for (int p = 0; p < count; ++p) {
    dof_[p].fill(-1);
    const int used_axes = rotation_ ? kNodeDofs : Dim;
    for (int axis = 0; axis < used_axes; ++axis) {
      if (removed[p][axis]) {
        ++fixed_dofs_;
        continue;
      }
      dof_[p][axis] = dof_count_++;
      const double inertia =
          axis < Dim ? mass_[p] : mass_[p] * radius_[p] * radius_[p] / inverse_inertia_factor;
      dof_inverse_root_mass_.push_back(1.0 / std::sqrt(inertia));
      dof_owner_.push_back(p);
      dof_axis_.push_back(axis);
    }
  }
  int node = 0;
  for (const WallOptions<Dim>& wall : scene.walls) {
    if (wall.drive != WallDrive::kForce) continue;
    wall_dof_[node++] = dof_count_++;
    dof_inverse_root_mass_.push_back(1.0 / std::sqrt(wall.mass_kg));
    dof_owner_.push_back(-1);
    dof_axis_.push_back(-1);
  }
  BuildAdjacency();
}

template <int Dim>
void LinearisedNetwork<Dim>::BuildAdjacency() {
  const int count = particle_count();
  adjacency_offset_.assign(count + 1, 0);
  for (int c = 0; c < link_count(); ++c) {
    ++adjacency_offset_[link_i_[c] + 1];
    if (link_j_[c] >= 0) ++adjacency_offset_[link_j_[c] + 1];
  }
  for (int p = 0; p < count; ++p) adjacency_offset_[p + 1] += adjacency_offset_[p];
  adjacency_entry_.assign(adjacency_offset_[count], 0);
  std::vector<int> cursor(adjacency_offset_.begin(), adjacency_offset_.end() - 1);
  for (int c = 0; c < link_count(); ++c) {
    adjacency_entry_[cursor[link_i_[c]]++] = 2 * c;
    if (link_j_[c] >= 0) adjacency_entry_[cursor[link_j_[c]]++] = 2 * c + 1;
  }
}

template <int Dim>
std::vector<std::array<int, 2>> LinearisedNetwork<Dim>::ContactPairs() const {
  std::vector<std::array<int, 2>> pairs;
  pairs.reserve(contact_links_);
  for (int c = 0; c < contact_links_; ++c)
    pairs.push_back({original_index_[link_i_[c]], original_index_[link_j_[c]]});
  return pairs;
}

template <int Dim>
void LinearisedNetwork<Dim>::LinkKinematics(const std::vector<double>& x,
                                            std::vector<double>* normal,
                                            std::vector<Vector<Dim>>* tangential) const {
  const int links = link_count(), count = particle_count();
  normal->resize(links);
  if (tangential) tangential->resize(links);
  // 1. Particle motions u = M^-1/2 x (prescribed axes: 0), one pass over the particles.
  std::vector<Vector<Dim>>& motion = scratch_motion_;
  std::vector<Angular<Dim>>& spin = scratch_spin_;
  motion.resize(count);
  if (rotation_) spin.resize(count);
  const double* inverse_root = dof_inverse_root_mass_.data();
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    const auto& dof = dof_[p];
    for (int axis = 0; axis < Dim; ++axis) {
      const int d = dof[axis];
      motion[p][axis] = d >= 0 ? x[d] * inverse_root[d] : 0.0;
    }
    if (rotation_) {
      if constexpr (Dim == 2) {
        const int d = dof[2];
        spin[p] = d >= 0 ? x[d] * inverse_root[d] : 0.0;
      } else {
        for (int axis = 0; axis < 3; ++axis) {
          const int d = dof[3 + axis];
          spin[p][axis] = d >= 0 ? x[d] * inverse_root[d] : 0.0;
        }
      }
    }
  }
  // 2. d = (u_j + theta_j x s_j) - (u_i + theta_i x s_i), s_i = R_i n, s_j = -R_j n.
  const int* const link_i = link_i_.data();
  const int* const link_j = link_j_.data();
  const Vector<Dim>* const normals = link_normal_.data();
  const Vector<Dim>* const u = motion.data();
  const double* const radius = radius_.data();
  double* const elongation = normal->data();
  Vector<Dim>* const slip = tangential ? tangential->data() : nullptr;
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i[c], j = link_j[c];
    const Vector<Dim> n = normals[c];
    Vector<Dim> d = -u[i];
    if (j >= 0) {
      d += u[j];
    } else if (j <= -2) {
      const int w = -2 - j;
      const int wd = wall_dof_[w];
      if (wd >= 0) d += x[wd] * inverse_root[wd] * wall_normal_[w];
    }
    if (rotation_) {
      d -= RotationCross(spin[i], Vector<Dim>(radius[i] * n));
      if (j >= 0) d += RotationCross(spin[j], Vector<Dim>(-radius[j] * n));
    }
    const double g = n.dot(d);
    elongation[c] = g;
    if (slip) slip[c] = d - g * n;
  }
}

template <int Dim>
void LinearisedNetwork<Dim>::GatherLinkForces(const std::vector<double>& normal,
                                              const std::vector<Vector<Dim>>& tangential,
                                              std::vector<double>& y) const {
  const int count = particle_count();
  y.assign(dof_count_, 0.0);
  // F = f_n n + f_t on i, formed where it is used (each link twice).
  const bool has_tangential = !tangential.empty();
  const Vector<Dim>* const normals = link_normal_.data();
  const double* const normal_force = normal.data();
  const Vector<Dim>* const tangential_force = has_tangential ? tangential.data() : nullptr;
  const bool rotation = rotation_;
  // 2. y = K u = minus the internal forces: -F on i, +F on j; the moment -R n x F on both.
  const double* const inverse_root = dof_inverse_root_mass_.data();
  const int* const offset = adjacency_offset_.data();
  const int* const entry = adjacency_entry_.data();
  double* const out = y.data();
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    Vector<Dim> translation = Vector<Dim>::Zero();
    Angular<Dim> moment = ZeroAngular<Dim>();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      Vector<Dim> f = normal_force[c] * normals[c];
      if (tangential_force) f += tangential_force[c];
      if (entry[e] & 1)
        translation += f;
      else
        translation -= f;
      if (rotation) moment -= Cross(normals[c], f);
    }
    const auto& dof = dof_[p];
    for (int axis = 0; axis < Dim; ++axis) {
      const int d = dof[axis];
      if (d >= 0) out[d] = translation[axis] * inverse_root[d];
    }
    if (rotation) {
      moment *= radius_[p];
      if constexpr (Dim == 2) {
        const int d = dof[2];
        if (d >= 0) out[d] = moment * inverse_root[d];
      } else {
        for (int axis = 0; axis < 3; ++axis) {
          const int d = dof[3 + axis];
          if (d >= 0) out[d] = moment[axis] * inverse_root[d];
        }
      }
    }
  }
  for (size_t w = 0; w < wall_dof_.size(); ++w) {
    const int d = wall_dof_[w];
    if (d < 0) continue;
    double sum = 0.0;  // internal force on the wall is -F: y = n_w . F
    for (const int c : wall_node_links_[w]) {
      Vector<Dim> f = normal_force[c] * normals[c];
      if (tangential_force) f += tangential_force[c];
      sum += wall_normal_[w].dot(f);
    }
    out[d] = sum * inverse_root[d];
  }
}

template <int Dim>
void LinearisedNetwork<Dim>::ApplyScaledStiffness(const std::vector<double>& x,
                                                  std::vector<double>& y) const {
  std::vector<double>& normal = scratch_normal_;
  std::vector<Vector<Dim>>& tangential = scratch_tangential_;
  LinkKinematics(x, &normal, tangential_ ? &tangential : nullptr);
  const int links = link_count();
  for (int c = 0; c < links; ++c) normal[c] *= link_kn_[c];
  if (tangential_)
    for (int c = 0; c < links; ++c) tangential[c] *= link_kt_[c];
  else
    tangential.clear();
  GatherLinkForces(normal, tangential, y);
  if (bending_) AddBendingStiffness(x, y);
}

template <int Dim>
void LinearisedNetwork<Dim>::AddBendingStiffness(const std::vector<double>& x,
                                                 std::vector<double>& y) const {
  if (!bending_) return;
  const int count = particle_count();
  // Rotations theta = J^-1/2 x (prescribed axes: 0).
  std::vector<Angular<Dim>>& spin = scratch_spin_;
  spin.resize(count);
  const double* inverse_root = dof_inverse_root_mass_.data();
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    if constexpr (Dim == 2) {
      const int d = dof_[p][2];
      spin[p] = d >= 0 ? x[d] * inverse_root[d] : 0.0;
    } else {
      for (int axis = 0; axis < 3; ++axis) {
        const int d = dof_[p][3 + axis];
        spin[p][axis] = d >= 0 ? x[d] * inverse_root[d] : 0.0;
      }
    }
  }
  // The bond's moment on i is M = K_b (theta_j - theta_i); K theta gets -M at i, +M at j.
  const int* const offset = adjacency_offset_.data();
  const int* const entry = adjacency_entry_.data();
  double* const out = y.data();
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    Angular<Dim> sum = ZeroAngular<Dim>();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      if (c >= contact_links_) continue;
      const Angular<Dim> relative = spin[link_j_[c]] - spin[link_i_[c]];
      Angular<Dim> moment;
      if constexpr (Dim == 2) {
        moment = link_kb_[c] * relative;
      } else {
        const Vector<3>& n = link_normal_[c];
        const double twist = relative.dot(n);
        moment = link_kb_[c] * (relative - twist * n) + (link_kw_[c] * twist) * n;
      }
      if (entry[e] & 1)
        sum += moment;
      else
        sum -= moment;
    }
    if constexpr (Dim == 2) {
      const int d = dof_[p][2];
      if (d >= 0) out[d] += sum * inverse_root[d];
    } else {
      for (int axis = 0; axis < 3; ++axis) {
        const int d = dof_[p][3 + axis];
        if (d >= 0) out[d] += sum[axis] * inverse_root[d];
      }
    }
  }
}

template <int Dim>
double LinearisedNetwork<Dim>::GershgorinBound() const {
  using Matrix = Eigen::Matrix<double, Dim, Eigen::Dynamic>;
  std::vector<double> row_sum(dof_count_, 0.0);
  std::vector<int> local;
  for (int c = 0; c < link_count(); ++c) {
    const int i = link_i_[c], j = link_j_[c];
    const Vector<Dim>& n = link_normal_[c];
    // d = L q over the link's local dofs q.
    local.clear();
    std::vector<Vector<Dim>> columns;
    auto add_particle = [&](int p, double sign, const Vector<Dim>& arm) {
      for (int axis = 0; axis < Dim; ++axis) {
        if (dof_[p][axis] < 0) continue;
        local.push_back(dof_[p][axis]);
        columns.push_back(sign * Vector<Dim>::Unit(axis));
      }
      if (!rotation_) return;
      for (int r = 0; r < kRotations; ++r) {
        if (dof_[p][Dim + r] < 0) continue;
        local.push_back(dof_[p][Dim + r]);
        Angular<Dim> unit = ZeroAngular<Dim>();
        if constexpr (Dim == 2) {
          unit = 1.0;
        } else {
          unit[r] = 1.0;
        }
        columns.push_back(sign * RotationCross(unit, arm));
      }
    };
    add_particle(i, -1.0, Vector<Dim>(radius_[i] * n));
    if (j >= 0) {
      add_particle(j, 1.0, Vector<Dim>(-radius_[j] * n));
    } else if (j <= -2 && wall_dof_[-2 - j] >= 0) {
      local.push_back(wall_dof_[-2 - j]);
      columns.push_back(wall_normal_[-2 - j]);
    }
    const int size = static_cast<int>(local.size());
    if (size == 0) continue;
    Matrix l(Dim, size);
    for (int k = 0; k < size; ++k) l.col(k) = columns[k] * dof_inverse_root_mass_[local[k]];
    const Eigen::Matrix<double, Dim, Dim> spring =
        link_kn_[c] * n * n.transpose() +
        link_kt_[c] * (Eigen::Matrix<double, Dim, Dim>::Identity() - n * n.transpose());
    const Eigen::MatrixXd a = l.transpose() * spring * l;
    for (int k = 0; k < size; ++k) row_sum[local[k]] += a.row(k).cwiseAbs().sum();
    if (bending_ && c < contact_links_) {
      // The bond's rotational spring on (theta_i, theta_j): [K_b, -K_b; -K_b, K_b], scaled.
      Eigen::Matrix<double, LinearisedNetwork<Dim>::kRotations,
                    LinearisedNetwork<Dim>::kRotations>
          rotational;
      if constexpr (Dim == 2) {
        rotational(0, 0) = link_kb_[c];
      } else {
        rotational = link_kb_[c] * (Eigen::Matrix3d::Identity() - n * n.transpose()) +
                     link_kw_[c] * n * n.transpose();
      }
      for (const int p : {i, j}) {
        for (int r = 0; r < kRotations; ++r) {
          const int d = dof_[p][Dim + r];
          if (d < 0) continue;
          double sum = 0.0;
          for (const int q : {i, j}) {
            const double sign = q == p ? 1.0 : -1.0;
            for (int s2 = 0; s2 < kRotations; ++s2) {
              const int e = dof_[q][Dim + s2];
              if (e < 0) continue;
              sum += std::abs(sign * rotational(r, s2) * dof_inverse_root_mass_[d] *
                              dof_inverse_root_mass_[e]);
            }
          }
          row_sum[d] += sum;
        }
      }
    }
  }
  double bound = 0.0;
  for (const double s : row_sum) bound = std::max(bound, s);
  return bound;
}

template <int Dim>
void LinearisedNetwork<Dim>::StrainOfLinkForces(const ParticleCompliance<Dim>& unit_compliance,
                                                const std::vector<double>& normal,
                                                const std::vector<Vector<Dim>>& tangential,
                                                std::vector<SymmetricTensor<Dim>>* strain) const {
  const int count = particle_count();
  strain->resize(count);
  const bool has_tangential = !tangential.empty();
  const Vector<Dim>* const normals = link_normal_.data();
  const double* const normal_force = normal.data();
  const Vector<Dim>* const tangential_force = has_tangential ? tangential.data() : nullptr;
  const int* const offset = adjacency_offset_.data();
  const int* const entry = adjacency_entry_.data();
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    // Madan (2.41), (2.44): sigma = sym(sum s (x) F) / V with s (x) F = R n (x) (f_n n + f_t) at
    // both ends of a link.
    SymmetricTensor<Dim> sum = SymmetricTensor<Dim>::Zero();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      const Vector<Dim>& n = normals[c];
      Vector<Dim> f = normal_force[c] * n;
      if (tangential_force) f += tangential_force[c];
      sum += SymmetricOuter(n, f);
    }
    (*strain)[p] = unit_compliance.Strain(sum * (radius_[p] / volume_[p]));
  }
}

template <int Dim>
void LinearisedNetwork<Dim>::NormalDisplacementOfStrain(
    const std::vector<SymmetricTensor<Dim>>& strain, std::vector<double>* normal) const {
  const int links = link_count();
  normal->resize(links);
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i_[c], j = link_j_[c];
    const Vector<Dim>& n = link_normal_[c];
    double sum = radius_[i] * QuadraticForm(strain[i], n);  // Madan (2.53)
    if (j >= 0) sum += radius_[j] * QuadraticForm(strain[j], n);
    (*normal)[c] = sum;
  }
}

template <int Dim>
void LinearisedNetwork<Dim>::TangentialDisplacementOfStrain(
    const std::vector<SymmetricTensor<Dim>>& strain, std::vector<Vector<Dim>>* tangential) const {
  const int links = link_count();
  tangential->resize(links);
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i_[c], j = link_j_[c];
    const Vector<Dim>& n = link_normal_[c];
    Vector<Dim> sum = radius_[i] * (FullMatrix(strain[i]) * n);
    if (j >= 0) sum += radius_[j] * (FullMatrix(strain[j]) * n);
    (*tangential)[c] = sum - sum.dot(n) * n;
  }
}

template <int Dim>
template <typename LinkForce>
std::vector<double> LinearisedNetwork<Dim>::WallMotions(const LinkForce& force) const {
  std::vector<double> motion(wall_dof_.size(), 0.0);
  for (size_t w = 0; w < wall_dof_.size(); ++w) {
    const int d = wall_dof_[w];
    if (d < 0) continue;
    double sum = 0.0;
    for (const int c : wall_node_links_[w]) sum += wall_normal_[w].dot(force(c));
    motion[w] = sum * dof_inverse_root_mass_[d] * dof_inverse_root_mass_[d];
  }
  return motion;
}

template <int Dim>
void LinearisedNetwork<Dim>::ApplyPencilOperator(const ParticleCompliance<Dim>& compliance,
                                                 double shift, const std::vector<double>& x,
                                                 std::vector<double>& y) const {
  if (rotation_) throw InputError("ApplyPencilOperator: the network has rotations (kt > 0)");
  const int links = link_count(), count = particle_count();
  const Vector<Dim>* const normals = link_normal_.data();
  const double* const root_kn = link_root_kn_.data();
  const double* const inverse_root = dof_inverse_root_mass_.data();
  const int* const offset = adjacency_offset_.data();
  const int* const entry = adjacency_entry_.data();
  std::vector<Vector<Dim>>& motion = scratch_motion_;
  std::vector<SymmetricTensor<Dim>>& strain = scratch_strain_;
  motion.resize(count);
  strain.resize(count);
  // 1. Per particle, from the link forces f = K_n^1/2 x: its motion M^-1 (C^T f) (GatherLinkForces
  //    then the M^-1/2 of LinkKinematics) and its strain (StrainOfLinkForces).
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    Vector<Dim> translation = Vector<Dim>::Zero();
    SymmetricTensor<Dim> stress = SymmetricTensor<Dim>::Zero();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      const Vector<Dim> f = root_kn[c] * x[c] * normals[c];
      if (entry[e] & 1)
        translation += f;
      else
        translation -= f;
      stress += SymmetricOuter(normals[c], f);
    }
    for (int axis = 0; axis < Dim; ++axis) {
      const int d = dof_[p][axis];
      motion[p][axis] = d >= 0 ? translation[axis] * inverse_root[d] * inverse_root[d] : 0.0;
    }
    strain[p] = compliance.Strain(stress * (radius_[p] / volume_[p]));
  }
  const std::vector<double> wall_motion =
      WallMotions([&](int c) { return Vector<Dim>(root_kn[c] * x[c] * normals[c]); });
  // 2. Per link: K_n^1/2 (n . d + shift x the strain correction), d = u_j - u_i.
  y.resize(links);
  const int* const link_i = link_i_.data();
  const int* const link_j = link_j_.data();
  const Vector<Dim>* const u = motion.data();
  const double* const radius = radius_.data();
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i[c], j = link_j[c];
    const Vector<Dim>& n = normals[c];
    Vector<Dim> d = -u[i];
    double correction = radius[i] * QuadraticForm(strain[i], n);
    if (j >= 0) {
      d += u[j];
      correction += radius[j] * QuadraticForm(strain[j], n);
    } else if (j <= -2) {
      d += wall_motion[-2 - j] * wall_normal_[-2 - j];
    }
    y[c] = root_kn[c] * (n.dot(d) + shift * correction);
  }
}

template <int Dim>
void LinearisedNetwork<Dim>::ApplyTangentialPencilOperator(
    const ParticleCompliance<Dim>& compliance, double shift, const std::vector<double>& v,
    std::vector<double>& y) const {
  const int links = link_count(), count = particle_count();
  if (static_cast<int>(v.size()) != links * (1 + Dim))
    throw InputError("ApplyTangentialPencilOperator: the vector has " + std::to_string(v.size()) +
                     " entries, the network " + std::to_string(links) + " x (1 + Dim) links");
  // Six passes, alternating particles and links (each needs the previous one complete):
  // A~^T v in passes 1-3 (ending as the motions M^-1/2 A~^T v), A~ of it in passes 4-6.
  const Vector<Dim>* const normals = link_normal_.data();
  const double* const root_kn = link_root_kn_.data();
  const double* const kt = link_kt_.data();
  const double* const root_kt = link_root_kt_.data();
  const double* const radius = radius_.data();
  const double* const volume = volume_.data();
  const double* const inverse_root = dof_inverse_root_mass_.data();
  const int* const offset = adjacency_offset_.data();
  const int* const entry = adjacency_entry_.data();
  const int* const link_i = link_i_.data();
  const int* const link_j = link_j_.data();
  std::vector<SymmetricTensor<Dim>>& strain_n = scratch_strain2_;
  std::vector<SymmetricTensor<Dim>>& strain_t = scratch_strain_;
  std::vector<Vector<Dim>>& force_t = pencil_tangential_;
  std::vector<double>& shift_term = pencil_correction_;
  std::vector<double>& elongation = pencil_normal_;
  std::vector<Vector<Dim>>& motion = scratch_motion_;
  std::vector<Angular<Dim>>& spin = scratch_spin_;
  strain_n.resize(count);
  strain_t.resize(count);
  motion.resize(count);
  spin.resize(count);
  force_t.resize(links);
  shift_term.resize(links);
  elongation.resize(links);
  y.resize(v.size());
  const double* const vn = v.data();
  const double* const vt = v.data() + links;

  // 1. Particles: the strain of the normal forces f_n = K_n^1/2 v_n.
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    SymmetricTensor<Dim> sum = SymmetricTensor<Dim>::Zero();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      sum += (root_kn[c] * vn[c]) * SymmetricOuter(normals[c], normals[c]);
    }
    strain_n[p] = compliance.Strain(sum * (radius[p] / volume[p]));
  }
  // 2. Links: its normal displacement N eps (for the shift: S v_n = K_n^1/2 N eps) and its
  //    tangential displacement T eps, giving f_t = K_t^1/2 v_t + K_t T eps / 2
  //    (K_t^1/2 (v_t + G^T v_n / 2)); v_t's normal component is dropped. Stored: f_n n + f_t.
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i[c], j = link_j[c];
    const Vector<Dim> n = normals[c];
    Vector<Dim> m = radius[i] * (FullMatrix(strain_n[i]) * n);
    if (j >= 0) m += radius[j] * (FullMatrix(strain_n[j]) * n);
    const double normal_part = m.dot(n);
    shift_term[c] = root_kn[c] * normal_part;
    Vector<Dim> slip = Eigen::Map<const Vector<Dim>>(vt + Dim * c);
    slip -= slip.dot(n) * n;
    // The whole link force f_n n + f_t, as pass 3 sums it.
    force_t[c] = (root_kn[c] * vn[c]) * n + root_kt[c] * slip + (0.5 * kt[c]) * (m - normal_part * n);
  }
  // 3. Particles: the motions M^-1 C^T f (GatherLinkForces, then the M^-1/2 of
  //    LinkKinematics); prescribed axes do not move.
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    Vector<Dim> translation = Vector<Dim>::Zero();
    Angular<Dim> moment = ZeroAngular<Dim>();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      const Vector<Dim>& f = force_t[c];
      if (entry[e] & 1)
        translation += f;
      else
        translation -= f;
      moment -= Cross(normals[c], f);
    }
    const auto& dof = dof_[p];
    for (int axis = 0; axis < Dim; ++axis) {
      const int d = dof[axis];
      motion[p][axis] = d >= 0 ? translation[axis] * inverse_root[d] * inverse_root[d] : 0.0;
    }
    moment *= radius[p];
    if constexpr (Dim == 2) {
      const int d = dof[2];
      spin[p] = d >= 0 && rotation_ ? moment * inverse_root[d] * inverse_root[d] : 0.0;
    } else {
      for (int axis = 0; axis < 3; ++axis) {
        const int d = dof[3 + axis];
        spin[p][axis] =
            d >= 0 && rotation_ ? moment[axis] * inverse_root[d] * inverse_root[d] : 0.0;
      }
    }
  }
  const std::vector<double> wall_motion = WallMotions([&](int c) { return force_t[c]; });
  // 4. Links: the relative displacement d of the contact points; a_t = K_t^1/2 d_t is the
  //    tangential block of y, K_t d_t the tangential force whose strain pass 5 needs.
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i[c], j = link_j[c];
    const Vector<Dim> n = normals[c];
    Vector<Dim> d = -motion[i] - RotationCross(spin[i], Vector<Dim>(radius[i] * n));
    if (j >= 0)
      d += motion[j] + RotationCross(spin[j], Vector<Dim>(-radius[j] * n));
    else if (j <= -2)
      d += wall_motion[-2 - j] * wall_normal_[-2 - j];
    const double g = n.dot(d);
    const Vector<Dim> slip = d - g * n;
    elongation[c] = g;
    force_t[c] = kt[c] * slip;
    Eigen::Map<Vector<Dim>>(y.data() + links + Dim * c) = root_kt[c] * slip;
  }
  // 5. Particles: the strain of the tangential forces K_t d_t.
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    SymmetricTensor<Dim> sum = SymmetricTensor<Dim>::Zero();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      sum += SymmetricOuter(normals[c], force_t[c]);
    }
    strain_t[p] = compliance.Strain(sum * (radius[p] / volume[p]));
  }
  // 6. Links: a_n = K_n^1/2 (g + N eps_t / 2), plus shift S v_n.
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i[c], j = link_j[c];
    const Vector<Dim> n = normals[c];
    double correction = radius[i] * QuadraticForm(strain_t[i], n);
    if (j >= 0) correction += radius[j] * QuadraticForm(strain_t[j], n);
    y[c] = root_kn[c] * (elongation[c] + 0.5 * correction) + shift * shift_term[c];
  }
}

template <int Dim>
void LinearisedNetwork<Dim>::ApplyTangentialPencilShift(const ParticleCompliance<Dim>& compliance,
                                                        const std::vector<double>& v,
                                                        std::vector<double>& y) const {
  const int links = link_count();
  std::vector<double> normal(v.begin(), v.begin() + links), image;
  ApplyDdemOperator(compliance, normal, image);
  y.assign(v.size(), 0.0);
  std::copy(image.begin(), image.end(), y.begin());
}

template <int Dim>
void LinearisedNetwork<Dim>::ApplyDdemOperator(const ParticleCompliance<Dim>& unit_compliance,
                                               const std::vector<double>& x,
                                               std::vector<double>& y) const {
  const int links = link_count();
  std::vector<double>& force = scratch_force_;
  force.resize(links);
  for (int c = 0; c < links; ++c) force[c] = link_root_kn_[c] * x[c];
  StrainOfLinkForces(unit_compliance, force, {}, &scratch_strain_);
  NormalDisplacementOfStrain(scratch_strain_, &y);
  for (int c = 0; c < links; ++c) y[c] *= link_root_kn_[c];
}

template <int Dim>
void LinearisedNetwork<Dim>::ApplyDdemOperatorPair(const ParticleCompliance<Dim>& unit_compliance,
                                                   const std::vector<double>& x1,
                                                   const std::vector<double>& x2,
                                                   std::vector<double>& y1,
                                                   std::vector<double>& y2) const {
  const int links = link_count(), count = particle_count();
  std::vector<SymmetricTensor<Dim>>& strain1 = scratch_strain_;
  std::vector<SymmetricTensor<Dim>>& strain2 = scratch_strain2_;
  strain1.resize(count);
  strain2.resize(count);
  const Vector<Dim>* const normals = link_normal_.data();
  const double* const root_kn = link_root_kn_.data();
  const int* const offset = adjacency_offset_.data();
  const int* const entry = adjacency_entry_.data();
  // As StrainOfLinkForces with f = sqrt(kn) x, normal forces only, for both vectors.
#pragma omp parallel for if (count >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int p = 0; p < count; ++p) {
    SymmetricTensor<Dim> sum1 = SymmetricTensor<Dim>::Zero(), sum2 = SymmetricTensor<Dim>::Zero();
    for (int e = offset[p]; e < offset[p + 1]; ++e) {
      const int c = entry[e] >> 1;
      const SymmetricTensor<Dim> nn = SymmetricOuter(normals[c], normals[c]);
      sum1 += (root_kn[c] * x1[c]) * nn;
      sum2 += (root_kn[c] * x2[c]) * nn;
    }
    const double scale = radius_[p] / volume_[p];
    strain1[p] = unit_compliance.Strain(sum1 * scale);
    strain2[p] = unit_compliance.Strain(sum2 * scale);
  }
  y1.resize(links);
  y2.resize(links);
#pragma omp parallel for if (links >= kParallelItems) num_threads(num_threads_) schedule(static)
  for (int c = 0; c < links; ++c) {
    const int i = link_i_[c], j = link_j_[c];
    const Vector<Dim>& n = normals[c];
    double sum1 = radius_[i] * QuadraticForm(strain1[i], n);
    double sum2 = radius_[i] * QuadraticForm(strain2[i], n);
    if (j >= 0) {
      sum1 += radius_[j] * QuadraticForm(strain1[j], n);
      sum2 += radius_[j] * QuadraticForm(strain2[j], n);
    }
    y1[c] = root_kn[c] * sum1;
    y2[c] = root_kn[c] * sum2;
  }
}

template class LinearisedNetwork<2>;
template class LinearisedNetwork<3>;

}  // namespace specimen
