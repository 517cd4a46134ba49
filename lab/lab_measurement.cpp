#include "lab/lab_measurement.h"

#include <cmath>
#include <string>

#include "common/error.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Axial shortening and lateral expansion (mean of the other normal components) of a Bagi
// strain tensor, both from the tension-positive tensor: axial = -e_aa, lateral = e_ll.
template <int Dim>
void AxialAndLateral(const Eigen::Matrix3d& strain, int axis, double* axial, double* lateral) {
  *axial = -strain(axis, axis);
  double sum = 0.0;
  for (int k = 0; k < Dim; ++k)
    if (k != axis) sum += strain(k, k);
  *lateral = sum / (Dim - 1);
}

// The window's two end states; false if the curve does not reach them before the peak.
bool WindowStates(const std::vector<LabCurvePoint>& curve, const CurvePeak& peak, double low,
                  double high, LabCurvePoint* first, LabCurvePoint* second, int* samples) {
  if (peak.index < 0 || !(peak.control > 0.0)) return false;
  const double level_low = low * peak.control, level_high = high * peak.control;
  if (!InterpolateAtControl(curve, peak.index, level_low, first) ||
      !InterpolateAtControl(curve, peak.index, level_high, second))
    return false;
  *samples = 0;
  for (int k = 0; k <= peak.index; ++k)
    if (curve[k].control >= level_low && curve[k].control <= level_high) ++*samples;
  return true;
}

}  // namespace

CurvePeak FindPeak(const std::vector<LabCurvePoint>& curve, double post_peak_fraction) {
  CurvePeak peak;
  for (int k = 0; k < static_cast<int>(curve.size()); ++k)
    if (peak.index < 0 || curve[k].control > peak.control) {
      peak.index = k;
      peak.control = curve[k].control;
    }
  if (peak.index >= 0 && peak.control > 0.0)
    for (int k = peak.index + 1; k < static_cast<int>(curve.size()); ++k)
      if (curve[k].control <= post_peak_fraction * peak.control) {
        peak.confirmed = true;
        break;
      }
  return peak;
}

bool InterpolateAtControl(const std::vector<LabCurvePoint>& curve, int last_index, double level,
                          LabCurvePoint* state) {
  for (int k = 0; k <= last_index && k < static_cast<int>(curve.size()); ++k) {
    if (curve[k].control < level) continue;
    if (k == 0) {
      *state = curve[0];
      return true;
    }
    const LabCurvePoint& a = curve[k - 1];
    const LabCurvePoint& b = curve[k];
    const double t = (level - a.control) / (b.control - a.control);
    LabCurvePoint p = a;
    p.time_s = a.time_s + t * (b.time_s - a.time_s);
    p.stress_pa = a.stress_pa + t * (b.stress_pa - a.stress_pa);
    p.strain = a.strain + t * (b.strain - a.strain);
    p.boundary_strain = a.boundary_strain + t * (b.boundary_strain - a.boundary_strain);
    p.control = level;
    p.axial_stress_pa = a.axial_stress_pa + t * (b.axial_stress_pa - a.axial_stress_pa);
    p.lateral_stress_pa = a.lateral_stress_pa + t * (b.lateral_stress_pa - a.lateral_stress_pa);
    p.platen_force_n = a.platen_force_n + t * (b.platen_force_n - a.platen_force_n);
    *state = p;
    return true;
  }
  return false;
}

void PlaneStrainFromInPlane(double in_plane_youngs_pa, double in_plane_poisson, double* youngs_pa,
                            double* poisson) {
  *poisson = in_plane_poisson / (1.0 + in_plane_poisson);
  *youngs_pa = in_plane_youngs_pa * (1.0 - *poisson * *poisson);
}

template <int Dim>
ElasticConstantsMeasured SecantElasticConstants(const std::vector<LabCurvePoint>& curve,
                                                const CurvePeak& peak, int axis, double low,
                                                double high) {
  ElasticConstantsMeasured e;
  LabCurvePoint a, b;
  if (!WindowStates(curve, peak, low, high, &a, &b, &e.samples_in_window)) return e;
  e.window_low_pa = a.control;
  e.window_high_pa = b.control;
  for (int k = 0; k <= peak.index; ++k)
    if (curve[k].control >= b.control) {
      e.broken_bonds_in_window = curve[k].broken_in_tension + curve[k].broken_in_shear;
      break;
    }
  double axial_a, lateral_a, axial_b, lateral_b;
  AxialAndLateral<Dim>(a.strain, axis, &axial_a, &lateral_a);
  AxialAndLateral<Dim>(b.strain, axis, &axial_b, &lateral_b);
  const double stress_change = b.axial_stress_pa - a.axial_stress_pa;
  const double axial_change = axial_b - axial_a;
  if (!(axial_change != 0.0) || !(b.boundary_strain != a.boundary_strain)) return e;
  e.measured = true;
  e.youngs_modulus_in_plane_pa = stress_change / axial_change;      // Labra (4.31)
  e.poisson_ratio_in_plane = (lateral_b - lateral_a) / axial_change;  // (4.34)
  e.youngs_modulus_platen_pa = stress_change / (b.boundary_strain - a.boundary_strain);
  if constexpr (Dim == 2) {
    PlaneStrainFromInPlane(e.youngs_modulus_in_plane_pa, e.poisson_ratio_in_plane,
                           &e.youngs_modulus_pa, &e.poisson_ratio);
  } else {
    e.youngs_modulus_pa = e.youngs_modulus_in_plane_pa;
    e.poisson_ratio = e.poisson_ratio_in_plane;
  }
  return e;
}

template <int Dim>
ElasticConstantsMeasured LinearPortionElasticConstants(const std::vector<LabCurvePoint>& curve, int axis,
                                                       double low_fraction) {
  ElasticConstantsMeasured e;
  // The intact part: up to the last sample before the first broken bond, and not past the
  // largest control value (a platen that lost contact, say).
  int end = 0;
  while (end < static_cast<int>(curve.size()) &&
         curve[end].broken_in_tension + curve[end].broken_in_shear == 0)
    ++end;
  int top = -1;
  for (int k = 0; k < end; ++k)
    if (top < 0 || curve[k].control > curve[top].control) top = k;
  if (top < 0 || !(curve[top].control > 0.0)) return e;
  const double level_low = low_fraction * curve[top].control;
  // Sums of the three least-squares lines against the axial strain x: stress, lateral strain,
  // and the stress against the platen strain.
  double n = 0.0, sx = 0.0, sxx = 0.0, ss = 0.0, sxs = 0.0, sl = 0.0, sxl = 0.0;
  double sb = 0.0, sbb = 0.0, sbs = 0.0;
  for (int k = 0; k <= top; ++k) {
    if (curve[k].control < level_low) continue;
    double axial, lateral;
    AxialAndLateral<Dim>(curve[k].strain, axis, &axial, &lateral);
    const double stress = curve[k].axial_stress_pa, platen = curve[k].boundary_strain;
    n += 1.0;
    sx += axial, sxx += axial * axial, ss += stress, sxs += axial * stress;
    sl += lateral, sxl += axial * lateral;
    sb += platen, sbb += platen * platen, sbs += platen * stress;
  }
  const double det = n * sxx - sx * sx, det_platen = n * sbb - sb * sb;
  if (n < 4.0 || !(det > 0.0) || !(det_platen > 0.0)) return e;
  e.measured = true;
  e.samples_in_window = static_cast<int>(n);
  e.window_low_pa = level_low;
  e.window_high_pa = curve[top].control;
  e.youngs_modulus_in_plane_pa = (n * sxs - sx * ss) / det;
  e.poisson_ratio_in_plane = (n * sxl - sx * sl) / det;
  e.youngs_modulus_platen_pa = (n * sbs - sb * ss) / det_platen;
  if constexpr (Dim == 2) {
    PlaneStrainFromInPlane(e.youngs_modulus_in_plane_pa, e.poisson_ratio_in_plane, &e.youngs_modulus_pa,
                           &e.poisson_ratio);
  } else {
    e.youngs_modulus_pa = e.youngs_modulus_in_plane_pa;
    e.poisson_ratio = e.poisson_ratio_in_plane;
  }
  return e;
}

template <int Dim>
double SecantBulkModulus(const std::vector<LabCurvePoint>& curve, const CurvePeak& peak,
                         double low, double high) {
  LabCurvePoint a, b;
  int samples = 0;
  if (!WindowStates(curve, peak, low, high, &a, &b, &samples)) return 0.0;
  double mean_a = 0.0, mean_b = 0.0, volume_a = 0.0, volume_b = 0.0;
  for (int k = 0; k < Dim; ++k) {
    mean_a -= a.stress_pa(k, k) / Dim;
    mean_b -= b.stress_pa(k, k) / Dim;
    volume_a -= a.strain(k, k);
    volume_b -= b.strain(k, k);
  }
  return volume_b != volume_a ? (mean_b - mean_a) / (volume_b - volume_a) : 0.0;
}

template <int Dim>
double SecantShearModulus(const std::vector<LabCurvePoint>& curve, const CurvePeak& peak,
                          double low, double high) {
  LabCurvePoint a, b;
  int samples = 0;
  if (!WindowStates(curve, peak, low, high, &a, &b, &samples)) return 0.0;
  const int s = Dim - 1;  // 2D: xy, 3D: xz
  const double strain_change = b.strain(0, s) - a.strain(0, s);
  return strain_change != 0.0 ? (b.stress_pa(0, s) - a.stress_pa(0, s)) / (2.0 * strain_change)
                              : 0.0;
}

MohrCoulombFit FitMohrCoulomb(const std::vector<double>& confining, const std::vector<double>& peak) {
  if (confining.size() != peak.size())
    throw InputError("FitMohrCoulomb: " + std::to_string(confining.size()) + " confinements for " +
                     std::to_string(peak.size()) + " peak stresses");
  const int n = static_cast<int>(confining.size());
  double mean_x = 0.0, mean_y = 0.0;
  for (int k = 0; k < n; ++k) {
    mean_x += confining[k] / n;
    mean_y += peak[k] / n;
  }
  double sxx = 0.0, sxy = 0.0;
  for (int k = 0; k < n; ++k) {
    sxx += (confining[k] - mean_x) * (confining[k] - mean_x);
    sxy += (confining[k] - mean_x) * (peak[k] - mean_y);
  }
  if (n < 2 || !(sxx > 0.0))
    throw InputError("FitMohrCoulomb: the envelope needs at least two distinct confinements (got " +
                     std::to_string(n) + " points)");
  MohrCoulombFit fit;
  fit.points = n;
  fit.slope = sxy / sxx;
  fit.intercept_pa = mean_y - fit.slope * mean_x;
  double residual = 0.0;
  for (int k = 0; k < n; ++k) {
    const double r = peak[k] - (fit.intercept_pa + fit.slope * confining[k]);
    residual += r * r / n;
  }
  fit.rms_residual_pa = std::sqrt(residual);
  // sigma_1 = 2 c cos(phi) / (1 - sin phi) + sigma_3 (1 + sin phi) / (1 - sin phi).
  const double sine = (fit.slope - 1.0) / (fit.slope + 1.0);
  if (fit.slope > 1.0 && fit.intercept_pa > 0.0) {
    const double phi = std::asin(sine);
    fit.friction_angle_deg = phi * 180.0 / kPi;
    fit.cohesion_pa = fit.intercept_pa * (1.0 - sine) / (2.0 * std::cos(phi));
    fit.valid = true;
  }
  return fit;
}

template ElasticConstantsMeasured SecantElasticConstants<2>(const std::vector<LabCurvePoint>&,
                                                            const CurvePeak&, int, double, double);
template ElasticConstantsMeasured SecantElasticConstants<3>(const std::vector<LabCurvePoint>&,
                                                            const CurvePeak&, int, double, double);
template ElasticConstantsMeasured LinearPortionElasticConstants<2>(const std::vector<LabCurvePoint>&, int,
                                                                   double);
template ElasticConstantsMeasured LinearPortionElasticConstants<3>(const std::vector<LabCurvePoint>&, int,
                                                                   double);
template double SecantBulkModulus<2>(const std::vector<LabCurvePoint>&, const CurvePeak&, double,
                                     double);
template double SecantBulkModulus<3>(const std::vector<LabCurvePoint>&, const CurvePeak&, double,
                                     double);
template double SecantShearModulus<2>(const std::vector<LabCurvePoint>&, const CurvePeak&, double,
                                      double);
template double SecantShearModulus<3>(const std::vector<LabCurvePoint>&, const CurvePeak&, double,
                                      double);

}  // namespace specimen
