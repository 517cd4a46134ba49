#pragma once
// Averaged stress over a set of particles (Love-Weber; Madan (4.1)-(4.3), Labra (A.9)-(A.14)):
//   sigma = (1/V) sum_{p in set} sum_{c of p} s_pc (x) f_pc,   symmetrised,
// with s_pc = R_p n the arm from the centre to the contact point and f_pc the contact force
// on p. Contact forces only: external surface loads and wall forces are not included, so
// use it on interior particles or add them. SpecimenStress below is the whole-specimen
// average with the wall contacts; the Bagi strain is in homogenisation_strain.h.

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

// The average stress of the whole specimen (Labra (4.5), (A.14); Madan (4.3)), with the
// wall contacts (platens, lateral walls) as boundary terms:
//   sigma = (1/V) sym[ sum_c l^c (x) f^c + sum_{wall contacts} s (x) f ],
// l^c = x_j - x_i the branch vector of contact c and f^c the force on i (so a bond in
// tension gives a positive l.f: tension positive); s = -R n_wall the arm from the centre
// to the contact point on the wall and f the elastic wall force on the particle (the wall
// dashpot, a small rate term, is left out). In static equilibrium the sum equals
// sum over external forces of (point of action) (x) force, so with platens alone
// sigma_yy = -F H / V = -F / W for V = H W. Forces prescribed at particle centres (fixed
// degrees of freedom) need no extra term: their arm is zero. V > 0 [m^3; 2D: m^2 x 1 m].
template <int Dim>
Eigen::Matrix<double, Dim, Dim> SpecimenStress(const SceneState<Dim>& state, double volume);

}  // namespace specimen
