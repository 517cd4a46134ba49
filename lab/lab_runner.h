#pragma once
// One run of a lab test at one platen speed: the scene (walls, servo, kinematic boundary),
// the consolidation of a confined test, the loading loop with its samples, broken-bond
// tracking and snapshots, and the measurement at the end. RunLabTest (lab_test.cpp)
// validates, scales the density and sets the damping, calls this, and repeats it at half
// the speed for the quasi-static check.

#include "lab/lab_specimen.h"
#include "lab/lab_test.h"

namespace specimen {

// `material` is the one the simulation uses (density and damping already set); `speed` is
// the platen speed V [m/s]; `strain_limit` the resolved limit (> 0).
template <int Dim>
LabTestResult RunLabTestAtSpeed(const Packing<Dim>& packing, const LabSpecimen<Dim>& specimen,
                                const MaterialParameters& material,
                                const LabTestOptions& options, double speed,
                                double strain_limit);

// The wave speed scale of the loading-rate group: sqrt(kn / rho) in 2D (kn per unit
// thickness), sqrt(kn / (rho r_mean)) in 3D [m/s].
template <int Dim>
double WaveSpeedScale(const MaterialParameters& material, double mean_radius_m);

}  // namespace specimen
