#include "solver/bond_range.h"

#include <algorithm>
#include <utility>

#include "solver/neighbour_search.h"

namespace specimen {

template <int Dim>
std::vector<std::array<int, 2>> BondCandidatePairs(const Packing<Dim>& packing, double bond_range) {
  std::vector<std::array<int, 2>> pairs = packing.contacts;
  for (auto& pair : pairs)
    if (pair[0] > pair[1]) std::swap(pair[0], pair[1]);
  if (bond_range > 1.0 && packing.size() > 1) {
    // Candidates within ri + rj + (gamma - 1) 2 r_max hold every pair within gamma (ri + rj).
    const double r_max = *std::max_element(packing.radii.begin(), packing.radii.end());
    std::vector<std::array<int, 2>> near;
    CandidateSearch<Dim> search;
    search.FindPairs(packing.centres, packing.radii, 2.0 * (bond_range - 1.0) * r_max, &near);
    for (const auto& [i, j] : near)
      if (WithinBondRange((packing.centres[j] - packing.centres[i]).norm(), packing.radii[i], packing.radii[j],
                          bond_range))
        pairs.push_back({i, j});
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

template std::vector<std::array<int, 2>> BondCandidatePairs<2>(const Packing<2>&, double);
template std::vector<std::array<int, 2>> BondCandidatePairs<3>(const Packing<3>&, double);

}  // namespace specimen
