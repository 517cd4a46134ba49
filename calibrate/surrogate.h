#pragma once
// The maps as a prediction of what the real specimens measure, corrected by what they did
// measure (output space mapping). The fitted surfaces (map_sweep.h) are built on smaller map
// specimens; their offsets do not transfer to the real ones exactly (strength by 10-25 %),
// but their trends do. Every measurement on a real specimen (a verification stored with the
// maps, or a run of this calibration) is a sample of the true map, and the difference to the
// surface there is carried over to nearby points:
//
//   q_corrected(x) = q_map(x) + delta(x),   delta(x) = sum_i w_i(x) delta_i / sum_i w_i(x)
//
// for q = ln(E / kn), nu, ln(sigma_c / Rn), ln(sigma_t / Rn) (logarithms: the transfer error
// of a group is a factor), with Shepard weights w_i = g_i / (d_i^2 + eps^2), d_i the distance
// in the maps' box scaled to [0, 1] per axis (the elastic quantities ignore the strength-only
// axes Rt/Rn and mu, on which they do not depend). Far from every measurement the correction
// tends to their weighted mean, the average transfer factor. The calibration loop adds the
// exact line correction of its own rounds on top (calibration_solver.h).
//
//   CalibrationSurrogate s(maps, ucs_descriptors, bts_descriptors);
//   s.AddMeasurement(point, /*stored=*/true);        // from the map file
//   double nu = s.Poisson(ratios);                   // corrected prediction

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/map_set.h"
#include "calibrate/sweep_grid.h"

namespace specimen {

// A measurement on the real specimens at one point of the ratios. Elastic runs leave the
// strengths at 0; strength rounds may carry the elastic constants of their point.
struct SurrogateMeasurement {
  MicroRatios ratios;
  double youngs_per_stiffness = 0.0;  // E / kn [m^-1 in 3D; dimensionless in 2D], 0 = none
  double poisson_ratio = 0.0;         // used when youngs_per_stiffness > 0
  double ucs_per_strength = 0.0;      // sigma_c / Rn [Pa/N], 0 = none
  double tensile_per_strength = 0.0;  // sigma_t / Rn [Pa/N], used with ucs_per_strength
};

class CalibrationSurrogate {
 public:
  // Weight of a measurement stored with the maps relative to one of this calibration: stored
  // ones come from other targets, hence other points, and may predate small protocol changes.
  static constexpr double kStoredWeight = 0.2;
  // eps of the weights, in box-scaled units.
  static constexpr double kSmoothing = 0.05;

  CalibrationSurrogate() = default;
  CalibrationSurrogate(const MapSet& maps, const PackingDescriptors& ucs_specimen,
                       const PackingDescriptors& bts_specimen);

  void AddMeasurement(const SurrogateMeasurement& m, bool stored);
  int measurements() const { return static_cast<int>(points_.size()); }

  // Corrected predictions on the real specimens at `ratios` (inputs outside the box are
  // clamped to it). E / kn and the strengths per unit Rn follow from the groups and the
  // specimens' descriptors (dimensionless_groups.h). With `line`, the measurements on the
  // line through `ratios` along that ratio are left out: a 1D solve along it corrects by
  // those exactly (piecewise linear through them, calibration_solver.h), whereas the
  // weights here flatten the slope at every measured point.
  double YoungsPerStiffness(const MicroRatios& ratios, const MicroRatio* line = nullptr) const;
  double Poisson(const MicroRatios& ratios, const MicroRatio* line = nullptr) const;
  double UcsPerStrength(const MicroRatios& ratios, const MicroRatio* line = nullptr) const;
  double TensilePerStrength(const MicroRatios& ratios, const MicroRatio* line = nullptr) const;
  // sigma_c / sigma_t, independent of Rn.
  double StrengthRatio(const MicroRatios& ratios, const MicroRatio* line = nullptr) const {
    return UcsPerStrength(ratios, line) / TensilePerStrength(ratios, line);
  }

  // The sweep's own points (sweep_grid.h), when the maps come with them.
  void SetSweepGrid(SweepGrid grid) { grid_ = std::move(grid); }
  bool HasSweepGrid() const { return grid_.valid(); }
  // sigma_c / sigma_t on the real specimens from the sweep grid, corrected as above by the
  // measurements (ln of the measured ratio minus the grid's at each; `line` as above);
  // StrengthRatio without a grid.
  double GridStrengthRatio(const MicroRatios& ratios, const MicroRatio* line = nullptr) const;

  // The same from the fitted surfaces alone (the transfer error is measured against these).
  double MapYoungsPerStiffness(const MicroRatios& ratios) const;
  double MapPoisson(const MicroRatios& ratios) const;
  double MapUcsPerStrength(const MicroRatios& ratios) const;
  double MapTensilePerStrength(const MicroRatios& ratios) const;
  // The sweep grid's sigma_c / sigma_t uncorrected (the fitted surfaces' without a grid).
  double MapGridStrengthRatio(const MicroRatios& ratios) const;

  // ln(sigma_c / sigma_t) measured minus the sweep grid's value (the surfaces' without a
  // grid), at each stored measurement with strengths: how far, and how uniformly, the ratio
  // transfers from the map specimens.
  std::vector<double> StoredStrengthRatioCorrections() const;
  // The same corrections each minus what the other stored measurements predict for it (their
  // Shepard mean at its point): the error of the corrected ratio where nothing was measured.
  std::vector<double> StoredStrengthRatioLeaveOneOut() const;
  // The measurements stored with the maps, as given.
  const std::vector<SurrogateMeasurement>& stored_measurements() const { return stored_; }

  const MapSet& maps() const { return maps_; }
  // The box of a ratio in the maps (lower == upper == the fixed value when it does not vary).
  double Lower(MicroRatio ratio) const;
  double Upper(MicroRatio ratio) const;
  bool Varies(MicroRatio ratio) const;

 private:
  enum Quantity { kElastic = 0, kPoisson = 1, kCompressive = 2, kTensile = 3 };
  struct Anchor {
    Eigen::VectorXd scaled;  // inputs scaled to the box
    double delta[4] = {0, 0, 0, 0};
    MicroRatios ratios;
    double log_ratio = 0.0;  // ln(sigma_c / sigma_t) measured, with has_strength
    bool has_elastic = false, has_strength = false;
    double weight = 1.0;
    // weight's share of its elastic point's (the anchors, with elastic or with strength data, at
    // the same kt/kn, kn/(Ep l), ...): see Decluster.
    double elastic_share = 1.0, strength_share = 1.0;
    bool stored = false;
  };
  // The shares above, after each measurement: an elastic point weighs as its heaviest anchor.
  void Decluster();
  Eigen::VectorXd Inputs(const MicroRatios& ratios) const;  // clamped to the box
  Eigen::VectorXd Scaled(const Eigen::VectorXd& inputs) const;
  double MapValue(Quantity q, const Eigen::VectorXd& inputs) const;
  double Correction(Quantity q, const Eigen::VectorXd& inputs, const MicroRatio* line) const;
  // sum w_i v(a_i) / sum w_i over the anchors with elastic (or strength) data, those on
  // `line` through `inputs` left out; 0 when none.
  template <typename Value>
  double ShepardMean(const Eigen::VectorXd& inputs, bool elastic, const MicroRatio* line, Value value) const;
  // ln(sigma_c / sigma_t) measured at `a` minus the grid's (the surfaces' without a grid).
  double RatioCorrection(const Anchor& a) const;
  // ln of the grid's ratio on the real specimens, uncorrected.
  double LogGridRatio(const MicroRatios& ratios) const;

  MapSet maps_;
  Eigen::VectorXd lower_, upper_;
  std::vector<bool> strength_only_;  // per input: Rt/Rn, mu
  double youngs_factor_ = 0.0;       // E / kn = Psi_E x this
  double ucs_factor_ = 0.0, tensile_factor_ = 0.0;  // sigma / Rn = Psi x these
  std::vector<Anchor> points_;
  SweepGrid grid_;
  std::vector<SurrogateMeasurement> stored_;
};

}  // namespace specimen
