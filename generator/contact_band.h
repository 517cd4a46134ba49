#pragma once
// The contact band: the last densification stage of generate-packing when overlaps are kept
// (GeneratorOptions::contact_band_rounds). It raises the coordination number past what exact
// contacts allow.
//
// Why it is needed. With free radii, each exact contact is one equation and a particle has
// Dim + 1 unknowns. A packing of exact contacts is therefore capped near nc = 2 (Dim + 1)
// less its wall ties: 3D nc <= 8 - 2 Nb / N (README, "nc: the rigidity bound"). A contact
// of the output is a pair with |gap| <= contact_tolerance. When overlaps up to the overlap
// tolerance are allowed, each pair becomes two inequalities, -overlap <= gap <= contact,
// and far more pairs than (Dim + 1) N can satisfy them at once.
//
// The stage runs after the rounds:
//   1. refill, `refill_passes` times: particles with fewer than Dim + 1 contacts with other
//      particles are removed (rattlers, or held only by a wall that is gone downstream: they
//      lower nc), except those an earlier pass put in. Their holes are refilled by particles
//      tangent to the Dim + 1 particles or walls of a simplex, or, in a hole larger than
//      r_max, by an r_max particle at its centre (hole_filling.h).
//   2. band, `band_rounds` least-squares solves. Each solve pays only the part of a gap that
//      lies outside the band (densify.h, band_gap). The first solve takes every pair open by
//      at most `candidate_gap`. Later solves keep the pairs that came within twice the
//      contact tolerance, and every pair in contact. The rest are one-sided: they may not
//      overlap beyond the band, but nothing pulls them together.

#include <vector>

#include "common/progress.h"
#include "generator/densify.h"
#include "generator/generate.h"
#include "generator/hole_filling.h"

namespace specimen {

struct ContactBandOptions {
  // Band limits relative to the volume-based mean radius, measured at each step: pairs end
  // within kBandMargin (contact_band.cpp) of them, so a later small change of the mean
  // radius cannot push one out.
  double contact_tolerance = 0.02;
  double overlap_tolerance = 0.02;
  // Pairs open by at most this (relative to the mean radius) are pulled in by the first solve.
  double candidate_gap = 0.16;
  int refill_passes = 2;
  int band_rounds = 3;  // the third solve is a no-op when the second converged
  // Radius bounds, length scale, threads and iteration cap of the solves. The band fields
  // and the constraint flags are set by the stage.
  LevenbergMarquardtOptions solver;
  HoleFillingOptions hole_filling;  // for the refill
  double ghost_band = 0.0;          // for the contact graph (contact_graph.h)
};

// Runs the stage on the centres and radii in place; returns one record per step. Throws
// InputError for tolerances out of range and ComputationError if a solve cannot start.
// The refill alone (band_rounds 0) works on exact contacts too; the band solves need the
// overlaps kept afterwards (GeneratorOptions::keep_small_overlaps).
template <int Dim>
std::vector<GeneratorBandStep> RunContactBand(const Domain<Dim>& domain,
                                              const ContactBandOptions& options,
                                              std::vector<Vector<Dim>>& centres,
                                              std::vector<double>& radii,
                                              const ProgressCallback& progress = {});

}  // namespace specimen
