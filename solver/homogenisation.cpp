#include "solver/homogenisation.h"

#include <string>

#include "common/error.h"
#include "solver/scene_state.h"

namespace specimen {

template <int Dim>
Eigen::Matrix<double, Dim, Dim> LoveWeberStress(const SceneState<Dim>& s,
                                                const std::vector<int>& particles, double volume) {
  if (!(volume > 0.0)) throw InputError("LoveWeberStress: volume must be > 0");
  Eigen::Matrix<double, Dim, Dim> sum = Eigen::Matrix<double, Dim, Dim>::Zero();
  for (const int q : particles) {
    if (q < 0 || q >= s.particles.size())
      throw InputError("LoveWeberStress: particle index " + std::to_string(q) + " is out of range");
    const double r = s.particles.radius[q];
    // The arm is +r n at i and -r n at j, where the force is -f: both give r n (x) f.
    for (int e = s.adjacency.offset[q]; e < s.adjacency.offset[q + 1]; ++e) {
      const int k = s.adjacency.entry[e] >> 1;
      sum.noalias() += r * s.contacts.normal[k] * s.contacts.force[k].transpose();
    }
  }
  return 0.5 * (sum + sum.transpose()) / volume;
}

template <int Dim>
Eigen::Matrix<double, Dim, Dim> SpecimenStress(const SceneState<Dim>& s, double volume) {
  if (!(volume > 0.0)) throw InputError("SpecimenStress: volume must be > 0");
  Eigen::Matrix<double, Dim, Dim> sum = Eigen::Matrix<double, Dim, Dim>::Zero();
  const ContactArrays<Dim>& c = s.contacts;
  const auto& x = s.particles.position;
  for (int k = 0; k < c.size(); ++k) {
    const auto& [i, j] = c.pair[k];
    sum.noalias() += (x[j] - x[i]) * c.force[k].transpose();
  }
  for (const WallState<Dim>& w : s.walls) {
    for (size_t k = 0; k < w.particle.size(); ++k) {
      const double fn = w.normal_elastic_force[k];  // <= 0: compression
      if (fn == 0.0) continue;
      const Vector<Dim>& push = w.PushDirection(k);
      const Vector<Dim> force = -fn * push + w.tangential_force[k];
      sum.noalias() += (-s.particles.radius[w.particle[k]] * push) * force.transpose();
    }
  }
  return 0.5 * (sum + sum.transpose()) / volume;
}

template Eigen::Matrix2d SpecimenStress<2>(const SceneState<2>&, double);
template Eigen::Matrix3d SpecimenStress<3>(const SceneState<3>&, double);
template Eigen::Matrix2d LoveWeberStress<2>(const SceneState<2>&, const std::vector<int>&, double);
template Eigen::Matrix3d LoveWeberStress<3>(const SceneState<3>&, const std::vector<int>&, double);

}  // namespace specimen
