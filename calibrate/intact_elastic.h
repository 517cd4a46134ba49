#pragma once
// The elastic constants a calibration matches to a rock's E and nu: those of the intact
// specimen, the average modulus of the linear portion in the ISRM suggested method
// (Bieniawski & Bernede 1979; ASTM D7012 method B calls it the average modulus). A bonded
// specimen is linear until its first bond breaks, so an elastic run is the UCS with
// unbreakable bonds to an axial strain of 1.5e-3, sampled every 50 steps, read by
// lab_measurement.h LinearPortionElasticConstants (least squares over 20-100 % of the largest
// stress). It gives what the intact part of a test to failure gives (5,064 discs, Labra's
// stiffnesses: nu 0.20115 against 0.20121; 0.2011 at half the rate; E within 0.05 %), at
// about 6,000 steps instead of 180,000, and depends on kn, kt and the DDEM particle
// elasticity only: never on the bond strengths.
//
// Why not Labra's 1-50 % secant: bonds start to break at 40-45 % of the peak, so that secant
// moves with Rn and Rt/Rn as much as with kt/kn (nu 0.37 instead of 0.20 with his
// parameters), and a calibration of nu by kt/kn then fights the strength corrections.

#include "calibrate/forward_model.h"
#include "generator/packing.h"
#include "lab/lab_test.h"
#include "solver/material.h"

namespace specimen {

// The protocol of an elastic run: `protocol` with strain_limit 1.5e-3, a sample every 50
// steps, no quasi-static check, no snapshots.
LabTestOptions ElasticRunOptions(const LabTestOptions& protocol);

// The elastic constants of the intact specimen at `material` (its bond strengths are made
// infinite). ComputationError when the linear portion was not measured.
template <int Dim>
ElasticMeasurement MeasureIntactElasticConstants(const Packing<Dim>& ucs_specimen, MaterialParameters material,
                                                 const LabTestOptions& protocol);

}  // namespace specimen
