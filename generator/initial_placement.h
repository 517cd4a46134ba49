#pragma once
// Steps 1 and 2 of the generator (Labra section 3.2.4): nodes filling the domain at the
// spacing implied by the requested size, and Stienen-like initial radii.
//
// Nodes. Labra takes the interior nodes of a randomly perturbed finite-element mesh. We
// place nodes by random sequential addition (RSA) of exclusion spheres whose sizes are
// drawn over a spread (largest first), log-uniformly by default or from a power law: like
// a graded unstructured mesh, node spacing varies locally, but no lattice exists to
// survive into the packing. The size distribution is what bounds the density in 3D
// (measured, 30k spheres in the unit cylinder: Stienen radii on log-uniform nodes over a
// spread of 3 end at 34.1 %; the node spheres of a power law s^-3.5 over a spread of 8
// taken as the radii, at 26.3 %; README, generator benchmark). Deterministic for a given
// seed.

#include <random>
#include <vector>

#include "generator/domain.h"

namespace specimen {

template <int Dim>
struct NodeSet {
  std::vector<Vector<Dim>> positions;
  std::vector<double> exclusion_radii;  // the RSA sphere of each node (local spacing / 2)
};

// Random sequential addition of `target_count` exclusion spheres with radii distributed
// over [a, a * size_spread] with number density ~ s^-size_exponent (1: log-uniform; 4 in
// 3D: equal solid volume per size decade), `a` chosen so that they would fill
// `fill_fraction` of the domain; each sphere lies inside the domain and overlaps no other. Spheres that find no
// place within `attempts_per_node` trials are dropped, so the result may hold slightly
// fewer nodes than asked.
template <int Dim>
NodeSet<Dim> RandomSequentialNodes(const Domain<Dim>& domain, int target_count, double size_spread,
                                   double size_exponent, double fill_fraction, int attempts_per_node,
                                   std::mt19937_64& rng);

// Truncated power law on [1, spread] with density ~ s^-exponent: draws a size from a
// uniform number u in [0, 1) (inverse transform), and the moment E[s^k].
double PowerLawSize(double spread, double exponent, double u);
double PowerLawMoment(double spread, double exponent, double k);

// Step 2, Stienen-like radii: each node takes its share of the distance to each Delaunay
// neighbour in proportion to the exclusion radii (d_ij rho_i / (rho_i + rho_j)); the mean
// over the nearer half of the neighbours, times a uniform random factor in
// [factor_min, factor_max], clamped to [radius_min, radius_max].
template <int Dim>
std::vector<double> StienenRadii(const Domain<Dim>& domain, const NodeSet<Dim>& nodes,
                                 double factor_min, double factor_max, double radius_min,
                                 double radius_max, std::mt19937_64& rng);

}  // namespace specimen
