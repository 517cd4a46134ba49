// Spatial renumbering of large scenes (scene_state.h): a Simulation of a shuffled packing
// (renumbered inside along a Hilbert curve) must give, in the packing's order, what a
// Simulation of the same packing presented already in that order gives, with every index
// the user passes (loads, fixed dofs, SetVelocity, ParticleStress, the watched contact)
// meaning the packing's particle or contacts() entry.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "solver/regular_lattice.h"
#include "solver/scene_state.h"
#include "solver/simulation.h"

namespace specimen {
namespace {

// `packing` with its particles listed in the order new_of_old (contacts relabelled).
template <int Dim>
Packing<Dim> Renumbered(const Packing<Dim>& packing, const std::vector<int>& new_of_old) {
  Packing<Dim> out = packing;
  for (int q = 0; q < packing.size(); ++q) {
    out.centres[new_of_old[q]] = packing.centres[q];
    out.radii[new_of_old[q]] = packing.radii[q];
  }
  for (auto& pair : out.contacts) {
    pair = {new_of_old[pair[0]], new_of_old[pair[1]]};
    if (pair[0] > pair[1]) std::swap(pair[0], pair[1]);
  }
  std::sort(out.contacts.begin(), out.contacts.end());
  return out;
}

template <int Dim>
Packing<Dim> Shuffled(const Packing<Dim>& packing, std::uint32_t seed) {
  std::vector<int> permutation(packing.size());
  std::iota(permutation.begin(), permutation.end(), 0);
  std::shuffle(permutation.begin(), permutation.end(), std::mt19937(seed));
  return Renumbered(packing, permutation);
}

// Bonded specimen between two platens across the last axis, DDEM or rigid, with a
// point load, fixed dofs and a particle set moving: every path that carries an index.
template <int Dim>
SceneOptions<Dim> Scene(const Packing<Dim>& packing, const std::vector<int>& loaded,
                        const std::vector<int>& held, double time_step, bool deformable) {
  SceneOptions<Dim> scene;
  MaterialParameters& m = scene.material;
  m.normal_stiffness_n_per_m = 1e8;
  m.tangential_stiffness_n_per_m = 5e7;
  m.density_kg_per_m3 = 2000;
  m.friction_coefficient = 0.5;
  m.bond_tensile_strength_n = 50.0;
  m.translational_damping = 0.1;
  m.rotational_damping = 0.1;
  if (deformable) {
    // kn / (Ep l) = 0.2 in 2D (l = 1 m), kn / (Ep R) = 0.2 in 3D: the force iteration converges.
    m.particle_youngs_modulus_pa = Dim == 2 ? 5e8 : 5e11;
    m.particle_poisson_ratio = 0.2;
  }
  double lower = 1e300, upper = -1e300;
  for (int q = 0; q < packing.size(); ++q) {
    lower = std::min(lower, packing.centres[q][Dim - 1] - packing.radii[q]);
    upper = std::max(upper, packing.centres[q][Dim - 1] + packing.radii[q]);
  }
  WallOptions<Dim> bottom;
  bottom.name = "bottom";
  bottom.point[Dim - 1] = lower;
  bottom.normal[Dim - 1] = 1.0;
  bottom.normal_stiffness_n_per_m = 2e8;
  WallOptions<Dim> top = bottom;
  top.name = "top";
  top.point[Dim - 1] = upper;
  top.normal[Dim - 1] = -1.0;
  top.velocity[Dim - 1] = -0.05;
  scene.walls = {bottom, top};
  PointLoad<Dim> load;
  load.name = "side";
  load.particles = loaded;
  load.force_n[0] = 20.0;
  load.application_direction[0] = -1.0;
  scene.point_loads = {load};
  FixedDofs<Dim> fixed;
  fixed.name = "held";
  fixed.particles = held;
  fixed.fix_translation[0] = true;
  fixed.velocity[0] = 0.01;
  scene.fixed_dofs = {fixed};
  scene.time_step.time_step_s = time_step;
  return scene;
}

template <int Dim>
void CompareWithPresorted(const Packing<Dim>& lattice, bool deformable) {
  const Packing<Dim> packing = Shuffled(lattice, 7);
  const int count = packing.size();
  ASSERT_GE(count, kSpatialOrderThreshold);
  const ParticleOrder order = SpatialOrder<Dim>(packing.centres);
  ASSERT_FALSE(order.identity());
  // The same specimen in the internal order: its own Simulation is not renumbered.
  const Packing<Dim> presorted = Renumbered(packing, order.internal_of_external);
  ASSERT_TRUE(SpatialOrder<Dim>(presorted.centres).identity());

  std::vector<int> loaded, held;
  for (int q = 0; q < count; q += 97) loaded.push_back(q);
  for (int q = 5; q < count; q += 131) held.push_back(q);
  auto internal = [&](std::vector<int> list) {
    for (int& q : list) q = order.Internal(q);
    return list;
  };
  const double dt =
      0.5 *
      Simulation<Dim>(packing, Scene<Dim>(packing, loaded, held, 0.0, deformable)).time_step_s();
  Simulation<Dim> a(packing, Scene<Dim>(packing, loaded, held, dt, deformable));
  Simulation<Dim> b(presorted,
                    Scene<Dim>(presorted, internal(loaded), internal(held), dt, deformable));
  EXPECT_TRUE(a.state().order.identity());  // the view is in the packing's order

  Vector<Dim> kick = Vector<Dim>::Zero();
  kick[0] = 0.3;
  a.SetVelocity(11, kick);
  b.SetVelocity(order.Internal(11), kick);
  // A reference taken before the run must show the state after it.
  const ParticleArrays<Dim>& held_reference = a.particles();
  RunOptions run;
  run.max_steps = 300;
  const RunSummary summary_a = a.Run(run);
  const RunSummary summary_b = b.Run(run);
  EXPECT_EQ(summary_a.contacts, summary_b.contacts);
  EXPECT_EQ(summary_a.bonds_intact, summary_b.bonds_intact);
  EXPECT_EQ(&held_reference, &a.particles());

  const ParticleArrays<Dim>& pa = a.particles();
  const ParticleArrays<Dim>& pb = b.particles();
  double largest_move = 0.0, position_error = 0.0, velocity_error = 0.0, largest_speed = 0.0;
  for (int q = 0; q < count; ++q) {
    const int k = order.Internal(q);
    EXPECT_EQ(pa.radius[q], pb.radius[k]);
    largest_move = std::max(largest_move, (pa.position[q] - packing.centres[q]).norm());
    largest_speed = std::max(largest_speed, pa.velocity[q].norm());
    position_error = std::max(position_error, (pa.position[q] - pb.position[k]).norm());
    velocity_error = std::max(velocity_error, (pa.velocity[q] - pb.velocity[k]).norm());
    if (deformable) {
      EXPECT_NEAR((a.ParticleStress(q) - b.ParticleStress(k)).norm(), 0.0,
                  1e-9 * (1.0 + b.ParticleStress(k).norm()));
    }
  }
  EXPECT_GT(largest_move, 0.0);
  EXPECT_LE(position_error, 1e-12 * largest_move);
  EXPECT_LE(velocity_error, 1e-12 * largest_speed);
  EXPECT_EQ(held_reference.position[3], pa.position[3]);

  // Contacts in the packing's numbering, sorted by pair, forces on the lower index.
  const ContactArrays<Dim>& ca = a.contacts();
  const ContactArrays<Dim>& cb = b.contacts();
  ASSERT_EQ(ca.size(), cb.size());
  double largest_force = 0.0, force_error = 0.0;
  for (int c = 0; c < ca.size(); ++c) {
    const auto [i, j] = ca.pair[c];
    ASSERT_LT(i, j);
    if (c > 0) {
      ASSERT_LT(ca.pair[c - 1], ca.pair[c]);
    }
    const int k = cb.Find(order.Internal(i), order.Internal(j));
    ASSERT_GE(k, 0);
    EXPECT_EQ(a.contacts().Find(i, j), c);
    const double sign = order.Internal(i) < order.Internal(j) ? 1.0 : -1.0;
    EXPECT_EQ(ca.state[c], cb.state[k]);
    largest_force = std::max(largest_force, cb.force[k].norm());
    force_error = std::max(force_error, (ca.force[c] - sign * cb.force[k]).norm());
    EXPECT_NEAR(ca.normal[c].dot(sign * cb.normal[k]), 1.0, 1e-12);
  }
  EXPECT_GT(largest_force, 0.0);
  EXPECT_LE(force_error, 1e-9 * largest_force);

  // Walls, loads, constraints, energy.
  for (int w = 0; w < 2; ++w) {
    EXPECT_NEAR(a.wall(w).NormalReaction(), b.wall(w).NormalReaction(),
                1e-9 * std::abs(b.wall(w).NormalReaction()));
    ASSERT_EQ(a.wall(w).particle.size(), b.wall(w).particle.size());
    for (size_t k = 0; k < a.wall(w).particle.size(); ++k) {
      if (k > 0) {
        EXPECT_LT(a.wall(w).particle[k - 1], a.wall(w).particle[k]);
      }
      const int q = a.wall(w).particle[k];
      EXPECT_TRUE(std::binary_search(b.wall(w).particle.begin(), b.wall(w).particle.end(),
                                     order.Internal(q)));
    }
  }
  EXPECT_EQ(a.state().loads[0].load.particles, loaded);
  EXPECT_EQ(a.state().constraints.sets[0].particles, held);
  const Vector<Dim> reaction_a = a.FixedDofsReaction(0), reaction_b = b.FixedDofsReaction(0);
  EXPECT_NEAR((reaction_a - reaction_b).norm(), 0.0, 1e-9 * reaction_b.norm());
  EXPECT_NEAR(a.Energy().Imbalance(), b.Energy().Imbalance(),
              1e-9 * std::abs(b.Energy().kinetic_j + b.Energy().Elastic()));

  // The DDEM force iteration watches contacts() entry c in both numberings.
  if (deformable) {
    ForceIterationOptions iterate;
    iterate.max_iterations = 5;
    const int c = ca.size() / 3;
    iterate.watched_contact = c;
    const ForceIterationSummary ia = a.IterateDeformedContactForces(iterate);
    iterate.watched_contact = cb.Find(order.Internal(ca.pair[c][0]), order.Internal(ca.pair[c][1]));
    const ForceIterationSummary ib = b.IterateDeformedContactForces(iterate);
    ASSERT_EQ(ia.watched_normal_force_n.size(), ib.watched_normal_force_n.size());
    for (size_t k = 0; k < ia.watched_normal_force_n.size(); ++k)
      EXPECT_NEAR(ia.watched_normal_force_n[k], ib.watched_normal_force_n[k],
                  1e-9 * std::abs(ib.watched_normal_force_n[k]) + 1e-12);
    EXPECT_NE(ia.watched_normal_force_n.front(), 0.0);
  }
}

TEST(SpatialOrder, SmallOrOrderedSetsKeepTheirNumbering) {
  const Packing<2> small = SquareLatticePacking(10, 10, 1e-3);
  EXPECT_TRUE(SpatialOrder<2>(small.centres).identity());
  const Packing<2> large = Shuffled(SquareLatticePacking(70, 60, 1e-3), 3);
  const ParticleOrder order = SpatialOrder<2>(large.centres);
  ASSERT_FALSE(order.identity());
  std::vector<int> seen(large.size(), 0);
  for (int q = 0; q < large.size(); ++q) {
    ++seen[order.Internal(q)];
    EXPECT_EQ(order.External(order.Internal(q)), q);
  }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), large.size());
  // Neighbours along the curve are neighbours in space: the mean distance between
  // consecutive particles is a few diameters, not the specimen's size.
  double sum = 0.0;
  for (int k = 1; k < large.size(); ++k)
    sum += (large.centres[order.External(k)] - large.centres[order.External(k - 1)]).norm();
  EXPECT_LT(sum / (large.size() - 1), 3 * 2e-3);
}

TEST(SpatialOrder, RenumberedSceneMatchesThePresortedOne2D) {
  CompareWithPresorted<2>(SquareLatticePacking(72, 60, 1e-3), true);
}

TEST(SpatialOrder, RenumberedSceneMatchesThePresortedOne3D) {
  CompareWithPresorted<3>(CubicLatticePacking(17, 16, 16, 1e-3), false);
}

// DDEM in 3D: the strain rows the contact pass reads (scene_state.h) follow the renumbering
// and the force iteration.
TEST(SpatialOrder, RenumberedDeformableSceneMatchesThePresortedOne3D) {
  CompareWithPresorted<3>(CubicLatticePacking(17, 16, 16, 1e-3), true);
}

}  // namespace
}  // namespace specimen
