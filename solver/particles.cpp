#include "solver/particles.h"

#include <cmath>
#include <string>

#include "common/error.h"

namespace specimen {

template <int Dim>
ParticleArrays<Dim> BuildParticles(const Packing<Dim>& packing, const MaterialParameters& material,
                                   bool deformable) {
  const int count = packing.size();
  if (static_cast<int>(packing.centres.size()) != count)
    throw InputError("packing has " + std::to_string(packing.centres.size()) + " centres but " +
                     std::to_string(count) + " radii");
  if (count == 0) throw InputError("packing has no particles");
  ParticleArrays<Dim> p;
  p.position = packing.centres;
  p.velocity.assign(count, Vector<Dim>::Zero());
  p.angular_velocity.assign(count, ZeroAngular<Dim>());
  if (Dim == 2) p.rotation_angle.assign(count, 0.0);
  p.radius = packing.radii;
  p.mass.resize(count);
  p.inverse_mass.resize(count);
  p.inverse_inertia.resize(count);
  for (int i = 0; i < count; ++i) {
    const double r = packing.radii[i];
    if (!(r > 0.0) || !std::isfinite(r))
      throw InputError("radius of particle " + std::to_string(i) + " = " + std::to_string(r) +
                       " is not allowed: it must be finite and > 0");
    if (!packing.centres[i].allFinite())
      throw InputError("centre of particle " + std::to_string(i) + " is not a finite point");
    const double m = material.density_kg_per_m3 * ParticleVolume<Dim>(r);  // 2D: per unit thickness
    // Madan (2.3) cylinder J = m R^2 / 2, (2.4) sphere J = 2/5 m R^2.
    const double inertia = (Dim == 2 ? 0.5 : 0.4) * m * r * r;
    p.mass[i] = m;
    p.inverse_mass[i] = 1.0 / m;
    p.inverse_inertia[i] = 1.0 / inertia;
  }
  if (deformable) p.strain.assign(count, SymmetricTensor<Dim>::Zero());
  return p;
}

template ParticleArrays<2> BuildParticles<2>(const Packing<2>&, const MaterialParameters&, bool);
template ParticleArrays<3> BuildParticles<3>(const Packing<3>&, const MaterialParameters&, bool);

}  // namespace specimen
