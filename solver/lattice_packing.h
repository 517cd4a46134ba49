#pragma once
// The six-spring lattice on a generated packing: the nodes are the particle centres and the
// triangles those of the Delaunay triangulation of the centres (of all triangulations of
// those points, the one with the largest smallest angle), each with the natural stiffness of
// its own geometry and the material's D (six_spring_lattice.h). Every triangle is a
// constant-strain element, so a homogeneous strain gives the exact stress on any packing.
//
// Surface nodes: the centres stop about one radius short of the specimen's sides, and the
// hull of the centres is as rough as the boundary row of particles, which makes the moduli
// a platen measures depend on how that ragged edge is counted (about r / width; docs/sources.md,
// "On generated packings"). With `surface_nodes`, every particle of the boundary row gets a node
// at its foot on that side (where a platen or the specimen's surface touches it), and every
// corner of a polygon domain one: the lattice then fills the domain up to its straight sides
// (a disc: up to the polygon of the feet), and a uniaxial test on it is exact.
//
// Slivers: without surface nodes, along the straight sides of a specimen the boundary particles stand nearly in a
// row, and the triangulation closes the hull over them with flat triangles. Their stiffness
// grows as 1 / area and would set the critical time step, while they carry nothing the
// specimen needs. Hull triangles whose smallest angle is below `min_hull_angle_deg` are cut
// away, repeatedly (each cut exposes the triangle behind it). Interior triangles are kept:
// cutting one would open a hole in the solid.
//
//   PackingLatticeSummary summary;
//   PackingLattice lattice = BuildPackingLattice(packing, d, 1.0, {}, &summary);
//   Eigen::Vector3d sigma = TriangleStress(lattice.triangles, t, displacements);

#include <string>
#include <vector>

#include "generator/packing.h"
#include "solver/six_spring_lattice.h"

namespace specimen {

struct PackingLatticeOptions {
  // Nodes at the feet of the particles touching a side and at the domain's corners.
  bool surface_nodes = true;
  // A particle stands on a side when its gap to it is at most this share of the mean radius,
  // in [0, 1]: the default takes the whole boundary row, not only the particles in contact,
  // so that consecutive feet are about a particle apart.
  double surface_gap = 0.5;
  // Hull triangles with a smaller angle than this are cut away, in [0, 40] degrees (without
  // surface nodes only: with them the hull is the domain's sides, where nothing is cut).
  double min_hull_angle_deg = 20.0;

  bool IsValid(std::string* error) const;
};

struct PackingLatticeSummary {
  int triangles = 0;             // kept
  int hull_slivers_removed = 0;  // hull triangles cut away
  int surface_nodes = 0;         // feet and corners added
  int free_nodes = 0;            // nodes left in no triangle: they carry no lattice force
  double smallest_angle_deg = 0.0;  // of the kept triangles
  double covered_area_m2 = 0.0;     // the kept triangles' area (per thickness)

  std::string Describe() const;
};

// The nodes and triangles of a packing's lattice.
struct PackingLattice {
  TriangleLattice triangles;
  // Node i < particle_nodes is particle i's centre; the surface nodes follow.
  std::vector<Vector<2>> nodes;
  int particle_nodes = 0;
  // Per surface node (index i - particle_nodes): the domain facet it lies on and the
  // particle it is the foot of (-1: a corner, on that facet and the one before it).
  std::vector<int> surface_facet, surface_particle;

  int node_count() const { return static_cast<int>(nodes.size()); }
};

// The lattice of the Delaunay triangulation of the packing's centres (and surface nodes), with
// hull slivers cut away. InputError on invalid options or fewer than 3 non-collinear nodes.
PackingLattice BuildPackingLattice(const Packing<2>& packing, const PlaneElasticity& d, double thickness_m,
                                   const PackingLatticeOptions& options, PackingLatticeSummary* summary);
// The same on bare nodes (no surface nodes are added).
TriangleLattice BuildPointLattice(const std::vector<Vector<2>>& nodes, const PlaneElasticity& d, double thickness_m,
                                  const PackingLatticeOptions& options, PackingLatticeSummary* summary);

// The stress of triangle t at `displacements` (Voigt {sxx, syy, sxy}, tension positive): the
// virial of its three edge forces over its volume, sigma = 1/(A s) sum_k f_k L_k n_k (x) n_k,
// with the current edge vectors L_k n_k. For small strains it is the CST stress D eps of the
// triangle's constant strain.
Eigen::Vector3d TriangleStress(const TriangleLattice& lattice, int triangle,
                               const std::vector<Vector<2>>& displacements);

// The constant strain of triangle t (Voigt {exx, eyy, gamma_xy}) from its nodes'
// displacements (the CST's B u, at rest geometry).
Eigen::Vector3d TriangleStrain(const TriangleLattice& lattice, int triangle,
                               const std::vector<Vector<2>>& displacements);

}  // namespace specimen
