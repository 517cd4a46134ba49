#include "generator/metrics.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.h"
#include "common/unit_names.h"
#include "generator/neighbour_grid.h"
#include "generator/union_volume.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Overlaps below this fraction of the mean radius are round-off: such pairs touch.
constexpr double kRoundOffOverlap = 1e-12;

// Angle of the direction (x, y) in degrees, folded into [0, 180): a contact has no sense.
double FoldedAngleDegrees(double x, double y) {
  double angle = std::atan2(y, x) * 180.0 / kPi;
  if (angle < 0.0) angle += 180.0;
  if (angle >= 180.0) angle -= 180.0;
  return angle;
}

void AddToHistogram(std::vector<double>& row, double x, double y, double weight) {
  const int bins = static_cast<int>(row.size());
  const int bin = static_cast<int>(FoldedAngleDegrees(x, y) / (180.0 / bins));
  row[std::clamp(bin, 0, bins - 1)] += weight;
}

template <int Dim>
std::vector<std::string> HistogramPlanes() {
  if constexpr (Dim == 2)
    return {"xy"};
  else
    return {"xy", "xz", "yz"};
}

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

}  // namespace

bool MetricsOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (orientation_bins < 1)
    return fail("orientation_bins = " + std::to_string(orientation_bins) +
                " is not allowed: it must be >= 1");
  if (!(corrected_porosity_tolerance > 0.0 && corrected_porosity_tolerance < 1.0))
    return fail("corrected_porosity_tolerance = " + ExactDouble(corrected_porosity_tolerance) +
                " is not allowed: it must be in (0, 1)");
  if (max_slices_per_sphere < 8)
    return fail("max_slices_per_sphere = " + std::to_string(max_slices_per_sphere) +
                " is not allowed: it must be >= 8");
  return true;
}

template <int Dim>
double ClippedUnionVolume(const Packing<Dim>& packing, const MetricsOptions& options,
                          double* error_bound) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("metrics options: " + error);
  const auto pairs = OverlappingPairs<Dim>(packing.centres, packing.radii, 0.0);
  const ClippedUnion union_volume = ClippedUnionOfParticles<Dim>(
      packing, pairs, options.corrected_porosity_tolerance * packing.domain.Volume(),
      options.max_slices_per_sphere);
  if (error_bound != nullptr) *error_bound = union_volume.error_bound;
  return union_volume.volume;
}

template <int Dim>
PackingMetrics<Dim> ComputePackingMetrics(const Packing<Dim>& packing,
                                          const MetricsOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("metrics options: " + error);
  const int count = packing.size();
  if (static_cast<int>(packing.centres.size()) != count)
    throw InputError("metrics: the packing has " + std::to_string(packing.centres.size()) +
                     " centres but " + std::to_string(count) + " radii");
  PackingMetrics<Dim> metrics;
  metrics.particle_count = count;
  metrics.domain_volume = packing.domain.Volume();

  // 1. Sizes (Labra 3.12) and the nominal porosity (3.13) with overlaps counted twice.
  double sum_squared = 0.0, sum_cubed = 0.0;
  if (count > 0) {
    metrics.min_radius = *std::min_element(packing.radii.begin(), packing.radii.end());
    metrics.max_radius = *std::max_element(packing.radii.begin(), packing.radii.end());
  }
  for (double r : packing.radii) {
    metrics.particle_volume += ParticleVolume<Dim>(r);
    sum_squared += r * r;
    sum_cubed += r * r * r;
  }
  metrics.radius_ratio = metrics.min_radius > 0.0 ? metrics.max_radius / metrics.min_radius : 0.0;
  metrics.mean_radius = VolumeMeanRadius<Dim>(packing.radii);
  if (count > 0) {
    metrics.mean_radius_squared = sum_squared / count;
    metrics.mean_radius_cubed = sum_cubed / count;
  }
  metrics.nominal_porosity = 1.0 - metrics.particle_volume / metrics.domain_volume;
  // Relative values are per mean radius; an all-zero packing has no scale.
  const double per_radius = metrics.mean_radius > 0.0 ? 1.0 / metrics.mean_radius : 0.0;

  // 2. Contacts: coordination (3.17), fabric (3.19)-(3.21), orientations, gaps, branches.
  const int contact_count = static_cast<int>(packing.contacts.size());
  metrics.contact_count = contact_count;
  metrics.coordination_number = count > 0 ? 2.0 * contact_count / count : 0.0;
  std::vector<int> contacts_of(count, 0);
  Eigen::Matrix<double, Dim, Dim> fabric_sum = Eigen::Matrix<double, Dim, Dim>::Zero();
  metrics.orientation_histograms.assign(Dim == 2 ? 1 : 3,
                                        std::vector<double>(options.orientation_bins, 0.0));
  int directed_contacts = 0, open_contacts = 0;
  double branch_sum = 0.0, branch_squared_sum = 0.0, gap_sum = 0.0;
  for (const auto& contact : packing.contacts) {
    const int i = contact[0], j = contact[1];
    if (i < 0 || j < 0 || i >= count || j >= count || i == j)
      throw InputError("metrics: contact (" + std::to_string(i) + ", " + std::to_string(j) +
                       ") does not join two distinct particles of the " + std::to_string(count) +
                       " in the packing");
    ++contacts_of[i];
    ++contacts_of[j];
    const Vector<Dim> branch = packing.centres[j] - packing.centres[i];
    const double length = branch.norm();
    branch_sum += length;
    branch_squared_sum += length * length;
    const double gap = length - packing.radii[i] - packing.radii[j];
    if (gap > 0.0) {
      ++open_contacts;
      gap_sum += gap * per_radius;
      metrics.max_contact_gap = std::max(metrics.max_contact_gap, gap * per_radius);
    }
    if (length == 0.0) continue;  // coincident centres: no direction
    const Vector<Dim> n = branch / length;
    ++directed_contacts;
    fabric_sum += n * n.transpose();
    if constexpr (Dim == 2) {
      AddToHistogram(metrics.orientation_histograms[0], n.x(), n.y(), 1.0);
    } else {
      // Projections onto the xy, xz and yz planes, weighted by the projected length.
      const int axes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
      for (int plane = 0; plane < 3; ++plane) {
        const double a = n[axes[plane][0]], b = n[axes[plane][1]];
        const double projected = std::hypot(a, b);
        if (projected > 0.0) AddToHistogram(metrics.orientation_histograms[plane], a, b, projected);
      }
    }
  }
  if (contact_count > 0) {
    metrics.mean_branch_length = branch_sum / contact_count;
    metrics.mean_branch_length_squared = branch_squared_sum / contact_count;
  }
  if (open_contacts > 0) metrics.mean_contact_gap = gap_sum / open_contacts;
  if (directed_contacts > 0) {
    metrics.fabric = fabric_sum / directed_contacts;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Dim, Dim>> solver(metrics.fabric,
                                                                          Eigen::EigenvaluesOnly);
    metrics.fabric_eigenvalues = solver.eigenvalues();  // ascending
  }
  if (count > 0) {
    int under = 0;
    for (int c : contacts_of) under += c < Dim + 1 ? 1 : 0;
    metrics.under_coordinated_fraction = static_cast<double>(under) / count;
  }

  // 3. Overlaps over every overlapping pair (neighbour search), and the union volume.
  const auto pairs = OverlappingPairs<Dim>(packing.centres, packing.radii, 0.0);
  double overlap_sum = 0.0;
  for (const auto& pair : pairs) {
    const double overlap = -packing.Gap(pair[0], pair[1]) * per_radius;
    if (overlap < kRoundOffOverlap) continue;
    ++metrics.overlapping_pairs;
    overlap_sum += overlap;
    metrics.max_overlap = std::max(metrics.max_overlap, overlap);
  }
  if (metrics.overlapping_pairs > 0) metrics.mean_overlap = overlap_sum / metrics.overlapping_pairs;
  const ClippedUnion union_volume = ClippedUnionOfParticles<Dim>(
      packing, pairs, options.corrected_porosity_tolerance * metrics.domain_volume,
      options.max_slices_per_sphere);
  metrics.corrected_porosity = 1.0 - union_volume.volume / metrics.domain_volume;
  metrics.corrected_porosity_error = union_volume.error_bound / metrics.domain_volume;

  // 4. Protrusion through the boundary: r_i - (distance of x_i to the boundary).
  double max_protrusion = 0.0;
  int protruding = 0;
#pragma omp parallel for reduction(max : max_protrusion) reduction(+ : protruding) if (count > 20000)
  for (int i = 0; i < count; ++i) {
    const double protrusion =
        (packing.radii[i] - packing.domain.SignedDistance(packing.centres[i])) * per_radius;
    if (protrusion > kRoundOffOverlap) {
      ++protruding;
      max_protrusion = std::max(max_protrusion, protrusion);
    }
  }
  metrics.max_protrusion = max_protrusion;
  metrics.protruding_particles = protruding;
  return metrics;
}

template <int Dim>
std::string MetricsReport(const PackingMetrics<Dim>& m) {
  std::ostringstream out;
  const bool plane = Dim == 2;
  const std::string volume_unit = plane ? "m^2 (per m of thickness)" : "m^3";
  auto line = [&](const std::string& name, const std::string& value, const std::string& note) {
    char buffer[200];
    std::snprintf(buffer, sizeof(buffer), "  %-32s %22s   %s", name.c_str(), value.c_str(),
                  note.c_str());
    std::string text = buffer;
    text.erase(text.find_last_not_of(' ') + 1);
    out << text << '\n';
  };
  auto number = [](double value) { return Format("%.6g", value); };
  out << "Packing metrics (" << Dim << "D, " << (plane ? "discs" : "spheres") << ")\n";
  out << "Particles\n";
  line("count", std::to_string(m.particle_count), "");
  line("mean radius", number(m.mean_radius), "m, volume-based (Labra 3.12)");
  line("min / max radius", number(m.min_radius) + " / " + number(m.max_radius), "m");
  line("radius ratio", number(m.radius_ratio), "max / min");
  line("<r^2>", number(m.mean_radius_squared), "m^2");
  line("<r^3>", number(m.mean_radius_cubed), "m^3");
  out << "Volume\n";
  line("domain " + std::string(plane ? "area" : "volume"), number(m.domain_volume), volume_unit);
  line("particle " + std::string(plane ? "area" : "volume"), number(m.particle_volume),
       volume_unit + ", overlaps counted twice");
  line("nominal porosity", Format("%.6f", m.nominal_porosity),
       "1 - particle / domain (Labra 3.13)");
  line("corrected porosity", Format("%.6f", m.corrected_porosity),
       "1 - |union of particles in domain| / domain");
  line("corrected porosity error bound", Format("%.2e", m.corrected_porosity_error),
       plane ? "exact up to round-off" : "guaranteed bound");
  out << "Contacts\n";
  line("contacts", std::to_string(m.contact_count), "");
  line("coordination number", Format("%.4f", m.coordination_number), "2 Nc / Np (Labra 3.17)");
  line("under-coordinated particles", Format("%.4f", m.under_coordinated_fraction),
       "share with fewer than " + std::to_string(Dim + 1) + " contacts");
  line("mean / max contact gap", number(m.mean_contact_gap) + " / " + number(m.max_contact_gap),
       "per mean radius, contacts with a gap");
  line("<l>", number(m.mean_branch_length), "m, branch length over contacts");
  line("<l^2>", number(m.mean_branch_length_squared), "m^2");
  out << "Overlaps and boundary\n";
  line("overlapping pairs", std::to_string(m.overlapping_pairs), "all pairs, not only contacts");
  line("mean / max overlap", number(m.mean_overlap) + " / " + number(m.max_overlap),
       "per mean radius");
  line("protruding particles", std::to_string(m.protruding_particles), "");
  line("max protrusion", number(m.max_protrusion), "per mean radius, beyond the boundary");
  out << "Fabric (Labra 3.19-3.21; isotropic: all " << (plane ? "1/2" : "1/3") << ")\n";
  std::string eigenvalues;
  for (int k = 0; k < Dim; ++k)
    eigenvalues += (k > 0 ? " " : "") + Format("%.5f", m.fabric_eigenvalues[k]);
  line("eigenvalues", eigenvalues, "ascending");
  for (int row = 0; row < Dim; ++row) {
    std::string text;
    for (int col = 0; col < Dim; ++col)
      text += (col > 0 ? " " : "") + Format("%+.5f", m.fabric(row, col));
    line(row == 0 ? "tensor" : "", text, "");
  }
  const auto planes = HistogramPlanes<Dim>();
  for (size_t row = 0; row < m.orientation_histograms.size() && row < planes.size(); ++row) {
    const auto& histogram = m.orientation_histograms[row];
    if (histogram.empty()) continue;
    double total = 0.0, peak = 0.0;
    for (double w : histogram) {
      total += w;
      peak = std::max(peak, w);
    }
    const double isotropic = total / histogram.size();
    line(
        "orientations " + planes[row], isotropic > 0.0 ? Format("%.3f", peak / isotropic) : "-",
        "largest bin / isotropic, " + std::to_string(histogram.size()) + " bins over [0, 180) deg");
  }
  return out.str();
}

template <int Dim>
nlohmann::json MetricsToJson(const PackingMetrics<Dim>& m) {
  nlohmann::json json;
  json["dimension"] = Dim;
  json["particle_count"] = m.particle_count;
  json[VolumeName("domain", Dim)] = m.domain_volume;
  json[VolumeName("particle", Dim)] = m.particle_volume;
  json["mean_radius_m"] = m.mean_radius;
  json["min_radius_m"] = m.min_radius;
  json["max_radius_m"] = m.max_radius;
  json["radius_ratio"] = m.radius_ratio;
  json["nominal_porosity"] = m.nominal_porosity;
  json["corrected_porosity"] = m.corrected_porosity;
  json["corrected_porosity_error"] = m.corrected_porosity_error;
  json["contact_count"] = m.contact_count;
  json["coordination_number"] = m.coordination_number;
  json["under_coordinated_fraction"] = m.under_coordinated_fraction;
  json["overlapping_pairs"] = m.overlapping_pairs;
  json["mean_overlap_per_r_mean"] = m.mean_overlap;
  json["max_overlap_per_r_mean"] = m.max_overlap;
  json["mean_contact_gap_per_r_mean"] = m.mean_contact_gap;
  json["max_contact_gap_per_r_mean"] = m.max_contact_gap;
  nlohmann::json fabric = nlohmann::json::array();
  for (int row = 0; row < Dim; ++row) {
    nlohmann::json values = nlohmann::json::array();
    for (int col = 0; col < Dim; ++col) values.push_back(m.fabric(row, col));
    fabric.push_back(values);
  }
  json["fabric"] = fabric;
  json["fabric_eigenvalues"] =
      std::vector<double>(m.fabric_eigenvalues.data(), m.fabric_eigenvalues.data() + Dim);
  const size_t bins = m.orientation_histograms.empty() ? 0 : m.orientation_histograms[0].size();
  json["orientation_histograms"] = {{"planes", HistogramPlanes<Dim>()},
                                    {"bin_width_deg", bins > 0 ? 180.0 / bins : 0.0},
                                    {"weights", m.orientation_histograms}};
  json["max_protrusion_per_r_mean"] = m.max_protrusion;
  json["protruding_particles"] = m.protruding_particles;
  json["mean_radius_squared_m2"] = m.mean_radius_squared;
  json["mean_radius_cubed_m3"] = m.mean_radius_cubed;
  json["mean_branch_length_m"] = m.mean_branch_length;
  json["mean_branch_length_squared_m2"] = m.mean_branch_length_squared;
  return json;
}

template PackingMetrics<2> ComputePackingMetrics<2>(const Packing<2>&, const MetricsOptions&);
template PackingMetrics<3> ComputePackingMetrics<3>(const Packing<3>&, const MetricsOptions&);
template std::string MetricsReport<2>(const PackingMetrics<2>&);
template std::string MetricsReport<3>(const PackingMetrics<3>&);
template nlohmann::json MetricsToJson<2>(const PackingMetrics<2>&);
template nlohmann::json MetricsToJson<3>(const PackingMetrics<3>&);
template double ClippedUnionVolume<2>(const Packing<2>&, const MetricsOptions&, double*);
template double ClippedUnionVolume<3>(const Packing<3>&, const MetricsOptions&, double*);

}  // namespace specimen
