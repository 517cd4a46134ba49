#include "stability/stability_closed_forms.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace specimen {

namespace {

constexpr double kPi = 3.14159265358979323846;

LatticeLimits PlaneStrainLimits(double nu) {
  LatticeLimits limits;
  limits.row = kPi / (4.0 * (1.0 - nu * nu));                                     // Madan (3.27)
  limits.square = kPi / (4.0 * (1.0 + nu));                                       // (3.42)
  limits.hexagonal = kPi / ((1.0 + nu) * std::max(3.0, 6.0 * (1.0 - 2.0 * nu)));  // (3.78)
  return limits;
}

}  // namespace

LatticeLimits ClosedFormLimits(int dimension, double nu, PlaneModel plane_model) {
  if (dimension == 3) {
    LatticeLimits limits;
    limits.row = kPi / 3.0;
    limits.square = kPi / (3.0 * std::max(1.0 + nu, 1.0 - 2.0 * nu));
    limits.hexagonal = std::numeric_limits<double>::quiet_NaN();
    return limits;
  }
  if (plane_model == PlaneModel::kPlaneStrain) return PlaneStrainLimits(nu);
  // Plane stress (Ep, nu) = plane strain (Ep / (1 - nu'^2), nu'), nu' = nu / (1 + nu).
  const double equivalent = nu / (1.0 + nu);
  const double factor = 1.0 - equivalent * equivalent;
  LatticeLimits limits = PlaneStrainLimits(equivalent);
  limits.row *= factor;
  limits.square *= factor;
  limits.hexagonal *= factor;
  return limits;
}

}  // namespace specimen
