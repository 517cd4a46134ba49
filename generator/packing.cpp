#include "generator/packing.h"

#include <algorithm>
#include <cmath>

namespace specimen {

template <int Dim>
double VolumeMeanRadius(const std::vector<double>& radii) {
  if (radii.empty()) return 0.0;
  double sum = 0.0;
  for (double r : radii) sum += std::pow(r, Dim);
  return std::pow(sum / static_cast<double>(radii.size()), 1.0 / Dim);
}

template <int Dim>
double ParticleVolume(double radius) {
  constexpr double kPi = 3.14159265358979323846;
  if constexpr (Dim == 2) return kPi * radius * radius;
  else return 4.0 / 3.0 * kPi * radius * radius * radius;
}

template <int Dim>
void SetContactsFromCandidates(Packing<Dim>& packing,
                               const std::vector<std::array<int, 2>>& candidates,
                               double tolerance) {
  const double limit = tolerance * VolumeMeanRadius<Dim>(packing.radii);
  std::vector<std::array<int, 2>> contacts;
  contacts.reserve(candidates.size());
  for (auto pair : candidates) {
    if (pair[0] == pair[1]) continue;
    if (pair[0] > pair[1]) std::swap(pair[0], pair[1]);
    if (std::abs(packing.Gap(pair[0], pair[1])) <= limit) contacts.push_back(pair);
  }
  std::sort(contacts.begin(), contacts.end());
  contacts.erase(std::unique(contacts.begin(), contacts.end()), contacts.end());
  packing.contacts = std::move(contacts);
  packing.contact_tolerance = tolerance;
}

template <int Dim>
int RemoveFlaggedParticles(const std::vector<char>& remove, std::vector<Vector<Dim>>& centres,
                           std::vector<double>& radii, std::vector<char>* marks) {
  size_t kept = 0;
  for (size_t i = 0; i < centres.size(); ++i) {
    if (remove[i]) continue;
    centres[kept] = centres[i];
    radii[kept] = radii[i];
    if (marks) (*marks)[kept] = (*marks)[i];
    ++kept;
  }
  const int removed = static_cast<int>(centres.size() - kept);
  centres.resize(kept);
  radii.resize(kept);
  if (marks) marks->resize(kept);
  return removed;
}

template <int Dim>
double NominalPorosity(const Domain<Dim>& domain, const std::vector<double>& radii) {
  double volume = 0.0;
  for (double radius : radii) volume += ParticleVolume<Dim>(radius);
  return 1.0 - volume / domain.Volume();
}

template double NominalPorosity<2>(const Domain<2>&, const std::vector<double>&);
template double NominalPorosity<3>(const Domain<3>&, const std::vector<double>&);
template int RemoveFlaggedParticles<2>(const std::vector<char>&, std::vector<Vector<2>>&,
                                       std::vector<double>&, std::vector<char>*);
template int RemoveFlaggedParticles<3>(const std::vector<char>&, std::vector<Vector<3>>&,
                                       std::vector<double>&, std::vector<char>*);
template double VolumeMeanRadius<2>(const std::vector<double>&);
template double VolumeMeanRadius<3>(const std::vector<double>&);
template double ParticleVolume<2>(double);
template double ParticleVolume<3>(double);
template void SetContactsFromCandidates<2>(Packing<2>&, const std::vector<std::array<int, 2>>&,
                                           double);
template void SetContactsFromCandidates<3>(Packing<3>&, const std::vector<std::array<int, 2>>&,
                                           double);

}  // namespace specimen
