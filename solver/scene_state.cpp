#include "solver/scene_state.h"

#include <type_traits>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

namespace specimen {

namespace {

// Skilling's transform (AIP Conf. Proc. 707, 381 (2004)) of `bits`-bit coordinates to the
// transposed Hilbert index, then the index itself by interleaving the bits.
template <int Dim>
std::uint64_t HilbertIndex(std::array<std::uint32_t, Dim> x, int bits) {
  const std::uint32_t top = 1u << (bits - 1);
  for (std::uint32_t q = top; q > 1; q >>= 1) {
    const std::uint32_t p = q - 1;
    for (int i = 0; i < Dim; ++i) {
      if (x[i] & q) {
        x[0] ^= p;
      } else {
        const std::uint32_t t = (x[0] ^ x[i]) & p;
        x[0] ^= t;
        x[i] ^= t;
      }
    }
  }
  for (int i = 1; i < Dim; ++i) x[i] ^= x[i - 1];
  std::uint32_t t = 0;
  for (std::uint32_t q = top; q > 1; q >>= 1)
    if (x[Dim - 1] & q) t ^= q - 1;
  for (int i = 0; i < Dim; ++i) x[i] ^= t;
  std::uint64_t index = 0;
  for (int b = bits - 1; b >= 0; --b)
    for (int i = 0; i < Dim; ++i) index = (index << 1) | ((x[i] >> b) & 1u);
  return index;
}

// out[new_of_old[k]] = v[k].
template <class T>
void Permute(std::vector<T>& v, const std::vector<int>& new_of_old, std::vector<T>& buffer) {
  if (v.empty()) return;
  buffer.resize(v.size());
  for (size_t k = 0; k < v.size(); ++k) buffer[new_of_old[k]] = std::move(v[k]);
  std::swap(v, buffer);
}

template <class T>
void Permute(std::vector<T>& v, const std::vector<int>& new_of_old) {
  std::vector<T> buffer;
  Permute(v, new_of_old, buffer);
}

}  // namespace

template <int Dim>
ParticleOrder SpatialOrder(const std::vector<Vector<Dim>>& centres, int threshold) {
  ParticleOrder order;
  const int count = static_cast<int>(centres.size());
  if (count < std::max(2, threshold)) return order;
  Vector<Dim> lower = centres[0], upper = centres[0];
  for (const Vector<Dim>& x : centres) {
    lower = lower.cwiseMin(x);
    upper = upper.cwiseMax(x);
  }
  // One scale for every axis (the curve keeps its shape), 2^bits cells along the longest.
  constexpr int kBits = Dim == 2 ? 31 : 21;
  const double extent = (upper - lower).maxCoeff();
  const double scale = extent > 0.0 ? (std::ldexp(1.0, kBits) - 1.0) / extent : 0.0;
  std::vector<std::pair<std::uint64_t, int>> keyed(count);
  for (int q = 0; q < count; ++q) {
    std::array<std::uint32_t, Dim> cell;
    for (int axis = 0; axis < Dim; ++axis)
      cell[axis] = static_cast<std::uint32_t>((centres[q][axis] - lower[axis]) * scale);
    keyed[q] = {HilbertIndex<Dim>(cell, kBits), q};
  }
  std::sort(keyed.begin(), keyed.end());
  bool identity = true;
  for (int k = 0; k < count && identity; ++k) identity = keyed[k].second == k;
  if (identity) return order;
  order.external_of_internal.resize(count);
  order.internal_of_external.resize(count);
  for (int k = 0; k < count; ++k) {
    order.external_of_internal[k] = keyed[k].second;
    order.internal_of_external[keyed[k].second] = k;
  }
  return order;
}

template <int Dim>
void RenumberParticles(SceneState<Dim>& s, const std::vector<int>& new_of_old,
                       std::vector<int>* old_contact_of_new) {
  auto relabel = [&](int& q) { q = new_of_old[q]; };

  // Particles and their accumulators.
  ParticleArrays<Dim>& p = s.particles;
  {
    std::vector<double> buffer;
    Permute(p.rotation_angle, new_of_old, buffer);
    Permute(p.radius, new_of_old, buffer);
    Permute(p.mass, new_of_old, buffer);
    Permute(p.inverse_mass, new_of_old, buffer);
    Permute(p.inverse_inertia, new_of_old, buffer);
  }
  {
    std::vector<Vector<Dim>> buffer;
    Permute(p.position, new_of_old, buffer);
    Permute(p.velocity, new_of_old, buffer);
    Permute(s.external_force, new_of_old, buffer);
  }
  Permute(p.angular_velocity, new_of_old);
  Permute(p.strain, new_of_old);
  s.deformation_step = -1;  // rebuilt from the strains by the next contact pass
  Permute(s.external_torque, new_of_old);
  Permute(s.external_moment, new_of_old);
  s.external_flag.clear();
  s.external_flag_search = -1;

  // Contacts: new pairs, i < j, sorted.
  ContactArrays<Dim>& c = s.contacts;
  const int contacts = c.size();
  std::vector<std::pair<std::array<int, 2>, int>> keyed(contacts);
  for (int k = 0; k < contacts; ++k) {
    const int i = new_of_old[c.pair[k][0]], j = new_of_old[c.pair[k][1]];
    keyed[k] = {i < j ? std::array<int, 2>{i, j} : std::array<int, 2>{j, i}, k};
  }
  std::sort(keyed.begin(), keyed.end());
  ContactArrays<Dim>& sorted = s.contacts_scratch;
  sorted.Clear();
  sorted.tangential_enabled = c.tangential_enabled;
  sorted.moments_enabled = c.moments_enabled;
  sorted.Reserve(contacts);
  if (old_contact_of_new) old_contact_of_new->resize(contacts);
  for (int k = 0; k < contacts; ++k) {
    const int old = keyed[k].second;
    sorted.AppendCopy(c, old);
    sorted.pair.back() = keyed[k].first;
    if (new_of_old[c.pair[old][0]] > new_of_old[c.pair[old][1]]) {
      // i and j swap: the normal i -> j and the forces on i change sign.
      sorted.normal.back() = -sorted.normal.back();
      sorted.force.back() = -sorted.force.back();
      if (sorted.tangential_enabled)
        sorted.tangential_force.back() = -sorted.tangential_force.back();
      if (sorted.moments_enabled) sorted.bond_moment.back() = -sorted.bond_moment.back();
    }
    if (old_contact_of_new) (*old_contact_of_new)[k] = old;
  }
  std::swap(s.contacts, s.contacts_scratch);
  s.contacts_scratch.Clear();
  RebuildAdjacency(s);

  // Candidate pairs of the last search (rebuilt by the next one; kept consistent).
  for (auto& pair : s.candidate_pairs) {
    relabel(pair[0]);
    relabel(pair[1]);
    if (pair[0] > pair[1]) std::swap(pair[0], pair[1]);
  }
  std::sort(s.candidate_pairs.begin(), s.candidate_pairs.end());

  // Wall candidates, sorted by particle with their forces (and a jaw's per-particle data).
  for (WallState<Dim>& w : s.walls) {
    const size_t count = w.particle.size();
    std::vector<std::pair<int, size_t>> by_particle(count);
    for (size_t k = 0; k < count; ++k) by_particle[k] = {new_of_old[w.particle[k]], k};
    std::sort(by_particle.begin(), by_particle.end());
    auto permuted = [&](const auto& values) {
      std::decay_t<decltype(values)> out(values.empty() ? 0 : count);
      for (size_t k = 0; k < out.size(); ++k) out[k] = values[by_particle[k].second];
      return out;
    };
    std::vector<int> particle(count);
    for (size_t k = 0; k < count; ++k) particle[k] = by_particle[k].first;
    w.particle = std::move(particle);
    w.normal_elastic_force = permuted(w.normal_elastic_force);
    w.tangential_force = permuted(w.tangential_force);
    w.jaw_inward = permuted(w.jaw_inward);
    w.jaw_weight = permuted(w.jaw_weight);
    w.jaw_reference_centre = permuted(w.jaw_reference_centre);
  }

  // Loads (per-particle bookkeeping stays with its entry) and prescribed dofs.
  for (PointLoadState<Dim>& load : s.loads)
    for (int& q : load.load.particles) relabel(q);
  ConstraintTable<Dim>& t = s.constraints;
  Permute(t.slot_of_particle, new_of_old);
  for (int& q : t.particle) relabel(q);
  for (FixedDofs<Dim>& set : t.sets)
    for (int& q : set.particles) relabel(q);
}

template <int Dim>
void ApplySpatialOrder(SceneState<Dim>& s) {
  ParticleOrder order = SpatialOrder<Dim>(s.particles.position);
  if (order.identity()) return;
  RenumberParticles(s, order.internal_of_external, nullptr);
  s.order = std::move(order);
}

template <int Dim>
void ExternalView<Dim>::Refresh(const SceneState<Dim>& s) const {
  if (!view_) view_ = std::make_unique<SceneState<Dim>>();
  SceneState<Dim>& v = *view_;
  v = s;
  RenumberParticles(v, s.order.external_of_internal, &internal_contact_);
  v.order = ParticleOrder();
  step_ = s.step;
  changes_seen_ = changes_;
}

template <int Dim>
const SceneState<Dim>& ExternalView<Dim>::Get(const SceneState<Dim>& s) const {
  if (s.order.identity()) return s;
  if (!view_ || step_ != s.step || changes_seen_ != changes_) Refresh(s);
  return *view_;
}

template <int Dim>
int ExternalView<Dim>::InternalContact(const SceneState<Dim>& s, int c) const {
  if (s.order.identity() || c < 0) return c;
  Get(s);
  return c < static_cast<int>(internal_contact_.size()) ? internal_contact_[c] : c;
}

template <int Dim>
void RefreshContactDeformation(SceneState<Dim>& s) {
  const ParticleArrays<Dim>& p = s.particles;
  s.deformation.resize(p.strain.size());
  for (size_t q = 0; q < p.strain.size(); ++q) s.deformation[q].Set(p.strain[q], p.radius[q]);
  s.deformation_step = s.step;
}

template <int Dim>
void RebuildAdjacency(SceneState<Dim>& s) {
  const int count = s.particles.size();
  const int contacts = s.contacts.size();
  ContactAdjacency& a = s.adjacency;
  a.offset.assign(static_cast<size_t>(count) + 1, 0);
  for (int c = 0; c < contacts; ++c) {
    ++a.offset[s.contacts.pair[c][0] + 1];
    ++a.offset[s.contacts.pair[c][1] + 1];
  }
  for (int q = 0; q < count; ++q) a.offset[q + 1] += a.offset[q];
  a.entry.assign(2 * static_cast<size_t>(contacts) + kAdjacencyPadding, 0);
  // Fill in contact order, so each particle's entries are sorted by contact.
  std::vector<int>& cursor = s.adjacency_cursor;
  cursor.assign(a.offset.begin(), a.offset.end() - 1);
  for (int c = 0; c < contacts; ++c) {
    a.entry[cursor[s.contacts.pair[c][0]]++] = 2 * c;
    a.entry[cursor[s.contacts.pair[c][1]]++] = 2 * c + 1;
  }
}

namespace {
template <class T>
std::size_t Bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}
}  // namespace

template <int Dim>
std::size_t MemoryBytes(const SceneState<Dim>& s) {
  const ParticleArrays<Dim>& p = s.particles;
  std::size_t bytes = sizeof(s);
  bytes += Bytes(p.position) + Bytes(p.velocity) + Bytes(p.angular_velocity) +
           Bytes(p.rotation_angle) + Bytes(p.radius) + Bytes(p.mass) + Bytes(p.inverse_mass) +
           Bytes(p.inverse_inertia) + Bytes(p.strain) + Bytes(s.deformation);
  for (const ContactArrays<Dim>* c : {&s.contacts, &s.contacts_scratch})
    bytes += Bytes(c->pair) + Bytes(c->state) + Bytes(c->reference_gap) + Bytes(c->normal) +
             Bytes(c->force) + Bytes(c->normal_elastic_force) + Bytes(c->tangential_force) +
             Bytes(c->bond_moment);
  bytes += Bytes(s.adjacency.offset) + Bytes(s.adjacency.entry) + Bytes(s.adjacency_cursor);
  bytes += Bytes(s.order.internal_of_external) + Bytes(s.order.external_of_internal);
  bytes += Bytes(s.external_force) + Bytes(s.external_torque) + Bytes(s.external_moment) +
           Bytes(s.external_flag);
  bytes += Bytes(s.candidate_pairs) + Bytes(s.constraints.slot_of_particle);
  for (const WallState<Dim>& w : s.walls)
    bytes += Bytes(w.particle) + Bytes(w.normal_elastic_force) + Bytes(w.tangential_force) + Bytes(w.jaw_inward) +
             Bytes(w.jaw_weight) + Bytes(w.jaw_reference_centre) +
             Bytes(w.scratch_particle) + Bytes(w.scratch_normal_force) +
             Bytes(w.scratch_tangential_force);
  return bytes;
}

template ParticleOrder SpatialOrder<2>(const std::vector<Vector<2>>&, int);
template ParticleOrder SpatialOrder<3>(const std::vector<Vector<3>>&, int);
template void RenumberParticles<2>(SceneState<2>&, const std::vector<int>&, std::vector<int>*);
template void RenumberParticles<3>(SceneState<3>&, const std::vector<int>&, std::vector<int>*);
template void ApplySpatialOrder<2>(SceneState<2>&);
template void ApplySpatialOrder<3>(SceneState<3>&);
template class ExternalView<2>;
template class ExternalView<3>;
template std::size_t MemoryBytes<2>(const SceneState<2>&);
template std::size_t MemoryBytes<3>(const SceneState<3>&);
template void RefreshContactDeformation<2>(SceneState<2>&);
template void RefreshContactDeformation<3>(SceneState<3>&);
template void RebuildAdjacency<2>(SceneState<2>&);
template void RebuildAdjacency<3>(SceneState<3>&);

}  // namespace specimen
