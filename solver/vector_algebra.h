#pragma once
// Fixed-size algebra shared by the solver stages, written once for both dimensions:
//  - Angular<Dim>: the rotational quantity of a particle, a scalar about z in 2D (discs)
//    and a vector in 3D (spheres);
//  - Cross(): the cross products between positions, forces and angular quantities;
//  - SymmetricTensor<Dim>: compact storage of a symmetric tensor (particle stress and
//    strain), tensor (not engineering) shear components:
//      2D (xx, yy, xy)             3D (xx, yy, zz, yz, xz, xy)

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "generator/domain.h"

namespace specimen {

template <int Dim>
struct AngularTraits;
template <>
struct AngularTraits<2> {
  using Type = double;
};
template <>
struct AngularTraits<3> {
  using Type = Eigen::Vector3d;
};
// Angular velocity, torque, rotation increment: a scalar about z in 2D, a vector in 3D.
template <int Dim>
using Angular = typename AngularTraits<Dim>::Type;

template <int Dim>
inline Angular<Dim> ZeroAngular() {
  if constexpr (Dim == 2) {
    return 0.0;
  } else {
    return Eigen::Vector3d::Zero();
  }
}

inline double AngularDot(double a, double b) { return a * b; }
inline double AngularDot(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.dot(b); }
inline double AngularNorm(double a) { return std::abs(a); }
inline double AngularNorm(const Eigen::Vector3d& a) { return a.norm(); }
inline bool AngularIsFinite(double a) { return std::isfinite(a); }
inline bool AngularIsFinite(const Eigen::Vector3d& a) { return a.allFinite(); }

// a x b: the z component in 2D.
inline double Cross(const Vector<2>& a, const Vector<2>& b) {
  return a.x() * b.y() - a.y() * b.x();
}
inline Vector<3> Cross(const Vector<3>& a, const Vector<3>& b) { return a.cross(b); }
// w x r for an angular quantity w (about z in 2D).
inline Vector<2> Cross(double w, const Vector<2>& r) { return Vector<2>(-w * r.y(), w * r.x()); }

// The unit vector perpendicular to n, rotated +90 degrees (2D only).
inline Vector<2> Perpendicular(const Vector<2>& n) { return Vector<2>(-n.y(), n.x()); }

template <int Dim>
constexpr int kVoigtSize = Dim == 2 ? 3 : 6;

// Symmetric tensor, tensor shear components (see the header comment for the order).
template <int Dim>
using SymmetricTensor = Eigen::Matrix<double, kVoigtSize<Dim>, 1>;

// n . T . n for a symmetric tensor T (Madan (2.53): the normal displacement of the
// contact point of a uniformly strained disc is R n.eps.n).
inline double QuadraticForm(const SymmetricTensor<2>& t, const Vector<2>& n) {
  return t[0] * n.x() * n.x() + t[1] * n.y() * n.y() + 2.0 * t[2] * n.x() * n.y();
}
inline double QuadraticForm(const SymmetricTensor<3>& t, const Vector<3>& n) {
  return t[0] * n.x() * n.x() + t[1] * n.y() * n.y() + t[2] * n.z() * n.z() +
         2.0 * (t[3] * n.y() * n.z() + t[4] * n.x() * n.z() + t[5] * n.x() * n.y());
}

// The symmetric part of a full Dim x Dim matrix (Madan (2.44)), in compact form.
inline SymmetricTensor<2> SymmetricPart(const Eigen::Matrix2d& m) {
  return SymmetricTensor<2>(m(0, 0), m(1, 1), 0.5 * (m(0, 1) + m(1, 0)));
}
inline SymmetricTensor<3> SymmetricPart(const Eigen::Matrix3d& m) {
  SymmetricTensor<3> t;
  t << m(0, 0), m(1, 1), m(2, 2), 0.5 * (m(1, 2) + m(2, 1)), 0.5 * (m(0, 2) + m(2, 0)),
      0.5 * (m(0, 1) + m(1, 0));
  return t;
}

// The full matrix of a compact symmetric tensor.
inline Eigen::Matrix2d FullMatrix(const SymmetricTensor<2>& t) {
  Eigen::Matrix2d m;
  m << t[0], t[2], t[2], t[1];
  return m;
}
inline Eigen::Matrix3d FullMatrix(const SymmetricTensor<3>& t) {
  Eigen::Matrix3d m;
  m << t[0], t[5], t[4], t[5], t[1], t[3], t[4], t[3], t[2];
  return m;
}

// a : b (double contraction) of two symmetric tensors.
template <int Dim>
inline double DoubleContraction(const SymmetricTensor<Dim>& a, const SymmetricTensor<Dim>& b) {
  double sum = 0.0;
  for (int k = 0; k < Dim; ++k) sum += a[k] * b[k];
  for (int k = Dim; k < kVoigtSize<Dim>; ++k) sum += 2.0 * a[k] * b[k];
  return sum;
}

// Frobenius norm of a symmetric tensor: bounds |n.T.n| for every unit n.
template <int Dim>
inline double FrobeniusNorm(const SymmetricTensor<Dim>& t) {
  return std::sqrt(DoubleContraction<Dim>(t, t));
}

}  // namespace specimen
