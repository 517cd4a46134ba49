#pragma once
// The average strain of a particle assembly by Bagi's method (Labra 2012, section 4.2.2 and
// App. B; Bagi 1996; Madan (4.4)-(4.6)): the particle centres are triangulated (Delaunay,
// CGAL, in the reference configuration), the centre displacements are interpolated
// linearly (P1) over each cell, and the cell gradients are averaged with the cell volumes:
//
//   grad u = (1/V) sum_L V_L grad u_L,   grad u_L = (1/V_L) sum_k u_k (x) a_k^L      (B.9)
//
// where a_k^L = V_L grad N_k is the complementary area vector of vertex k of cell L
// (a_k = -b_k / D, b_k the outward area vector of the face opposite k, (B.1)-(B.2)).
// Regrouped by edges this is Bagi's form (B.13):
//
//   grad u = (1/V) sum_{edges pq} (u_p - u_q) (x) d^pq,  d^pq = 1/(D+1) sum_{L ∋ pq} (a_p^L - a_q^L)
//
// and regrouped by vertices, grad u = (1/V) sum_p u_p (x) w_p with w_p = sum_{L ∋ p} a_p^L,
// which vanishes at every vertex whose cells close around it: only the vertices on the
// boundary of the triangulated region carry weight (the average gradient is the boundary
// integral (1/V) ∮ u (x) n). That is how it is evaluated: O(boundary vertices) per call.
// The strain is the symmetric part; the skew part is the mean rotation.
//
// Identities (unit tested): V delta_ij = sum_{pq} l_i d_j with l = x_p - x_q (B.4, Labra
// (4.7)), and an affine displacement field u = H x gives grad u = H exactly.
//
// Region: by default every cell of the triangulation counts (the convex hull of the
// centres). A subset of particles can be given; a cell counts when all its vertices are in
// the subset (e.g. the interior of a specimen, away from the boundary layer).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "generator/domain.h"

namespace specimen {

template <int Dim>
class BagiStrain {
 public:
  using Matrix = Eigen::Matrix<double, Dim, Dim>;

  // Triangulates `reference_centres` (Delaunay). `included` is empty (every particle) or
  // holds one flag per particle. Throws InputError for fewer than Dim + 1 centres, a flag
  // array of the wrong size, or a region without cells of positive volume.
  explicit BagiStrain(const std::vector<Vector<Dim>>& reference_centres,
                      const std::vector<bool>& included = {});

  // Volume of the triangulated region, sum V_L [m^3; 2D: m^2 x 1 m].
  double volume() const { return volume_; }
  int cell_count() const { return static_cast<int>(cells_.size()); }
  const std::vector<std::array<int, Dim + 1>>& cells() const { return cells_; }

  // The average displacement gradient (B.9)/(B.13), H_ij = d u_i / d x_j, of the
  // displacements current - reference. `current_centres` has one entry per particle.
  Matrix DisplacementGradient(const std::vector<Vector<Dim>>& current_centres) const;
  // Its symmetric part: the average (small) strain, tension positive.
  Matrix Strain(const std::vector<Vector<Dim>>& current_centres) const;

  // The complementary area vector d^pq of every edge of the counted cells (B.3), p < q.
  struct EdgeVector {
    int p = 0;
    int q = 0;
    Vector<Dim> d = Vector<Dim>::Zero();
  };
  std::vector<EdgeVector> ComplementaryAreaVectors() const;

 private:
  // a_k^L of one cell, k = 0..Dim, with V_L.
  std::array<Vector<Dim>, Dim + 1> AreaVectors(const std::array<int, Dim + 1>& cell,
                                               double* cell_volume) const;

  std::vector<Vector<Dim>> reference_;
  std::vector<std::array<int, Dim + 1>> cells_;
  double volume_ = 0.0;
  // The vertices with a non-zero weight w_p (the boundary of the region), and the weights.
  std::vector<int> weighted_vertex_;
  std::vector<Vector<Dim>> weight_;
};

}  // namespace specimen
