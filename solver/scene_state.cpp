#include "solver/scene_state.h"

namespace specimen {

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
  a.entry.resize(2 * static_cast<size_t>(contacts));
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
           Bytes(p.inverse_inertia) + Bytes(p.strain);
  for (const ContactArrays<Dim>* c : {&s.contacts, &s.contacts_scratch})
    bytes += Bytes(c->pair) + Bytes(c->state) + Bytes(c->reference_gap) + Bytes(c->normal) +
             Bytes(c->force) + Bytes(c->normal_elastic_force) + Bytes(c->tangential_force);
  bytes += Bytes(s.adjacency.offset) + Bytes(s.adjacency.entry) + Bytes(s.adjacency_cursor);
  bytes += Bytes(s.external_force) + Bytes(s.external_torque) + Bytes(s.external_moment);
  bytes += Bytes(s.candidate_pairs) + Bytes(s.constraints.slot_of_particle);
  for (const WallState<Dim>& w : s.walls)
    bytes += Bytes(w.particle) + Bytes(w.normal_elastic_force) + Bytes(w.tangential_force) +
             Bytes(w.scratch_particle) + Bytes(w.scratch_normal_force) +
             Bytes(w.scratch_tangential_force);
  return bytes;
}

template std::size_t MemoryBytes<2>(const SceneState<2>&);
template std::size_t MemoryBytes<3>(const SceneState<3>&);
template void RebuildAdjacency<2>(SceneState<2>&);
template void RebuildAdjacency<3>(SceneState<3>&);

}  // namespace specimen
