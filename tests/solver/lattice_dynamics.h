#pragma once
// Small lattices and a central-difference run for the six-spring lattice tests.

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "solver/six_spring_lattice.h"

namespace specimen {

// A periodic rhombic block of nx x ny nodes (even, so that the M point is a mode of it).
inline TriangleLattice PeriodicBlock(int nx, int ny, double side, const PlaneElasticity& d, double s) {
  TriangleLattice lattice;
  lattice.thickness_m = s;
  auto id = [&](int c, int r) { return ((r % ny + ny) % ny) * nx + (c % nx + nx) % nx; };
  auto at = [&](int c, int r) { return Vector<2>((c + 0.5 * r) * side, r * 0.5 * std::sqrt(3.0) * side); };
  auto add = [&](std::array<std::array<int, 2>, 3> v) {
    const Vector<2> a = at(v[0][0], v[0][1]), b = at(v[1][0], v[1][1]), c = at(v[2][0], v[2][1]);
    lattice.nodes.push_back({id(v[0][0], v[0][1]), id(v[1][0], v[1][1]), id(v[2][0], v[2][1])});
    lattice.rest_edges.push_back({b - a, c - b, a - c});
    lattice.rest_lengths.push_back({side, side, side});
    lattice.stiffness.push_back(TriangleNaturalStiffness(a, b, c, d, s));
    lattice.areas.push_back(0.25 * std::sqrt(3.0) * side * side);
  };
  for (int r = 0; r < ny; ++r) {
    for (int c = 0; c < nx; ++c) {
      add({{{c, r}, {c + 1, r}, {c, r + 1}}});
      add({{{c + 1, r}, {c + 1, r + 1}, {c, r + 1}}});
    }
  }
  return lattice;
}

// Largest |u| after `steps` of central differences at dt from a random field of amplitude 1e-9.
inline double CentralDifferenceGrowth(const TriangleLattice& lattice, int nodes, double density, double dt, int steps) {
  const std::vector<double> mass = LumpedMasses(lattice, nodes, density);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vector<2>> disp(nodes), velocity(nodes, Vector<2>::Zero()), force(nodes);
  for (auto& x : disp) x = 1e-9 * Vector<2>(u(rng), u(rng));
  double largest = 0.0;
  for (int step = 0; step < steps; ++step) {
    std::fill(force.begin(), force.end(), Vector<2>::Zero());
    AddTriangleForces(lattice, disp, &force);
    for (int i = 0; i < nodes; ++i) {
      velocity[i] += dt * force[i] / mass[i];
      disp[i] += dt * velocity[i];
      largest = std::max(largest, disp[i].norm());
    }
    if (!std::isfinite(largest) || largest > 1.0) return largest;
  }
  return largest;
}

}  // namespace specimen
