#include "lab/esys_export.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <ostream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/format.h"
#include "specimen_version.h"

namespace specimen {
namespace {

// The script after its constants, in ESyS-Particle's Python (checked with ESyS-Particle 2.3.5;
// tests/lab/esys_export_test.cpp runs it).
constexpr const char* kScriptBody = R"PY(
_missing = [name for name in ("KN", "KT", "RN", "RT", "MU", "DENSITY") if globals()[name] is None]
HERE = os.path.dirname(os.path.abspath(sys.argv[0]))


def read_geometry(path):
    """Particles [(x, y, z, r)] (particle i of the packing is ESyS id i) and bonds [(i, j, tag)]."""
    with open(path) as f:
        words = f.read().split()
    start = words.index("Simple") + 1
    count = int(words[start])
    particles = [tuple(float(v) for v in words[start + 1 + 6 * k:start + 5 + 6 * k]) for k in range(count)]
    start = words.index("BeginConnect") + 1
    count = int(words[start])
    bonds = [tuple(int(v) for v in words[start + 1 + 3 * k:start + 4 + 3 * k]) for k in range(count)]
    return particles, bonds


def particle_mass(radius):
    """Mass and moment of inertia as ESyS-Particle gives them (2D: discs of unit thickness)."""
    if DIMENSION == 2:
        mass = DENSITY * math.pi * radius ** 2
        return mass, 0.5 * mass * radius ** 2
    mass = DENSITY * 4.0 / 3.0 * math.pi * radius ** 3
    return mass, 0.4 * mass * radius ** 2


def critical_time_step(particles, bonds):
    """Madan (2.16)-(2.18): min over particles of 2 sqrt(m / k_eff), k_eff = sum over bonds of
    kn + kt (1 + m r^2 / J), times the local damping factor 1/sqrt(1 + alpha)."""
    stiffness = [KN + KT] * len(particles)
    for i, j, _ in bonds:
        for q in (i, j):
            mass, inertia = particle_mass(particles[q][3])
            stiffness[q] += KN + KT * (1.0 + mass * particles[q][3] ** 2 / inertia)
    bound = min(2.0 * math.sqrt(particle_mass(p[3])[0] / k) for p, k in zip(particles, stiffness))
    return bound / math.sqrt(1.0 + LOCAL_DAMPING)


def build(steps, law, output_dir):
    """The simulation object with the particles, the bonds (law "toolkit": each bond as a short
    normal bond at rest at d0 and a shear-only rotational bond; law "rotbond": ESyS's own
    rotational bond with kn, whose rest length is ri + rj), contacts after breakage, damping,
    and the savers of every bond's force at step 1 and at the last step."""
    if _missing:
        raise SystemExit("the contact parameters " + ", ".join(_missing) + " are not set: export "
                         "with --parameters <name>_parameters.toml, or set them at the top of this file")
    from esys.lsm import (LsmMpi, NRotShortBondPrms, RotBondPrms, RotFrictionPrms, LocalDampingPrms,
                          RotLocalDampingPrms, InteractionVectorFieldSaverPrms)
    from esys.lsm.util import Vec3, BoundingBox
    geometry = os.path.join(HERE, GEOMETRY)
    particles, bonds = read_geometry(geometry)
    radii = [p[3] for p in particles]
    workers = max(1, int(os.environ.get("OMPI_COMM_WORLD_SIZE", "2")) - 1)
    sim = LsmMpi(numWorkerProcesses=workers, mpiDimList=[workers, 1, 1])
    sim.initNeighbourSearch(particleType="RotSphere", gridSpacing=2.5 * max(radii), verletDist=0.1 * min(radii))
    if DIMENSION == 2:
        sim.force2dComputations(True)
    margin = 4.0 * max(radii)
    lower = [min(p[k] for p in particles) - margin for k in range(3)]
    upper = [max(p[k] for p in particles) + margin for k in range(3)]
    sim.setSpatialDomain(BoundingBox(Vec3(*lower), Vec3(*upper)))
    sim.readGeometry(geometry)
    sim.setParticleDensity(tag=0, mask=-1, Density=DENSITY)
    sim.setTimeStepSize(TIME_STEP_SAFETY * critical_time_step(particles, bonds))
    sim.setNumTimeSteps(steps)
    groups = []
    for tag, length in BOND_GROUPS:
        if law == "toolkit":
            names = ["normal_%d" % tag, "shear_%d" % tag]
            sim.createInteractionGroup(NRotShortBondPrms(name=names[0], normalK=KN, breakDistance=RN / (KN * length),
                                                         tag=tag))
            sim.createInteractionGroup(RotBondPrms(
                name=names[1], normalK=0.0, shearK=KT, torsionK=0.0, bendingK=0.0, normalBrkForce=RN,
                shearBrkForce=RT, torsionBrkForce=1.0, bendingBrkForce=1.0, tag=tag, scaling=False))
        else:
            names = ["rotbond_%d" % tag]
            sim.createInteractionGroup(RotBondPrms(
                name=names[0], normalK=KN, shearK=KT, torsionK=0.0, bendingK=0.0, normalBrkForce=RN,
                shearBrkForce=RT, torsionBrkForce=1.0, bendingBrkForce=1.0, tag=tag, scaling=False))
        groups += names
    sim.createInteractionGroup(RotFrictionPrms(name="friction", normalK=KN, dynamicMu=MU, staticMu=MU, shearK=KT,
                                               scaling=False))
    for name in groups:
        sim.createExclusion(interactionName1=name, interactionName2="friction")
    sim.createInteractionGroup(LocalDampingPrms(name="damping", viscosity=LOCAL_DAMPING))
    sim.createInteractionGroup(RotLocalDampingPrms(name="rotational_damping", viscosity=LOCAL_DAMPING))
    for name in groups:
        sim.createFieldSaver(InteractionVectorFieldSaverPrms(
            interactionName=name, fieldName="force", fileName=os.path.join(output_dir, name + "_force.dat"),
            fileFormat="RAW_WITH_ID", beginTimeStep=1, endTimeStep=steps, timeStepIncr=max(1, steps - 1)))
    return sim, particles, bonds, groups


def saved_forces(output_dir, name, index):
    """{(i, j): |force|} of the intact bonds of group `name` in its save `index` (0: step 1)."""
    forces = {}
    with open(os.path.join(output_dir, "%s_force.dat.%d.dat" % (name, index))) as f:
        for line in f:
            v = line.split()
            if len(v) >= 8:
                forces[(int(v[0]), int(v[1]))] = math.sqrt(sum(float(c) ** 2 for c in v[-3:]))
    return forces


def check_at_rest(steps, law, output_dir):
    """Runs `steps` steps without load: the largest bond force at step 1 and at the end, and the
    bonds with a broken part by the end."""
    os.makedirs(output_dir, exist_ok=True)
    sim, particles, bonds, groups = build(steps, law, output_dir)
    sim.run()
    largest = []
    intact_at_end = None
    for index in (0, 1 if steps > 1 else 0):
        top = 0.0
        intact = None
        for part in ("normal", "shear", "rotbond"):
            forces = {}
            for name in groups:
                if name.startswith(part + "_"):
                    forces.update(saved_forces(output_dir, name, index))
            if not any(name.startswith(part + "_") for name in groups):
                continue
            top = max([top] + list(forces.values()))
            pairs = set((min(i, j), max(i, j)) for i, j in forces)
            intact = pairs if intact is None else intact & pairs
        largest.append(top)
        intact_at_end = intact
    return {"dimension": DIMENSION, "particles": len(particles), "bonds": len(bonds), "bond_law": law,
            "bond_groups": len(BOND_GROUPS), "steps": steps, "time_step_s": sim.getTimeStepSize(),
            "kn": KN, "mean_radius_m": R_MEAN, "largest_bond_force_step_1_n": largest[0],
            "largest_bond_force_end_n": largest[1], "broken_bonds": len(bonds) - len(intact_at_end),
            "esys_version": sim.getLsmVersion()}


def main(argv):
    import argparse
    parser = argparse.ArgumentParser(prog="mpirun -np 2 esysparticle " + (argv[0] if argv else "this file"),
                                     description="The bonded specimen of this file in ESyS-Particle.")
    parser.add_argument("--run", choices=["at-rest"], default="at-rest",
                        help="at-rest: STEPS steps without load, then the largest bond force and the broken bonds")
    parser.add_argument("--steps", type=int, default=1000, help="steps (>= 1), default 1000")
    parser.add_argument("--bond-law", choices=["toolkit", "rotbond"], default="toolkit",
                        help="toolkit: the bonds of this file's header (default); rotbond: ESyS's rotational "
                        "bond with kn, kt, Rn, Rt, whose rest length is ri + rj (for comparison)")
    parser.add_argument("--output-dir", default=None,
                        help="where ESyS writes the bond forces; default: <this file's name>_out next to it")
    parser.add_argument("--json", default=None, help="write the result to this JSON file")
    args = parser.parse_args(argv[1:])
    if args.steps < 1:
        parser.error("--steps = %d is not allowed: it must be >= 1" % args.steps)
    output_dir = args.output_dir or os.path.splitext(os.path.abspath(argv[0]))[0] + "_out"
    result = check_at_rest(args.steps, args.bond_law, output_dir)
    report(result, args.json)
    return result


main(sys.argv)
)PY";

void CheckOptions(const EsysExportOptions& options) {
  if (!(options.tension_group_width > 0.0 && options.tension_group_width <= 1.0))
    throw InputError("tension_group_width = " + Number(options.tension_group_width) +
                     " is not allowed: it must be in (0, 1]");
  if (!(options.local_damping >= 0.0 && options.local_damping < 1.0))
    throw InputError("local_damping = " + Number(options.local_damping) + " is not allowed: it must be in [0, 1)");
  if (!(options.time_step_safety > 0.0 && options.time_step_safety <= 1.0))
    throw InputError("time_step_safety = " + Number(options.time_step_safety) +
                     " is not allowed: it must be in (0, 1]");
  if (options.material)
    RequireRigidPairBonds(*options.material,
                          options.parameters_source.empty() ? "the parameters" : options.parameters_source,
                          "ESyS-Particle",
                          "the normal force is carried by a short bond apart from the rotational bond, so the "
                          "combined peripheral stress of the force and the moment cannot be checked in one bond");
}

template <int Dim>
double InitialLength(const Packing<Dim>& packing, const std::array<int, 2>& bond) {
  return (packing.centres[bond[1]] - packing.centres[bond[0]]).norm();
}

// The tag of every bond (1-based group number), in bond order.
std::vector<int> BondTags(const std::vector<EsysBondGroup>& groups, size_t bond_count) {
  std::vector<int> tags(bond_count, 0);
  for (const auto& group : groups)
    for (int b : group.bonds) tags[b] = group.tag;
  return tags;
}

}  // namespace

template <int Dim>
std::vector<EsysBondGroup> EsysBondGroups(const Packing<Dim>& packing, const std::vector<std::array<int, 2>>& bonds,
                                          double width) {
  std::vector<int> order(bonds.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<double> length(bonds.size());
  for (size_t b = 0; b < bonds.size(); ++b) length[b] = InitialLength(packing, bonds[b]);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return length[a] < length[b]; });
  std::vector<EsysBondGroup> groups;
  double smallest = 0.0;
  for (int b : order) {
    if (groups.empty() || length[b] > smallest * (1.0 + width)) {
      groups.push_back(EsysBondGroup{static_cast<int>(groups.size()) + 1, 0.0, {}});
      smallest = length[b];
    }
    groups.back().bonds.push_back(b);
    groups.back().length_m = 0.5 * (smallest + length[b]);  // the middle of the group's range
  }
  return groups;
}

template <int Dim>
void WriteEsysGeometry(const Packing<Dim>& packing, const EsysExportOptions& options, std::ostream& out) {
  RequireBondedExportable(packing, options.bond_gap_tolerance, "ESyS-Particle geometry");
  CheckOptions(options);
  const std::vector<std::array<int, 2>> bonds = ExportedBonds(packing, options.bond_gap_tolerance);
  const std::vector<int> tags = BondTags(EsysBondGroups(packing, bonds, options.tension_group_width), bonds.size());
  Vector<Dim> lower = packing.centres[0], upper = packing.centres[0];
  for (const auto& c : packing.centres)
    for (int k = 0; k < Dim; ++k) {
      lower[k] = std::min(lower[k], c[k]);
      upper[k] = std::max(upper[k], c[k]);
    }
  auto xyz = [](const Vector<Dim>& v) {
    return ExactDouble(v[0]) + " " + ExactDouble(v[1]) + " " + (Dim == 3 ? ExactDouble(v[Dim - 1]) : std::string("0"));
  };
  // The format has no comment lines: what the file holds is stated in the script's header.
  out << "LSMGeometry 1.2\n"
      << "BoundingBox " << xyz(lower) << " " << xyz(upper) << "\n"
      << "PeriodicBoundaries 0 0 0\n"
      << "Dimension " << Dim << "D\n"
      << "BeginParticles\nSimple\n" << packing.size() << "\n";
  for (int i = 0; i < packing.size(); ++i)
    out << xyz(packing.centres[i]) << " " << ExactDouble(packing.radii[i]) << " " << i << " 0\n";
  out << "EndParticles\nBeginConnect\n" << bonds.size() << "\n";
  for (size_t b = 0; b < bonds.size(); ++b) out << bonds[b][0] << " " << bonds[b][1] << " " << tags[b] << "\n";
  out << "EndConnect\n";
}

template <int Dim>
void WriteEsysScript(const Packing<Dim>& packing, const EsysExportOptions& options, std::ostream& out) {
  RequireBondedExportable(packing, options.bond_gap_tolerance, "ESyS-Particle script");
  CheckOptions(options);
  const std::vector<std::array<int, 2>> bonds = ExportedBonds(packing, options.bond_gap_tolerance);
  const std::vector<EsysBondGroup> groups = EsysBondGroups(packing, bonds, options.tension_group_width);
  // What the grouping and ESyS's shear measure cost, bond by bond.
  double tension_error = 0.0, shear_stiffness_error = 0.0;
  for (const auto& group : groups)
    for (int b : group.bonds) {
      const double d0 = InitialLength(packing, bonds[b]);
      tension_error = std::max(tension_error, std::abs(d0 / group.length_m - 1.0));
      const double contact = packing.radii[bonds[b][0]] + packing.radii[bonds[b][1]];
      shear_stiffness_error = std::max(shear_stiffness_error, std::abs(contact / d0 - 1.0));
    }
  const MaterialParameters* m = options.material ? &*options.material : nullptr;
  out << "# Bonded specimen for ESyS-Particle (checked with ESyS-Particle 2.3.5), written by export-specimen "
      << kVersion << ".\n"
      << "# packing: " << PythonText(options.packing_source) << " (" << PythonText(packing.created_by) << ")\n"
      << "# parameters: "
      << (m ? PythonText(options.parameters_source.empty() ? "given" : options.parameters_source)
            : std::string("none: set KN ... DENSITY below"))
      << "\n# geometry: " << PythonText(options.geometry_name) << " (particle i of the packing is ESyS id i)\n"
      << "#\n"
      << "#   mpirun -np 2 esysparticle <this file> --run at-rest [--steps 1000]   bonds at rest, none broken\n"
      << "#   (1 master + 1 worker; -np N + 1 for N workers)\n"
      << "#\n"
      << "# Bonds: the listed pairs with |gap| <= " << ExactDouble(options.bond_gap_tolerance)
      << " (ri + rj)/2, as this toolkit's solver bonds them: " << bonds.size() << ".\n"
      << "# ESyS-Particle 2.3.5's rotational bond (RotBondPrms, BrittleBeamPrms) and NRotBondPrms take ri + rj as\n"
      << "# the rest length of the normal spring, so a bond across a gap would start with kn x gap. Each bond is\n"
      << "# therefore two ESyS bonds on the same pair, tagged with its group:\n"
      << "#   normal: NRotShortBondPrms, normalK = KN, rest length = the initial distance d0 (force 0 at\n"
      << "#           the start); it breaks when the stretch exceeds breakDistance x d0, breakDistance =\n"
      << "#           RN / (KN x the group's length): bonds grouped by d0 (" << groups.size()
      << " groups), tension limit RN\n"
      << "#           within " << Number(100.0 * tension_error, 3) << " % for every bond;\n"
      << "#   shear:  RotBondPrms, scaling False, normalK 0, shearK = KT, no torsion or bending, shearBrkForce\n"
      << "#           = RT: at rest at the start, breaks when |Fs| > RT. Its shear displacement is (ri + rj) x\n"
      << "#           the rotation of the branch, so its stiffness is KT (ri + rj)/d0: within "
      << Number(100.0 * shear_stiffness_error, 3) << " % of KT here.\n"
      << "# The two halves break separately (here a bond breaks as a whole). Contacts after breakage:\n"
      << "# RotFrictionPrms (KN, KT, MU, scaling False), excluded while a bond of the pair holds.\n"
      << "#\n"
      << "# Mass convention: "
      << (Dim == 2 ? "2D (force2dComputations): ESyS gives discs of unit thickness, m = rho pi r^2 per\n"
                     "# metre, J = m r^2 / 2, as this toolkit's 2D solver (not the sphere's 4/3 pi r^3 rho); KN, KT,\n"
                     "# RN, RT are per metre of thickness, so the forces are this toolkit's.\n"
                   : "3D spheres, m = 4/3 pi r^3 rho, J = 2/5 m r^2, as in this toolkit.\n")
      << "# DENSITY is the parameter file's density, before run-test's scale_density.\n"
      << "# Not carried over: contact dashpots, run-test's pauses on breakage and its inertia scaling.\n"
      << "import json\nimport math\nimport os\nimport sys\n\n"
      << "DIMENSION = " << Dim << "\n";
  WritePythonMaterialConstants(m, out);
  out << "R_MEAN = " << ExactDouble(VolumeMeanRadius<Dim>(packing.radii)) << "  # volume-based mean radius [m]\n"
      << "GEOMETRY = \"" << PythonText(options.geometry_name) << "\"  # relative to this file's directory\n"
      << "LOCAL_DAMPING = " << ExactDouble(options.local_damping) << "\n"
      << "TIME_STEP_SAFETY = " << ExactDouble(options.time_step_safety) << "\n"
      << "# bond groups: (tag, length [m]), the middle of the group's initial lengths\n"
      << "BOND_GROUPS = [\n";
  for (const auto& group : groups) out << "    (" << group.tag << ", " << ExactDouble(group.length_m) << "),\n";
  out << "]\n" << kPythonReportFunction << kScriptBody;
}

template <int Dim>
void SaveEsysSpecimen(const Packing<Dim>& packing, EsysExportOptions options, const std::string& script_path,
                      const std::string& geometry_path) {
  options.geometry_name = std::filesystem::path(geometry_path).filename().string();
  OutputGroup files;
  files.Add(geometry_path, [&](std::ostream& out) { WriteEsysGeometry(packing, options, out); });
  files.Add(script_path, [&](std::ostream& out) { WriteEsysScript(packing, options, out); });
  files.Commit();
}

template std::vector<EsysBondGroup> EsysBondGroups<2>(const Packing<2>&, const std::vector<std::array<int, 2>>&,
                                                      double);
template std::vector<EsysBondGroup> EsysBondGroups<3>(const Packing<3>&, const std::vector<std::array<int, 2>>&,
                                                      double);
template void WriteEsysGeometry<2>(const Packing<2>&, const EsysExportOptions&, std::ostream&);
template void WriteEsysGeometry<3>(const Packing<3>&, const EsysExportOptions&, std::ostream&);
template void WriteEsysScript<2>(const Packing<2>&, const EsysExportOptions&, std::ostream&);
template void WriteEsysScript<3>(const Packing<3>&, const EsysExportOptions&, std::ostream&);
template void SaveEsysSpecimen<2>(const Packing<2>&, EsysExportOptions, const std::string&, const std::string&);
template void SaveEsysSpecimen<3>(const Packing<3>&, EsysExportOptions, const std::string&, const std::string&);

}  // namespace specimen
