#pragma once
// The sweep's own points as a map of sigma_c / sigma_t: on the full-factorial grid of the
// sweep design, the tensor-product interpolant through every point (per axis, the quadratic
// through the three nearest levels; geometric axes such as Rt/Rn in logarithms). Exact at the
// points, where the fitted surfaces (response_surface.h, total degree 2) miss the shipped
// compressive groups by 0.13-0.17 in ln (rms residual): on the DDEM maps sigma_c / sigma_t at
// Rt/Rn 10 peaks inside the kt/kn axis (13.1, 19.7, 11.5 at kt/kn 0.15, 0.375, 0.6), a shape
// the fitted surfaces flatten.
// Used to rank the elastic sets that give a target's nu by the strength ratio they reach
// (calibration_solver.h); the strength rounds themselves follow the corrected surfaces.
//
//   SweepGrid grid(stored.design, stored.points);
//   if (grid.valid()) double g = grid.LogGroupRatio(ratios);  // ln(Psi_c / Psi_t)

#include <vector>

#include "calibrate/map_set.h"

namespace specimen {

struct SweepDesign;
struct SweepPoint;

class SweepGrid {
 public:
  SweepGrid() = default;
  // Not valid() unless every point of the design's grid was measured (ok, both groups > 0).
  SweepGrid(const SweepDesign& design, const std::vector<SweepPoint>& points);

  bool valid() const { return !nodes_.empty(); }
  // ln(Psi_c / Psi_t) at `ratios`, each axis clamped to its levels' range.
  double LogGroupRatio(const MicroRatios& ratios) const;

 private:
  struct Axis {
    MicroRatio ratio = MicroRatio::kStiffnessRatio;
    bool logarithmic = false;
    std::vector<double> levels;  // coordinates, increasing
    int stride = 1;              // in nodes_
  };
  std::vector<Axis> axes_;
  std::vector<double> nodes_;  // ln(Psi_c / Psi_t), in design order (first axis slowest)
};

}  // namespace specimen
