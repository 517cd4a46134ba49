#include "lab/lab_specimen.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/error.h"
#include "common/format.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The shapes each test accepts, as a phrase for messages.
std::string AcceptedShapes(LabTestKind kind) {
  switch (kind) {
    case LabTestKind::kUniaxialCompression:
      return "a rectangle (2D) or a cylinder or box (3D)";
    case LabTestKind::kBrazilian:
      return "a disc (2D) or a cylinder (3D)";
    default:
      return "a rectangle (2D) or a box (3D)";
  }
}

bool ShapeFits(LabTestKind kind, DomainShape shape) {
  switch (kind) {
    case LabTestKind::kUniaxialCompression:
      return shape == DomainShape::kRectangle || shape == DomainShape::kCylinder ||
             shape == DomainShape::kBox;
    case LabTestKind::kBrazilian:
      return shape == DomainShape::kDisc || shape == DomainShape::kCylinder;
    default:
      return shape == DomainShape::kRectangle || shape == DomainShape::kBox;
  }
}

}  // namespace

template <int Dim>
void CheckSpecimenShape(const Domain<Dim>& domain, LabTestKind kind) {
  if (!ShapeFits(kind, domain.shape()))
    throw InputError(std::string("test '") + LabTestKindName(kind) + "' needs a specimen that is " +
                     AcceptedShapes(kind) + "; the packing's domain is a " + domain.ShapeName() +
                     " (" + domain.ToShortText() + "): generate the packing in the test's shape");
}

template <int Dim>
LabSpecimen<Dim> DescribeSpecimen(const Packing<Dim>& packing, LabTestKind kind,
                                  double strain_boundary_margin) {
  const Domain<Dim>& domain = packing.domain;
  CheckSpecimenShape<Dim>(domain, kind);
  const std::string test = std::string("test '") + LabTestKindName(kind) + "'";
  const std::string where = test + " on the packing's " + domain.ShapeName() + " domain (" +
                            domain.ToShortText() + ")";
  if (packing.size() < 2 * (Dim + 1))
    throw InputError(where + ": " + std::to_string(packing.size()) +
                     " particles are too few for a specimen (" + std::to_string(2 * (Dim + 1)) +
                     " at least)");
  if (packing.contacts.empty())
    throw InputError(where + ": the packing has no contacts, so the specimen has no bonds");

  LabSpecimen<Dim> s;
  s.axis = kind == LabTestKind::kBrazilian ? 1 : Dim - 1;
  s.lower = Vector<Dim>::Constant(std::numeric_limits<double>::infinity());
  s.upper = -s.lower;
  double solid = 0.0;
  for (int q = 0; q < packing.size(); ++q) {
    const double r = packing.radii[q];
    s.lower = s.lower.cwiseMin(packing.centres[q] - Vector<Dim>::Constant(r));
    s.upper = s.upper.cwiseMax(packing.centres[q] + Vector<Dim>::Constant(r));
    solid += ParticleVolume<Dim>(r);
    s.max_radius_m = std::max(s.max_radius_m, r);
  }
  s.mean_radius_m = VolumeMeanRadius<Dim>(packing.radii);
  s.domain_volume_m3 = domain.Volume();
  s.nominal_porosity = 1.0 - solid / s.domain_volume_m3;

  // Does the packing fill its domain? Every side of the bounding box must be reached.
  static const char* const kSide[3][2] = {{"x min", "x max"}, {"y min", "y max"}, {"z min", "z max"}};
  for (int a = 0; a < Dim; ++a) {
    const double extent = domain.Upper()[a] - domain.Lower()[a];
    const double tolerance = std::max(2.0 * s.max_radius_m, 0.02 * extent);
    const double gaps[2] = {s.lower[a] - domain.Lower()[a], domain.Upper()[a] - s.upper[a]};
    for (int side = 0; side < 2; ++side)
      if (gaps[side] > tolerance)
        throw InputError(where + ": the particles do not fill the domain: they stop " +
                         Number(gaps[side]) + " m short of its " + kSide[a][side] +
                         " side (allowed " + Number(tolerance) +
                         " m); use a packing generated in this domain");
  }
  if (s.nominal_porosity > 0.6)
    throw InputError(where + ": the particles do not fill the domain: nominal porosity " +
                     Number(s.nominal_porosity) + " is above 0.6");

  // Extents and the cross-section the stress volume uses.
  s.height_m = s.upper[s.axis] - s.lower[s.axis];
  const Vector<Dim> size = domain.Upper() - domain.Lower();
  if constexpr (Dim == 2) {
    s.width_m = domain.shape() == DomainShape::kDisc ? 2.0 * domain.CircleRadius() : size.x();
    s.thickness_m = 1.0;
    s.cross_section_m2 = s.width_m;  // x 1 m
  } else {
    if (domain.shape() == DomainShape::kCylinder) {
      s.width_m = 2.0 * domain.CircleRadius();
      s.cross_section_m2 = kPi * domain.CircleRadius() * domain.CircleRadius();
      s.thickness_m = kind == LabTestKind::kBrazilian ? size.z() : s.width_m;
    } else {
      s.width_m = size.x();
      s.thickness_m = size.y();
      s.cross_section_m2 = size.x() * size.y();
    }
  }

  // Strain region: the particles of the load-carrying skeleton (at least Dim contacts, so
  // held by their bonds: a particle with fewer is a rattler whose displacement does not
  // follow the specimen's, and on the boundary of the triangulated region it would carry
  // the weight of a boundary vertex) at least the margin inside the domain.
  std::vector<int> contacts(packing.size(), 0);
  for (const auto& c : packing.contacts) {
    ++contacts[c[0]];
    ++contacts[c[1]];
  }
  auto select_region = [&](double margin) {
    s.strain_region.assign(packing.size(), true);
    s.rattlers = 0;
    int inside = 0;
    for (int q = 0; q < packing.size(); ++q) {
      if (contacts[q] < Dim) {
        s.strain_region[q] = false;
        ++s.rattlers;
      } else if (margin > 0.0) {
        s.strain_region[q] = domain.SignedDistance(packing.centres[q]) >= margin * s.mean_radius_m;
      }
      inside += s.strain_region[q] ? 1 : 0;
    }
    s.strain_margin_mean_radii = margin;
    return inside;
  };
  int inside = select_region(strain_boundary_margin);
  // The Brazilian strength is the platen force (Labra (4.38)); its strain only draws the
  // curve. A thin 3D disc of coarse spheres (a map specimen) may have no particle 4 radii
  // from every face: measure it over the whole skeleton instead of refusing the test.
  if (inside < 2 * (Dim + 1) && kind == LabTestKind::kBrazilian) inside = select_region(0.0);
  if (inside < 2 * (Dim + 1))
    throw InputError("strain_boundary_margin = " + Number(strain_boundary_margin) +
                     " mean radii leaves " + std::to_string(inside) +
                     " particles inside the specimen: it must leave a region to measure");
  if (inside == packing.size()) s.strain_region.clear();  // every particle
  if (kind == LabTestKind::kPureShear)
    for (int q = 0; q < packing.size(); ++q)
      if (domain.SignedDistance(packing.centres[q]) - packing.radii[q] < 0.5 * s.mean_radius_m)
        s.boundary_particles.push_back(q);
  return s;
}

template void CheckSpecimenShape<2>(const Domain<2>&, LabTestKind);
template void CheckSpecimenShape<3>(const Domain<3>&, LabTestKind);
template LabSpecimen<2> DescribeSpecimen<2>(const Packing<2>&, LabTestKind, double);
template LabSpecimen<3> DescribeSpecimen<3>(const Packing<3>&, LabTestKind, double);

}  // namespace specimen
