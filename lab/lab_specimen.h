#pragma once
// The specimen of a lab test (lab_test.h): its shape checked against the test, the loading
// axis, the extreme particle surfaces where the walls go, the lateral extent that enters the
// stress volume, and the particle sets of the strain region and of the kinematic (pure
// shear) boundary.
//
// Shapes: UCS on a rectangle (2D), cylinder or box (3D, axis z); Brazilian on a disc (2D)
// or cylinder (3D, axis z, loaded along y); biaxial, isotropic and pure shear on a
// rectangle (2D) or box (3D). The loading axis is y in 2D and z in 3D, except the
// Brazilian test (y). A packing "fills" its domain when its particles reach every side:
// the extreme particle surfaces lie within max(2 r_max, 2 % of the extent) of the domain's
// bounding box, and its nominal porosity is below 0.6.

#include <string>
#include <vector>

#include "generator/packing.h"
#include "lab/lab_test.h"

namespace specimen {

template <int Dim>
struct LabSpecimen {
  int axis = Dim - 1;  // loading axis
  // Extreme particle surfaces, min/max of x -/+ r per axis [m].
  Vector<Dim> lower = Vector<Dim>::Zero();
  Vector<Dim> upper = Vector<Dim>::Zero();
  double height_m = 0.0;  // upper - lower along the axis (BTS: the diameter D)
  // Area normal to the loading axis from the domain: 2D width x 1 m, 3D pi R^2 (cylinder)
  // or the x-y rectangle (box) [m^2].
  double cross_section_m2 = 0.0;
  double width_m = 0.0;      // 2D width, 3D diameter (cylinder) or x width (box)
  double thickness_m = 1.0;  // 2D 1 m; 3D Brazilian: cylinder length; 3D box: y depth
  double domain_volume_m3 = 0.0;
  double nominal_porosity = 0.0;
  double mean_radius_m = 0.0;  // volume-based (Labra (3.12))
  double max_radius_m = 0.0;
  // Bagi strain region: empty = every particle; else one flag per particle.
  std::vector<bool> strain_region;
  int rattlers = 0;  // particles with fewer than Dim contacts, left out of the strain region
  // Margin the strain region was selected with [mean radii]: the requested one, or 0 for a
  // Brazilian disc too thin for it (DescribeSpecimen).
  double strain_margin_mean_radii = 0.0;
  // Pure shear: the boundary particles (surface within 0.5 r_mean of the domain boundary).
  std::vector<int> boundary_particles;
};

// Throws InputError unless the domain has a shape the test accepts (header comment), naming
// the test, the shape and what it needs. DescribeSpecimen starts with it.
template <int Dim>
void CheckSpecimenShape(const Domain<Dim>& domain, LabTestKind kind);

// Checks the packing against the test and describes it. Throws InputError naming the
// test, the domain and what is wrong (wrong shape, a side the particles do not reach,
// porosity, too few particles or bonds, a strain margin that leaves no cell).
template <int Dim>
LabSpecimen<Dim> DescribeSpecimen(const Packing<Dim>& packing, LabTestKind kind,
                                  double strain_boundary_margin);

}  // namespace specimen
