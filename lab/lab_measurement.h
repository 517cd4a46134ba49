#pragma once
// What a lab test measures from its sampled curve (lab_test.h LabCurvePoint): the peak of
// the control quantity, the secant elastic constants over a window of it (Labra (4.31),
// (4.34): E' = d sigma_yy / d eps_yy, nu' = -d eps_xx / d eps_yy over 1-50 % of the peak),
// the 2D plane-strain conversion, the bulk and shear moduli of the isotropic and shear tests
// (Madan (4.33)-(4.36)) and the Mohr-Coulomb fit of a peak-strength envelope.
//
// Secants: the two end states are interpolated linearly between samples, on the rising
// branch (before the peak), where the control quantity first reaches window_low x peak and
// window_high x peak; E is the stress change over the strain change between them. Sampling
// every few hundred steps is enough: the curve is smooth at quasi-static rates, and the
// interpolation error is second order in the sample spacing.

#include <vector>

#include "lab/lab_test.h"

namespace specimen {

struct CurvePeak {
  int index = -1;          // sample of the largest control value (-1: empty curve)
  double control = 0.0;
  bool confirmed = false;  // a later sample fell to post_peak_fraction x the peak or below
};

CurvePeak FindPeak(const std::vector<LabCurvePoint>& curve, double post_peak_fraction);

// The state where the control quantity first reaches `level` on samples [0, last_index],
// interpolated linearly between the two samples around it. False if it is never reached.
bool InterpolateAtControl(const std::vector<LabCurvePoint>& curve, int last_index, double level,
                          LabCurvePoint* state);

// Plane-strain constants of a 2D model from its in-plane ones (docs/lab.md, "Measurement"):
// nu = nu' / (1 + nu'), E = E' (1 - nu^2).
void PlaneStrainFromInPlane(double in_plane_youngs_pa, double in_plane_poisson,
                            double* youngs_pa, double* poisson);

// Secant E and nu of a compression test (UCS, confined) along `axis` over the window
// [low, high] x the control value of `peak`. Axial and lateral strains from the Bagi tensor
// (lateral: the mean of the other normal components); the platen E from boundary_strain.
template <int Dim>
ElasticConstantsMeasured SecantElasticConstants(const std::vector<LabCurvePoint>& curve,
                                                const CurvePeak& peak, int axis,
                                                double window_low, double window_high);

// The elastic constants of the intact specimen, the average modulus of the linear portion
// of the ISRM suggested method (Bieniawski & Bernede 1979; ASTM D7012 method B): the slopes,
// by least squares, of the axial stress and of the lateral strain against the axial strain
// over the samples of a compression test (along `axis`) that lie before the first broken
// bond and the peak, and whose control stress is at least `low_fraction` x the largest one
// among them. Below that fraction the drive's start-up (the velocity ramp) still shows in the
// lateral strain. A bonded specimen is linear while no bond has broken, so these constants
// depend on kn, kt (and the DDEM particle elasticity) only, never on the bond strengths: the
// separation the calibrator relies on. broken_bonds_in_window is 0 by construction. Not
// measured (measured = false) when fewer than 4 samples qualify.
template <int Dim>
ElasticConstantsMeasured LinearPortionElasticConstants(const std::vector<LabCurvePoint>& curve,
                                                       int axis, double low_fraction);

// Secant K = d sigma_m / d eps_vol (isotropic test; 2D sigma_m = (sxx + syy)/2, eps_vol =
// exx + eyy, Madan (4.33)-(4.35)) and G = d sigma_xs / (2 d eps_xs) with s = y (2D) or z
// (3D) (shear test, (4.36)), over the same kind of window. 0 when the window is not reached.
template <int Dim>
double SecantBulkModulus(const std::vector<LabCurvePoint>& curve, const CurvePeak& peak,
                         double window_low, double window_high);
template <int Dim>
double SecantShearModulus(const std::vector<LabCurvePoint>& curve, const CurvePeak& peak,
                          double window_low, double window_high);

// Linear fit sigma_1 = a + b sigma_3 of peak strengths at several confinements (least
// squares), and the Mohr-Coulomb parameters of the line:
//   phi = asin((b - 1) / (b + 1)),  c = a (1 - sin phi) / (2 cos phi).
struct MohrCoulombFit {
  double intercept_pa = 0.0;  // a: the unconfined strength of the line
  double slope = 0.0;         // b = (1 + sin phi) / (1 - sin phi)
  double friction_angle_deg = 0.0;
  double cohesion_pa = 0.0;
  double rms_residual_pa = 0.0;
  int points = 0;
  bool valid = false;  // b > 1 (a positive friction angle) and a > 0
};

// Needs at least two points with distinct confinements: InputError otherwise, or for
// vectors of different sizes.
MohrCoulombFit FitMohrCoulomb(const std::vector<double>& confining_stress_pa,
                              const std::vector<double>& peak_stress_pa);

}  // namespace specimen
