#pragma once
// Pictures of a packing, drawn by gnuplot from CSV files written first (docs/generator.md,
// "Outputs"), so a user can restyle them from the same numbers:
//   <prefix>_particles.csv (x_m, y_m, [z_m,] radius_m) and, for small packings,
//       <prefix>_contacts.csv (i, j and both centres); <prefix>_packing.png (2D only): the
//       discs to scale, coloured by radius, with the domain outline and the contacts.
//   <prefix>_radii.csv, <prefix>_radius_histogram.png: particle counts per radius bin and
//       the share of the particle volume in each bin.
//   <prefix>_orientation.csv, <prefix>_orientation_rose.png: the contact-orientation
//       histogram(s) of PackingMetrics as a polar curve. Contacts have no direction, so
//       the bins over [0, 180) are repeated over [180, 360). 3D: projections onto the xy,
//       xz and yz planes, one curve each.
// Without gnuplot the CSV files are still written and the pictures are reported skipped.

#include <string>
#include <vector>

#include "common/plot.h"
#include "generator/metrics.h"
#include "generator/packing.h"

namespace specimen {

struct PackingPicturesOptions {
  // Bins of the radius histogram; 0 = automatic: ceil(sqrt(N)), at most 40. A packing of
  // equal radii gets one bin, [0.95 r, 1.05 r], so the bar has a width.
  int radius_bins = 0;
  // Render the PNG files with gnuplot; false writes only the CSV files they are drawn from
  // (generate-packing --no-pictures).
  bool draw = true;
  // Contacts are drawn (2D) only for packings of fewer particles than this: above it the
  // lines are sub-pixel and slow to draw. <prefix>_contacts.csv holds them at every size.
  int contact_drawing_limit = 5000;
  // Width of the packing picture in pixels; the height follows the domain's aspect ratio.
  int packing_picture_width_px = 1000;
  PlotOptions histogram_plot = {1000, 700};
  PlotOptions rose_plot = {900, 900};

  // False with a message naming the field if an option is out of range.
  bool IsValid(std::string* error) const;
};

// What WritePackingPictures produced.
struct PicturesWritten {
  std::vector<std::string> files;     // every file written (CSV and PNG), in order
  std::vector<std::string> warnings;  // pictures skipped and why; the CSVs are still there
};

// Writes the CSV files and pictures listed above, each atomically. From `metrics` it reads
// particle_count (must equal the packing's), orientation_histograms (1 row in 2D; 3 rows
// xy, xz, yz in 3D; equal numbers of bins; weights finite and >= 0; empty = no rose, a
// warning) and mean_radius and radius_ratio for a title. Throws InputError for
// inconsistent input and FileError if the output directory is missing or not writable,
// before writing anything; a failing gnuplot is a warning.
template <int Dim>
PicturesWritten WritePackingPictures(const Packing<Dim>& packing,
                                     const PackingMetrics<Dim>& metrics,
                                     const std::string& output_prefix,
                                     const PackingPicturesOptions& options = {});

}  // namespace specimen
