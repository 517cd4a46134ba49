#pragma once
// Madan's lattice specimens (thesis sections 3.5, 3.6, 4.4):
// equal discs R = 1 mm, rho = 2000 kg/m^3, kn = 7e10 N/m, kt = 0, plane strain, 10 kN per
// top/bottom-row particle applied at the poles (s = +-R e_y), ramped; middle column held
// in x. SC: 9 columns x 20 rows; HCP: 17 rows alternating 6 and 7 discs.

#include <optional>
#include <vector>

#include "solver/regular_lattice.h"
#include "solver/simulation.h"

namespace specimen {
namespace madan {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadius = 1e-3;
constexpr double kDensity = 2000.0;
constexpr double kNormalStiffness = 7e10;
constexpr double kRowForce = 1e4;  // per top/bottom particle [N per m thickness]
constexpr double kParticlePoisson = 0.35;

struct Specimen {
  Packing<2> packing;
  std::vector<int> top, bottom;  // loaded rows
  std::vector<int> left, right;  // first and last disc of every row
  std::vector<int> middle;       // held in x
};

inline Specimen SquareSpecimen() {
  Specimen s{SquareLatticePacking(9, 20, kRadius), {}, {}, {}, {}, {}};
  for (int c = 0; c < 9; ++c) {
    s.bottom.push_back(c);
    s.top.push_back(19 * 9 + c);
  }
  for (int r = 0; r < 20; ++r) {
    s.left.push_back(r * 9);
    s.right.push_back(r * 9 + 8);
    s.middle.push_back(r * 9 + 4);
  }
  return s;
}

// 17 rows, 6 (even rows, incl. top and bottom) and 7 (odd rows) discs; the middle disc of
// every 7-disc row (x = 6R) is held in x.
inline Specimen HexagonalSpecimen() {
  Specimen s{HexagonalLatticePacking(17, 6, 7, kRadius), {}, {}, {}, {}, {}};
  int index = 0;
  for (int r = 0; r < 17; ++r) {
    const int discs = r % 2 == 0 ? 6 : 7;
    for (int c = 0; c < discs; ++c, ++index) {
      if (r == 0) s.bottom.push_back(index);
      if (r == 16) s.top.push_back(index);
      if (c == 0) s.left.push_back(index);
      if (c == discs - 1) s.right.push_back(index);
      if (discs == 7 && c == 3) s.middle.push_back(index);
    }
  }
  return s;
}

// The scene: loads ramped over ramp_s, kt = 0, local damping alpha (0 = undamped), DDEM
// when particle_modulus is given (plane strain, nu_p = 0.35 unless given).
inline SceneOptions<2> Scene(const Specimen& specimen, std::optional<double> particle_modulus,
                             double ramp_s, double damping,
                             double particle_poisson = kParticlePoisson) {
  SceneOptions<2> scene;
  MaterialParameters& m = scene.material;
  m.normal_stiffness_n_per_m = kNormalStiffness;
  m.density_kg_per_m3 = kDensity;
  m.particle_youngs_modulus_pa = particle_modulus;
  m.particle_poisson_ratio = particle_poisson;
  m.plane_model = PlaneModel::kPlaneStrain;
  m.translational_damping = damping;
  PointLoad<2> top;
  top.name = "top row";
  top.particles = specimen.top;
  top.force_n = Vector<2>(0.0, -kRowForce);
  top.application_direction = Vector<2>(0.0, 1.0);  // the top pole
  top.amplitude = Amplitude::Ramp(ramp_s);
  PointLoad<2> bottom = top;
  bottom.name = "bottom row";
  bottom.particles = specimen.bottom;
  bottom.force_n = Vector<2>(0.0, kRowForce);
  bottom.application_direction = Vector<2>(0.0, -1.0);
  scene.point_loads = {top, bottom};
  FixedDofs<2> middle;
  middle.name = "middle column";
  middle.particles = specimen.middle;
  middle.fix_translation = {true, false};
  scene.fixed_dofs = {middle};
  return scene;
}

// Centre-span changes: height (mean over columns top - bottom) and width (mean over rows
// right - left), from the initial packing.
struct Spans {
  double height_change_m = 0.0;
  double width_change_m = 0.0;
};

inline Spans MeasureSpans(const Specimen& specimen, const ParticleArrays<2>& particles) {
  Spans s;
  const auto& x0 = specimen.packing.centres;
  const auto& x = particles.position;
  for (size_t k = 0; k < specimen.top.size(); ++k) {
    const int t = specimen.top[k], b = specimen.bottom[k];
    s.height_change_m += ((x[t].y() - x[b].y()) - (x0[t].y() - x0[b].y())) / specimen.top.size();
  }
  for (size_t k = 0; k < specimen.left.size(); ++k) {
    const int l = specimen.left[k], r = specimen.right[k];
    s.width_change_m += ((x[r].x() - x[l].x()) - (x0[r].x() - x0[l].x())) / specimen.left.size();
  }
  return s;
}

// Closed forms for the SC specimen (thesis (2.67), (2.72), (2.75), (4.26), (4.27)).
struct SquareClosedForm {
  double height_change_m;  // shortening, positive
  double poisson;
  double youngs_modulus_pa;
};

inline SquareClosedForm SquareTheory(std::optional<double> particle_modulus,
                                     double nu_p = kParticlePoisson) {
  double k = kNormalStiffness;
  double poisson = 0.0;
  if (particle_modulus) {
    const double ep = *particle_modulus;
    const double kp = kPi * ep / (2.0 * (1.0 - nu_p * nu_p));   // (2.72)
    k = kNormalStiffness * kp / (2.0 * kNormalStiffness + kp);  // (2.67)
    poisson = 4.0 * nu_p * (1.0 + nu_p) * kNormalStiffness /
              (4.0 * (1.0 - nu_p * nu_p) * kNormalStiffness + kPi * ep);  // (4.27)
  }
  const double dh = 19.0 * kRowForce / k;  // (2.75)
  // Stress on the outer width A = 18 mm (4.20), strain on the centre span H = 38 mm.
  const double e = (9.0 * kRowForce / 0.018) / (dh / 0.038);
  return {dh, poisson, e};
}

}  // namespace madan
}  // namespace specimen
