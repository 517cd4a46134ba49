#pragma once
// Steps 1 and 2 of the generator (Labra section 3.2.1): nodes filling the domain at the
// spacing implied by the requested size, and Stienen-like initial radii.
//
// Nodes: Labra uses the interior nodes of a randomly perturbed finite-element mesh. We
// use maximal Poisson-disc sampling (Bridson 2007) instead: it gives the same thing a
// good unstructured mesher gives (nodes at a nearly uniform spacing, every node with
// 5-7 Delaunay neighbours in 2D) with no lattice left in it, so no crystalline order
// can survive into the packing, at O(N) cost and with a seed that makes it repeatable.

#include <cstdint>
#include <random>
#include <vector>

#include "generator/domain.h"

namespace specimen {

// Maximal Poisson-disc sample of the domain: points at least `spacing` apart and at least
// `boundary_margin` inside the boundary. Deterministic for a given rng state.
template <int Dim>
std::vector<Vector<Dim>> PoissonDiscSample(const Domain<Dim>& domain, double spacing,
                                           double boundary_margin, std::mt19937_64& rng);

// Poisson-disc sample with about `target_count` points (within a few per cent): the
// spacing is found from a first sample and corrected once.
template <int Dim>
std::vector<Vector<Dim>> PoissonDiscSampleWithCount(const Domain<Dim>& domain, int target_count,
                                                    std::mt19937_64& rng);

// Step 2, Stienen-like radii: half the mean distance from each node to its Delaunay
// neighbours, times a uniform random factor in [factor_min, factor_max], clamped to
// [radius_min, radius_max].
template <int Dim>
std::vector<double> StienenRadii(const Domain<Dim>& domain, const std::vector<Vector<Dim>>& nodes,
                                 double factor_min, double factor_max, double radius_min,
                                 double radius_max, std::mt19937_64& rng);

}  // namespace specimen
