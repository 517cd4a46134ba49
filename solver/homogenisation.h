#pragma once
// Averaged stress over a set of particles (Love-Weber; Madan (4.1)-(4.3), Labra (A.9)-(A.14)):
//   sigma = (1/V) sum_{p in set} sum_{c of p} s_pc (x) f_pc,   symmetrised,
// with s_pc = R_p n the arm from the centre to the contact point and f_pc the contact force
// on p. Contact forces only: external surface loads and wall forces are not included, so
// use it on interior particles or add them. The full homogenisation (Bagi strain, moduli
// over a load range) is a later stage; this is what the lattice oracles need.

#include <Eigen/Core>
#include <vector>

namespace specimen {

template <int Dim>
struct SceneState;

// V [m^3, 2D: m^2 per unit thickness] is the volume the particles represent (e.g. their
// Voronoi cells), > 0.
template <int Dim>
Eigen::Matrix<double, Dim, Dim> LoveWeberStress(const SceneState<Dim>& state,
                                                const std::vector<int>& particles, double volume);

}  // namespace specimen
