#include "calibrate/surrogate.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace specimen {

CalibrationSurrogate::CalibrationSurrogate(const MapSet& maps, const PackingDescriptors& ucs,
                                           const PackingDescriptors& bts)
    : maps_(maps), lower_(maps.Lower()), upper_(maps.Upper()) {
  if (maps_.inputs.empty()) throw InputError("the maps have no varying micro ratio");
  for (MicroRatio r : maps_.inputs)
    strength_only_.push_back(r == MicroRatio::kStrengthRatio || r == MicroRatio::kFriction);
  // Labra (4.49), (4.56), (4.57) solved for E / kn and sigma / Rn.
  youngs_factor_ = ucs.SolidCoordination() / ucs.CharacteristicRadius();
  ucs_factor_ = ucs.SolidCoordination() / ucs.CharacteristicArea();
  tensile_factor_ = bts.SolidCoordination() / bts.CharacteristicArea();
}

Eigen::VectorXd CalibrationSurrogate::Inputs(const MicroRatios& ratios) const {
  const std::vector<double> x = maps_.InputsOf(ratios);
  Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
  return v.cwiseMax(lower_).cwiseMin(upper_);
}

Eigen::VectorXd CalibrationSurrogate::Scaled(const Eigen::VectorXd& inputs) const {
  Eigen::VectorXd s(inputs.size());
  for (Eigen::Index k = 0; k < inputs.size(); ++k) {
    const double width = upper_[k] - lower_[k];
    s[k] = width > 0.0 ? (inputs[k] - lower_[k]) / width : 0.0;
  }
  return s;
}

double CalibrationSurrogate::MapValue(Quantity q, const Eigen::VectorXd& x) const {
  switch (q) {
    case kElastic: return std::log(std::max(1e-12, maps_.elastic_group.Evaluate(x)) * youngs_factor_);
    case kPoisson: return maps_.poisson_ratio.Evaluate(x);
    case kCompressive: return std::log(std::max(1e-12, maps_.compressive_group.Evaluate(x)) * ucs_factor_);
    case kTensile: return std::log(std::max(1e-12, maps_.tensile_group.Evaluate(x)) * tensile_factor_);
  }
  return 0.0;
}

void CalibrationSurrogate::AddMeasurement(const SurrogateMeasurement& m, bool stored) {
  Anchor a;
  const Eigen::VectorXd x = Inputs(m.ratios);
  a.scaled = Scaled(x);
  a.weight = stored ? kStoredWeight : 1.0;
  a.stored = stored;
  if (m.youngs_per_stiffness > 0.0) {
    a.has_elastic = true;
    a.delta[kElastic] = std::log(m.youngs_per_stiffness) - MapValue(kElastic, x);
    a.delta[kPoisson] = m.poisson_ratio - MapValue(kPoisson, x);
  }
  if (m.ucs_per_strength > 0.0 && m.tensile_per_strength > 0.0) {
    a.has_strength = true;
    a.delta[kCompressive] = std::log(m.ucs_per_strength) - MapValue(kCompressive, x);
    a.delta[kTensile] = std::log(m.tensile_per_strength) - MapValue(kTensile, x);
    a.log_ratio = std::log(m.ucs_per_strength / m.tensile_per_strength);
  }
  a.ratios = m.ratios;
  if (a.has_elastic || a.has_strength) points_.push_back(a);
  if (stored) stored_.push_back(m);
  Decluster();
}

// The rounds of a calibration cluster at one elastic set (its strength rounds differ in Rt/Rn
// and mu only), and they share that set's error of the maps. Counted one by one they would
// outweigh every other anchor away from the set, however far: cell declustering gives each
// elastic point the weight of its heaviest anchor, shared in proportion to the anchors' own.
void CalibrationSurrogate::Decluster() {
  auto same_elastic_point = [this](const Anchor& a, const Anchor& b) {
    for (Eigen::Index k = 0; k < a.scaled.size(); ++k)
      if (!strength_only_[k] && std::abs(a.scaled[k] - b.scaled[k]) > 1e-9) return false;
    return true;
  };
  for (Anchor& a : points_) {
    double elastic_sum = 0.0, elastic_max = 0.0, strength_sum = 0.0, strength_max = 0.0;
    for (const Anchor& b : points_) {
      if (!same_elastic_point(a, b)) continue;
      if (b.has_elastic) elastic_sum += b.weight, elastic_max = std::max(elastic_max, b.weight);
      if (b.has_strength) strength_sum += b.weight, strength_max = std::max(strength_max, b.weight);
    }
    a.elastic_share = a.has_elastic ? elastic_max / elastic_sum : 1.0;
    a.strength_share = a.has_strength ? strength_max / strength_sum : 1.0;
  }
}

template <typename Value>
double CalibrationSurrogate::ShepardMean(const Eigen::VectorXd& x, bool elastic, const MicroRatio* line,
                                         Value value) const {
  const Eigen::VectorXd s = Scaled(x);
  int line_input = -1;
  if (line)
    for (size_t k = 0; k < maps_.inputs.size(); ++k)
      if (maps_.inputs[k] == *line) line_input = static_cast<int>(k);
  double sum = 0.0, weights = 0.0;
  for (const Anchor& a : points_) {
    if (elastic ? !a.has_elastic : !a.has_strength) continue;
    double d2 = 0.0, off_line = 0.0;
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      if (elastic && strength_only_[k]) continue;
      const double d = (s[k] - a.scaled[k]) * (s[k] - a.scaled[k]);
      d2 += d;
      if (k != line_input) off_line += d;
    }
    if (line && off_line <= 1e-18) continue;  // on the line
    const double w = a.weight * (elastic ? a.elastic_share : a.strength_share) / (d2 + kSmoothing * kSmoothing);
    sum += w * value(a);
    weights += w;
  }
  return weights > 0.0 ? sum / weights : 0.0;
}

double CalibrationSurrogate::Correction(Quantity q, const Eigen::VectorXd& x, const MicroRatio* line) const {
  return ShepardMean(x, q == kElastic || q == kPoisson, line, [q](const Anchor& a) { return a.delta[q]; });
}

double CalibrationSurrogate::YoungsPerStiffness(const MicroRatios& r, const MicroRatio* line) const {
  const Eigen::VectorXd x = Inputs(r);
  return std::exp(MapValue(kElastic, x) + Correction(kElastic, x, line));
}
double CalibrationSurrogate::Poisson(const MicroRatios& r, const MicroRatio* line) const {
  const Eigen::VectorXd x = Inputs(r);
  return MapValue(kPoisson, x) + Correction(kPoisson, x, line);
}
double CalibrationSurrogate::UcsPerStrength(const MicroRatios& r, const MicroRatio* line) const {
  const Eigen::VectorXd x = Inputs(r);
  return std::exp(MapValue(kCompressive, x) + Correction(kCompressive, x, line));
}
double CalibrationSurrogate::TensilePerStrength(const MicroRatios& r, const MicroRatio* line) const {
  const Eigen::VectorXd x = Inputs(r);
  return std::exp(MapValue(kTensile, x) + Correction(kTensile, x, line));
}

double CalibrationSurrogate::LogGridRatio(const MicroRatios& r) const {
  return grid_.LogGroupRatio(r) + std::log(ucs_factor_ / tensile_factor_);
}

double CalibrationSurrogate::GridStrengthRatio(const MicroRatios& r, const MicroRatio* line) const {
  if (!grid_.valid()) return StrengthRatio(r, line);
  const double correction =
      ShepardMean(Inputs(r), false, line, [this](const Anchor& a) { return a.log_ratio - LogGridRatio(a.ratios); });
  return std::exp(LogGridRatio(r) + correction);
}

double CalibrationSurrogate::MapGridStrengthRatio(const MicroRatios& r) const {
  if (!grid_.valid()) return MapUcsPerStrength(r) / MapTensilePerStrength(r);
  return std::exp(LogGridRatio(r));
}

double CalibrationSurrogate::MapYoungsPerStiffness(const MicroRatios& r) const {
  return std::exp(MapValue(kElastic, Inputs(r)));
}
double CalibrationSurrogate::MapPoisson(const MicroRatios& r) const { return MapValue(kPoisson, Inputs(r)); }
double CalibrationSurrogate::MapUcsPerStrength(const MicroRatios& r) const {
  return std::exp(MapValue(kCompressive, Inputs(r)));
}
double CalibrationSurrogate::MapTensilePerStrength(const MicroRatios& r) const {
  return std::exp(MapValue(kTensile, Inputs(r)));
}

double CalibrationSurrogate::RatioCorrection(const Anchor& a) const {
  return grid_.valid() ? a.log_ratio - LogGridRatio(a.ratios) : a.delta[kCompressive] - a.delta[kTensile];
}

std::vector<double> CalibrationSurrogate::StoredStrengthRatioCorrections() const {
  std::vector<double> out;
  for (const Anchor& a : points_)
    if (a.stored && a.has_strength) out.push_back(RatioCorrection(a));
  return out;
}

std::vector<double> CalibrationSurrogate::StoredStrengthRatioLeaveOneOut() const {
  std::vector<double> out;
  for (const Anchor& a : points_) {
    if (!a.stored || !a.has_strength) continue;
    double sum = 0.0, weights = 0.0;
    for (const Anchor& b : points_) {
      if (&b == &a || !b.stored || !b.has_strength) continue;
      const double w = b.weight / ((a.scaled - b.scaled).squaredNorm() + kSmoothing * kSmoothing);
      sum += w * RatioCorrection(b);
      weights += w;
    }
    if (weights > 0.0) out.push_back(RatioCorrection(a) - sum / weights);
  }
  return out;
}

bool CalibrationSurrogate::Varies(MicroRatio ratio) const {
  for (size_t k = 0; k < maps_.inputs.size(); ++k)
    if (maps_.inputs[k] == ratio) return upper_[k] > lower_[k];
  return false;
}

double CalibrationSurrogate::Lower(MicroRatio ratio) const {
  for (size_t k = 0; k < maps_.inputs.size(); ++k)
    if (maps_.inputs[k] == ratio) return lower_[k];
  return RatioValue(maps_.fixed, ratio);
}

double CalibrationSurrogate::Upper(MicroRatio ratio) const {
  for (size_t k = 0; k < maps_.inputs.size(); ++k)
    if (maps_.inputs[k] == ratio) return upper_[k];
  return RatioValue(maps_.fixed, ratio);
}

}  // namespace specimen
