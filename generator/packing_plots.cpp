#include "generator/packing_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"

namespace specimen {
namespace {

// A short number for titles and labels.
std::string Short(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

struct RadiusBin {
  double low = 0.0;
  double high = 0.0;
  long long count = 0;
  double volume = 0.0;
};

template <int Dim>
std::vector<RadiusBin> RadiusHistogram(const Packing<Dim>& packing, int requested_bins) {
  if (packing.size() == 0) return {};
  const auto [smallest, largest] = std::minmax_element(packing.radii.begin(), packing.radii.end());
  const double minimum = *smallest, maximum = *largest;
  std::vector<RadiusBin> bins;
  if (maximum == minimum) {
    bins.push_back({0.95 * minimum, 1.05 * minimum, 0, 0.0});
  } else {
    const int automatic =
        std::min(40, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(packing.size())))));
    const int count = requested_bins > 0 ? requested_bins : std::max(1, automatic);
    const double width = (maximum - minimum) / count;
    for (int k = 0; k < count; ++k)
      bins.push_back(
          {minimum + k * width, k + 1 == count ? maximum : minimum + (k + 1) * width, 0, 0.0});
  }
  double total_volume = 0.0;
  for (double radius : packing.radii) {
    int k = 0;
    if (bins.size() > 1) {
      k = static_cast<int>((radius - bins.front().low) / (bins[0].high - bins[0].low));
      k = std::clamp(k, 0, static_cast<int>(bins.size()) - 1);
    }
    const double volume = ParticleVolume<Dim>(radius);
    ++bins[k].count;
    bins[k].volume += volume;
    total_volume += volume;
  }
  for (auto& bin : bins) bin.volume /= total_volume;
  return bins;
}

// Names of the orientation histogram rows, as in PackingMetrics.
template <int Dim>
std::vector<std::string> PlaneNames() {
  if constexpr (Dim == 2)
    return {"xy"};
  else
    return {"xy", "xz", "yz"};
}

// Throws InputError unless the histograms have the shape PackingMetrics documents.
template <int Dim>
void RequireOrientationHistograms(const std::vector<std::vector<double>>& histograms) {
  const size_t rows = PlaneNames<Dim>().size();
  if (histograms.empty()) return;  // metrics without orientations: reported as a warning
  if (histograms.size() != rows)
    throw InputError("orientation_histograms has " + std::to_string(histograms.size()) +
                     " rows; a " + std::to_string(Dim) + "D packing needs " + std::to_string(rows) +
                     (Dim == 2 ? " (xy)" : " (xy, xz, yz)"));
  for (size_t row = 0; row < rows; ++row) {
    if (histograms[row].empty() || histograms[row].size() != histograms[0].size())
      throw InputError("orientation_histograms row " + std::to_string(row) + " has " +
                       std::to_string(histograms[row].size()) +
                       " bins; every row needs the same number, at least 1");
    for (double weight : histograms[row])
      if (!std::isfinite(weight) || weight < 0.0)
        throw InputError("orientation_histograms row " + std::to_string(row) +
                         " holds the weight " + ExactDouble(weight) + "; weights must be >= 0");
  }
}

// Palette from dark blue through green to yellow (viridis-like): readable in grey print
// and for colour-blind readers.
const char* const kPalette =
    "set palette defined (0 '#440154', 1 '#3b528b', 2 '#21918c', 3 '#5ec962', 4 '#fde725')\n";

template <int Dim>
std::string DomainOutlineObject(const Domain<Dim>& domain) {
  std::ostringstream script;
  const char* const style = " front fillstyle empty border lc rgb 'black' lw 1.5\n";
  if (domain.shape() == DomainShape::kDisc) {
    script << "set object 1 circle at " << ExactDouble(domain.CircleCentre().x()) << ','
           << ExactDouble(domain.CircleCentre().y()) << " size "
           << ExactDouble(domain.CircleRadius()) << style;
  } else {
    const auto& vertices = domain.PolygonVertices();
    script << "set object 1 polygon from ";
    for (const auto& vertex : vertices)
      script << ExactDouble(vertex.x()) << ',' << ExactDouble(vertex.y()) << " to ";
    script << ExactDouble(vertices.front().x()) << ',' << ExactDouble(vertices.front().y())
           << style;
  }
  return script.str();
}

// The packing to scale; returns the script and the picture height for the aspect ratio.
std::string PackingScript(const Packing<2>& packing, const std::string& particles_csv,
                          const std::string& contacts_csv, int width_px, int* height_px) {
  Vector<2> lower = packing.domain.Lower(), upper = packing.domain.Upper();
  double smallest_radius = packing.radii.front(), largest_radius = packing.radii.front();
  for (int i = 0; i < packing.size(); ++i) {
    lower = lower.cwiseMin(packing.centres[i] - Vector<2>::Constant(packing.radii[i]));
    upper = upper.cwiseMax(packing.centres[i] + Vector<2>::Constant(packing.radii[i]));
    smallest_radius = std::min(smallest_radius, packing.radii[i]);
    largest_radius = std::max(largest_radius, packing.radii[i]);
  }
  const Vector<2> margin = 0.02 * (upper - lower);
  lower -= margin;
  upper += margin;
  // Room for the labels and the colour box around a plot area of the domain's shape.
  const double aspect = (upper.y() - lower.y()) / (upper.x() - lower.x());
  *height_px =
      std::clamp(static_cast<int>(std::lround((width_px - 260) * aspect)) + 140, 300, 4000);
  if (smallest_radius == largest_radius) {  // gnuplot needs a non-empty colour range
    smallest_radius *= 0.999;
    largest_radius *= 1.001;
  }
  // Borders separate the discs of a small packing; in a large one they would paint it
  // dark, each disc being a few pixels wide.
  constexpr int kBorderedDiscLimit = 5000;
  const bool small = packing.size() < kBorderedDiscLimit;
  std::ostringstream script;
  script << "set datafile separator comma\n"
         << "set datafile columnheaders\n"
         << "unset key\n"
         << "set size ratio -1\n"
         << "set xrange [" << ExactDouble(lower.x()) << ':' << ExactDouble(upper.x()) << "]\n"
         << "set yrange [" << ExactDouble(lower.y()) << ':' << ExactDouble(upper.y()) << "]\n"
         << "set xlabel 'x [m]'\nset ylabel 'y [m]'\n"
         << "set cblabel 'radius [m]'\n"
         << "set cbrange [" << ExactDouble(smallest_radius) << ':' << ExactDouble(largest_radius)
         << "]\n"
         << kPalette << "set title '" << packing.size() << " discs, " << packing.contacts.size()
         << " contacts, " << packing.domain.ShapeName() << " domain' noenhanced\n"
         << DomainOutlineObject(packing.domain)
         << (small ? "set style fill solid 1.0 border lc rgb '#303030'\n"
                   : "set style fill solid 1.0 noborder\n")
         << "plot " << GnuplotQuote(particles_csv)
         << " using 1:2:3:3 with circles lc palette lw 0.5";
  if (!contacts_csv.empty())
    script << ", " << GnuplotQuote(contacts_csv)
           << " using 3:4:($5-$3):($6-$4) with vectors nohead lw 0.8 lc rgb '#d62728'";
  script << '\n';
  return script.str();
}

template <int Dim>
std::string HistogramScript(const Packing<Dim>& packing, const PackingMetrics<Dim>& metrics,
                            const std::string& radii_csv) {
  std::ostringstream script;
  script << "set datafile separator comma\n"
         << "set datafile columnheaders\n"
         << "set key top left\n"
         << "set xlabel 'radius [m]'\n"
         << "set ylabel 'particles per bin'\n"
         << "set y2label 'share of the particle volume'\n"
         << "set ytics nomirror\nset y2tics\n"
         << "set yrange [0:*]\nset y2range [0:*]\n"
         << "set grid ytics\n"
         << "set style fill solid 0.6 border lc rgb '#303030'\n"
         << "set title '" << packing.size() << (Dim == 2 ? " discs" : " spheres")
         << ", volume-mean radius " << Short(metrics.mean_radius) << " m, radius ratio "
         << Short(metrics.radius_ratio) << "' noenhanced\n"
         << "plot " << GnuplotQuote(radii_csv)
         << " using (($1+$2)/2):3:($2-$1) with boxes lc rgb '#3b528b' title 'particles', "
         << GnuplotQuote(radii_csv)
         << " using (($1+$2)/2):4 axes x1y2 with linespoints pt 7 lw 2 lc rgb '#d62728'"
         << " title 'volume fraction'\n";
  return script.str();
}

// Weights divided by the mean weight per bin of their row: 1 everywhere for isotropic
// contacts, whatever the contact count; rows without weight stay 0.
std::vector<std::vector<double>> RelativeToIsotropic(
    const std::vector<std::vector<double>>& histograms) {
  std::vector<std::vector<double>> relative;
  for (const auto& row : histograms) {
    double mean = 0.0;
    for (double weight : row) mean += weight;
    mean /= static_cast<double>(row.size());
    std::vector<double> scaled;
    for (double weight : row) scaled.push_back(mean > 0.0 ? weight / mean : 0.0);
    relative.push_back(scaled);
  }
  return relative;
}

// Upper end of the radial axis and its tic step: a round number, so that the outer circle
// (drawn at the last tic) encloses the curves.
double RoundAxisEnd(double value, double* step) {
  const double raw_step = value / 4.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw_step)));
  *step = 10.0 * magnitude;
  for (double multiple : {1.0, 2.0, 2.5, 5.0})
    if (multiple * magnitude >= raw_step) {
      *step = multiple * magnitude;
      break;
    }
  return std::ceil(value / *step - 1e-9) * *step;
}

template <int Dim>
std::string RoseScript(const Packing<Dim>& packing,
                       const std::vector<std::vector<double>>& relative,
                       const std::string& orientation_csv) {
  const std::vector<std::string> planes = PlaneNames<Dim>();
  const char* const colours[] = {"#3b528b", "#d62728", "#21918c"};
  double largest = 1.0;
  for (const auto& row : relative)
    for (double value : row) largest = std::max(largest, value);
  double step = 0.0;
  const double axis_end = RoundAxisEnd(1.1 * largest, &step);
  std::ostringstream script;
  script << "set datafile separator comma\n"
         << "set datafile columnheaders\n"
         << "set encoding utf8\n"
         << "set polar\nset angles degrees\nset size ratio -1\n"
         << "unset border\nunset xtics\nunset ytics\nunset raxis\n"
         << "set border polar\n"
         << "set grid polar 30\n"
         << "set ttics 0,30 format '%g°'\n"
         << "set rtics " << ExactDouble(step) << " axis nomirror\n"
         << "set rrange [0:" << ExactDouble(axis_end) << "]\n"
         << "set trange [0:360]\n"
         << "set key bmargin center horizontal\n"
         << "set style fill transparent solid 0.15 border\n"
         << "set title 'contact orientations, " << packing.contacts.size()
         << " contacts (1 = isotropic" << (Dim == 3 ? "; projections onto xy, xz, yz" : "")
         << ")' noenhanced\n";
  // gnuplot leaves the border of a closed filled curve open between the last and the
  // first point (357.5 and 2.5 degrees for 5-degree bins); an arrow closes it.
  const size_t bins = relative[0].size();
  const double width = 180.0 / static_cast<double>(bins);
  constexpr double kDegree = 3.14159265358979323846 / 180.0;
  const double first_angle = 0.5 * width * kDegree, last_angle = (360.0 - 0.5 * width) * kDegree;
  for (size_t p = 0; p < planes.size(); ++p)
    script << "set arrow " << p + 1 << " from "
           << ExactDouble(relative[p].back() * std::cos(last_angle)) << ','
           << ExactDouble(relative[p].back() * std::sin(last_angle)) << " to "
           << ExactDouble(relative[p].front() * std::cos(first_angle)) << ','
           << ExactDouble(relative[p].front() * std::sin(first_angle)) << " nohead lw 2 lc rgb '"
           << colours[p] << "'\n";
  script << "plot ";
  // Columns: 1-4 bin data, then one weight column per plane, then one relative column.
  for (size_t p = 0; p < planes.size(); ++p)
    script << GnuplotQuote(orientation_csv) << " using 3:" << 5 + planes.size() + p
           << " with filledcurves closed lw 2 lc rgb '" << colours[p] << "' title '" << planes[p]
           << " plane', ";
  script << "1 with lines dt 2 lw 1.5 lc rgb '#808080' title 'isotropic'\n";
  return script.str();
}

}  // namespace

bool PackingPicturesOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (radius_bins < 0 || radius_bins > 10000)
    return fail("radius_bins = " + std::to_string(radius_bins) +
                " is not allowed: it must be 0 (automatic) or 1..10000");
  if (contact_drawing_limit < 0)
    return fail("contact_drawing_limit = " + std::to_string(contact_drawing_limit) +
                " is not allowed: it must be >= 0");
  if (packing_picture_width_px < 300 || packing_picture_width_px > 10000)
    return fail("packing_picture_width_px = " + std::to_string(packing_picture_width_px) +
                " is not allowed: it must be in 300..10000");
  for (const auto& [name, plot] :
       {std::pair<const char*, PlotOptions>{"histogram_plot", histogram_plot},
        {"rose_plot", rose_plot}})
    if (plot.width_px < 100 || plot.height_px < 100 || plot.width_px > 10000 ||
        plot.height_px > 10000)
      return fail(std::string(name) + " size " + std::to_string(plot.width_px) + "x" +
                  std::to_string(plot.height_px) +
                  " is not allowed: each side must be in 100..10000");
  return true;
}

template <int Dim>
PicturesWritten WritePackingPictures(const Packing<Dim>& packing,
                                     const PackingMetrics<Dim>& metrics,
                                     const std::string& output_prefix,
                                     const PackingPicturesOptions& options) {
  // 1. Check everything before the first file appears.
  std::string options_error;
  if (!options.IsValid(&options_error)) throw InputError("packing pictures: " + options_error);
  if (packing.centres.size() != packing.radii.size())
    throw InputError("packing pictures: " + std::to_string(packing.centres.size()) +
                     " centres but " + std::to_string(packing.radii.size()) + " radii");
  if (metrics.particle_count != packing.size())
    throw InputError("packing pictures: the metrics describe " +
                     std::to_string(metrics.particle_count) + " particles but the packing has " +
                     std::to_string(packing.size()));
  for (const auto& contact : packing.contacts)
    if (std::min(contact[0], contact[1]) < 0 || std::max(contact[0], contact[1]) >= packing.size())
      throw InputError("packing pictures: contact (" + std::to_string(contact[0]) + ", " +
                       std::to_string(contact[1]) + ") refers to a particle that does not exist");
  RequireOrientationHistograms<Dim>(metrics.orientation_histograms);
  const std::string directory = std::filesystem::path(output_prefix).parent_path().string();
  RequireWritableDirectory(directory, "packing pictures");

  PicturesWritten written;
  const bool gnuplot = options.draw && GnuplotAvailable();
  std::vector<std::string> skipped;  // pictures not drawn because gnuplot is missing
  auto render = [&](const std::string& script, const std::string& png, const PlotOptions& plot) {
    if (!options.draw) return;
    if (!gnuplot) {
      skipped.push_back(png);
      return;
    }
    std::string error;
    if (RenderGnuplot(script, png, plot, &error))
      written.files.push_back(png);
    else
      written.warnings.push_back(error);
  };

  // 2. Radius histogram.
  const std::string radii_csv = output_prefix + "_radii.csv";
  const std::vector<RadiusBin> bins = RadiusHistogram(packing, options.radius_bins);
  WriteFileAtomically(radii_csv, [&](std::ostream& out) {
    out << "bin_low_m,bin_high_m,count,volume_fraction\n";
    for (const auto& bin : bins)
      out << ExactDouble(bin.low) << ',' << ExactDouble(bin.high) << ',' << bin.count << ','
          << ExactDouble(bin.volume) << '\n';
  });
  written.files.push_back(radii_csv);

  // 3. Orientation histogram(s), mirrored to the full circle, with the weights relative
  // to an isotropic distribution next to the raw ones.
  const std::vector<std::string> planes = PlaneNames<Dim>();
  const auto& histograms = metrics.orientation_histograms;
  const std::vector<std::vector<double>> relative = RelativeToIsotropic(histograms);
  bool orientations_drawable = false;
  for (const auto& row : relative)
    for (double value : row) orientations_drawable = orientations_drawable || value > 0.0;
  const std::string orientation_csv = output_prefix + "_orientation.csv";
  if (histograms.empty()) {
    written.warnings.push_back("the metrics hold no contact-orientation histogram: " +
                               orientation_csv + " and the rose were not written");
  } else {
    const size_t bin_count = histograms[0].size();
    WriteFileAtomically(orientation_csv, [&](std::ostream& out) {
      out << "bin_low_deg,bin_high_deg,bin_centre_deg,mirrored";
      for (const auto& plane : planes) out << ',' << plane << "_weight";
      for (const auto& plane : planes) out << ',' << plane << "_relative_to_isotropic";
      out << '\n';
      const double width = 180.0 / static_cast<double>(bin_count);
      for (size_t row = 0; row < 2 * bin_count; ++row) {
        const size_t k = row % bin_count;
        const double low = static_cast<double>(row) * width;
        out << ExactDouble(low) << ',' << ExactDouble(low + width) << ','
            << ExactDouble(low + 0.5 * width) << ',' << (row >= bin_count ? 1 : 0);
        for (size_t p = 0; p < planes.size(); ++p) out << ',' << ExactDouble(histograms[p][k]);
        for (size_t p = 0; p < planes.size(); ++p) out << ',' << ExactDouble(relative[p][k]);
        out << '\n';
      }
    });
    written.files.push_back(orientation_csv);
    if (!orientations_drawable)
      written.warnings.push_back(
          "no contact orientations (every weight is 0): the "
          "orientation rose was not drawn");
  }

  // 4. The particles and, for small packings, the contacts (drawn in 2D). The columns are
  // those of run-test's particles.csv, with z in 3D.
  const std::vector<std::string> axes = Dim == 2 ? std::vector<std::string>{"x", "y"}
                                                 : std::vector<std::string>{"x", "y", "z"};
  auto write_centre = [&](std::ostream& out, int particle) {
    for (int k = 0; k < Dim; ++k) out << ',' << ExactDouble(packing.centres[particle][k]);
  };
  const std::string particles_csv = output_prefix + "_particles.csv";
  WriteFileAtomically(particles_csv, [&](std::ostream& out) {
    for (const auto& axis : axes) out << axis << "_m,";
    out << "radius_m\n";
    for (int i = 0; i < packing.size(); ++i) {
      for (int k = 0; k < Dim; ++k) out << ExactDouble(packing.centres[i][k]) << ',';
      out << ExactDouble(packing.radii[i]) << '\n';
    }
  });
  written.files.push_back(particles_csv);
  std::string contacts_csv;
  if (!packing.contacts.empty()) {
    contacts_csv = output_prefix + "_contacts.csv";
    WriteFileAtomically(contacts_csv, [&](std::ostream& out) {
      out << "i,j";
      for (const char* end : {"i", "j"})
        for (const auto& axis : axes) out << ',' << axis << '_' << end << "_m";
      out << '\n';
      for (const auto& contact : packing.contacts) {
        out << contact[0] << ',' << contact[1];
        write_centre(out, contact[0]);
        write_centre(out, contact[1]);
        out << '\n';
      }
    });
    written.files.push_back(contacts_csv);
  }

  // 5. Pictures, from the files just written.
  if (packing.size() == 0) {
    written.warnings.push_back("the packing is empty: no packing picture or radius histogram");
  } else {
    if constexpr (Dim == 2) {
      PlotOptions plot;
      plot.width_px = options.packing_picture_width_px;
      const bool draw_contacts = packing.size() < options.contact_drawing_limit;
      const std::string script = PackingScript(packing, particles_csv, draw_contacts ? contacts_csv : std::string(),
                                               plot.width_px, &plot.height_px);
      render(script, output_prefix + "_packing.png", plot);
    }
    render(HistogramScript(packing, metrics, radii_csv), output_prefix + "_radius_histogram.png",
           options.histogram_plot);
  }
  if (orientations_drawable)
    render(RoseScript(packing, relative, orientation_csv), output_prefix + "_orientation_rose.png",
           options.rose_plot);

  if (!skipped.empty()) {
    std::string list;
    for (const auto& png : skipped) list += (list.empty() ? "" : ", ") + png;
    written.warnings.push_back(
        "gnuplot not found (apt-get install gnuplot-nox): pictures "
        "skipped: " +
        list + "; the CSV files hold the numbers");
  }
  return written;
}

template PicturesWritten WritePackingPictures<2>(const Packing<2>&, const PackingMetrics<2>&,
                                                 const std::string&, const PackingPicturesOptions&);
template PicturesWritten WritePackingPictures<3>(const Packing<3>&, const PackingMetrics<3>&,
                                                 const std::string&, const PackingPicturesOptions&);

}  // namespace specimen
