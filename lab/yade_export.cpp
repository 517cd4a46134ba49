#include "lab/yade_export.h"

#include <cmath>
#include <ostream>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/format.h"
#include "lab/bonded_export.h"
#include "lab/lab_specimen.h"
#include "specimen_version.h"

namespace specimen {
namespace {

// The script after its constants: the scene, the at-rest check and the UCS, in Yade's Python
// (checked with Yade 2023.02a; tests/lab/yade_export_yade_test.cpp runs it).
constexpr const char* kScriptBody = R"PY(
_missing = [name for name in ("KN", "KT", "RN", "RT", "MU", "DENSITY") if globals()[name] is None]
# The UCS drive of run-test (lab/lab_test.h, "Loading rate"): the wave speed scale
# sqrt(kn / rho) in 2D (kn per metre of thickness), sqrt(kn / (rho r_mean)) in 3D; each platen
# moves at LOADING_RATE_GROUP x that scale after a ramp of RAMP_TRANSITS wave transits.
if not _missing:
    WAVE_SPEED = math.sqrt(KN / DENSITY) if DIMENSION == 2 else math.sqrt(KN / (DENSITY * R_MEAN))
    PLATEN_KN = PLATEN_STIFFNESS_RATIO * KN
    if UCS_AXIS is not None:
        PLATEN_SPEED = LOADING_RATE_GROUP * WAVE_SPEED
        RAMP_TIME_S = RAMP_TRANSITS * UCS_HEIGHT / WAVE_SPEED


def contact_mass(radius):
    """Mass and moment of inertia of a particle under this file's mass convention."""
    if DIMENSION == 2:
        # A disc of thickness THICKNESS, as this toolkit's 2D solver: m = rho pi r^2 l,
        # J = m r^2 / 2 (docs/solver.md, "Conventions").
        mass = DENSITY * math.pi * radius ** 2 * THICKNESS
        return mass, 0.5 * mass * radius ** 2
    mass = DENSITY * 4.0 / 3.0 * math.pi * radius ** 3
    return mass, 0.4 * mass * radius ** 2


def build(with_platens=True):
    """Bodies, bonds and (for a UCS specimen) the two platens. Returns the platen ids."""
    if _missing:
        raise SystemExit("the contact parameters " + ", ".join(_missing) + " are not set: export "
                         "with --parameters <name>_parameters.toml, or set them at the top of this file")
    O.reset()
    # The material only sets what CohFrictPhys takes from it when Yade creates a contact on its
    # own (after a bond broke): young = KN / R_MEAN gives kn = KN for two spheres of the mean
    # radius (Ip2: kn = 2 E r1 r2 / (r1 + r2)), poisson = KT / KN gives ks = KT there. The
    # bonds below get KN, KT and their strengths exactly.
    particle_material = O.materials.append(CohFrictMat(
        young=KN / R_MEAN, poisson=KT / KN if KN > 0 else 0.0, density=DENSITY,
        frictionAngle=math.atan(MU), isCohesive=True, fragile=True, momentRotationLaw=False,
        normalCohesion=0.0, shearCohesion=0.0, label="particles"))
    platen_material = O.materials.append(FrictMat(young=KN / R_MEAN, poisson=0.0, density=DENSITY,
                                                  frictionAngle=0.0, label="platens"))
    ids = []
    for x, y, z, r in SPHERES:
        body = utils.sphere((x, y, z), r, material=particle_material)
        body.state.mass, inertia = contact_mass(r)
        body.state.inertia = (inertia, inertia, inertia)
        if DIMENSION == 2:
            body.state.blockedDOFs = "zXY"  # discs: in-plane motion and rotation about z only
        ids.append(O.bodies.append(body))
    platens = []
    if with_platens and UCS_AXIS is not None:
        lower = min(s[UCS_AXIS] - s[3] for s in SPHERES)
        upper = max(s[UCS_AXIS] + s[3] for s in SPHERES)
        # Platens touch the extreme particles (run-test's walls), frictionless, stiffness
        # PLATEN_KN per contact: Ip2_FrictMat_FrictMat_FrictPhys takes kn and ks from MatchMakers.
        platens = [O.bodies.append(utils.wall(lower, UCS_AXIS, sense=0, material=platen_material)),
                   O.bodies.append(utils.wall(upper, UCS_AXIS, sense=0, material=platen_material))]
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()], label="collider"),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Wall_Sphere_ScGeom()],
            [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(),
             Ip2_FrictMat_FrictMat_FrictPhys(kn=MatchMaker(algo="val", val=PLATEN_KN),
                                             ks=MatchMaker(algo="val", val=0.0),
                                             frictAngle=MatchMaker(algo="val", val=0.0))],
            [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(), Law2_ScGeom_FrictPhys_CundallStrack()]),
        NewtonIntegrator(damping=LOCAL_DAMPING, gravity=(0, 0, 0), label="newton"),
        PyRunner(iterPeriod=FRESH_CONTACT_PERIOD, command="set_fresh_contacts()", label="fresh"),
    ]
    # Each bond: created by hand (the collider would miss a pair with a gap), then given this
    # toolkit's constants and its initial gap as the zero-force distance (unp).
    for i, j in BONDS:
        interaction = utils.createInteraction(ids[i], ids[j])
        phys = interaction.phys
        phys.kn, phys.ks = KN, KT
        phys.normalAdhesion, phys.shearAdhesion = RN, RT
        phys.unp = interaction.geom.penetrationDepth  # Fn = kn (penetrationDepth - unp) = 0 now
        phys.tangensOfFrictionAngle = MU
        phys.fragile = True               # a bond breaks once, for good
        phys.cohesionBroken = False
        phys.cohesionDisablesFriction = True  # shear strength RT alone, as |ft| > Rt here
        phys.initCohesion = False
        phys.momentRotationLaw = False
    O.dt = TIME_STEP_SAFETY * critical_time_step()
    return platens


def set_fresh_contacts():
    """Contacts Yade made on its own (after a bond broke) get this toolkit's kn, kt and mu."""
    for interaction in O.interactions:
        phys = interaction.phys
        if isinstance(phys, CohFrictPhys) and phys.cohesionBroken and phys.kn != KN:
            phys.kn, phys.ks, phys.tangensOfFrictionAngle = KN, KT, MU


def critical_time_step():
    """Madan (2.16)-(2.18): min over particles of 2 sqrt(m / k_eff), k_eff = sum over bonds and
    platen contacts of kn + kt (1 + m r^2 / J), times the local damping factor 1/sqrt(1 + alpha)."""
    stiffness = [0.0] * len(SPHERES)
    for i, j in BONDS:
        for q in (i, j):
            mass, inertia = contact_mass(SPHERES[q][3])
            k = KN + KT * (1.0 + mass * SPHERES[q][3] ** 2 / inertia)
            stiffness[q] += k
    bound = float("inf")
    for q, (x, y, z, r) in enumerate(SPHERES):
        mass, _ = contact_mass(r)
        k = max(stiffness[q], KN + KT) + PLATEN_KN
        bound = min(bound, 2.0 * math.sqrt(mass / k))
    return bound / math.sqrt(1.0 + LOCAL_DAMPING)


def bond_state():
    """Largest |normal force| over the intact bonds [N], and the number of broken bonds."""
    largest, broken = 0.0, 0
    for i, j in BONDS:
        interaction = O.interactions[i, j] if O.interactions.has(i, j) else None
        if interaction is None or not interaction.isReal or interaction.phys.cohesionBroken:
            broken += 1
            continue
        largest = max(largest, interaction.phys.normalForce.norm())
    return largest, broken


def check_at_rest(steps):
    """Runs `steps` steps without load: the largest bond force after the first one and the
    bonds broken by the end (both zero for a specimen that starts at rest)."""
    build(with_platens=False)
    O.step()
    first, _ = bond_state()
    O.run(steps - 1, True)
    last, broken = bond_state()
    return {"dimension": DIMENSION, "particles": len(SPHERES), "bonds": len(BONDS),
            "steps": steps, "time_step_s": O.dt, "kn": KN, "mean_radius_m": R_MEAN,
            "largest_bond_force_step_1_n": first, "largest_bond_force_end_n": last,
            "broken_bonds": broken}


def linear_modulus(samples):
    """The ISRM average modulus of the linear portion, as run-test measures it (docs/lab.md,
    "Linear portion, intact"): the least-squares slope of stress against strain over the samples
    before the first broken bond, from LINEAR_PORTION_LOW x the largest stress among them."""
    intact = []
    for sample in samples:
        if sample["broken_bonds"] > 0:
            break
        intact.append(sample)
    if not intact:
        return None
    top = max(s["stress_pa"] for s in intact)
    used = [s for s in intact if s["stress_pa"] >= LINEAR_PORTION_LOW * top]
    if len(used) < 4:
        return None
    n = float(len(used))
    mean_e = sum(s["strain"] for s in used) / n
    mean_s = sum(s["stress_pa"] for s in used) / n
    sxx = sum((s["strain"] - mean_e) ** 2 for s in used)
    sxy = sum((s["strain"] - mean_e) * (s["stress_pa"] - mean_s) for s in used)
    return sxy / sxx if sxx > 0 else None


def run_ucs(strain_limit, stop_at_first_break, curve_path=None):
    """Uniaxial compression between the platens, each moving at PLATEN_SPEED towards the other
    after a linear ramp over RAMP_TIME_S (run-test's drive, without its pauses on breakage).
    Stress = mean platen force / UCS_AREA, strain = platen approach / initial gap. Stops at
    strain_limit, at the first broken bond (stop_at_first_break), or once the stress has fallen
    to POST_PEAK_FRACTION of its peak."""
    if UCS_AXIS is None:
        raise SystemExit("no UCS for this specimen: " + UCS_REFUSAL)
    bottom, top = build(with_platens=True)
    axis = UCS_AXIS
    gap0 = O.bodies[top].state.pos[axis] - O.bodies[bottom].state.pos[axis]
    samples, peak = [], 0.0
    while True:
        t = O.time
        speed = PLATEN_SPEED * min(1.0, t / RAMP_TIME_S) if RAMP_TIME_S > 0 else PLATEN_SPEED
        velocity = [0.0, 0.0, 0.0]
        velocity[axis] = speed
        O.bodies[bottom].state.vel = velocity
        velocity[axis] = -speed
        O.bodies[top].state.vel = velocity
        O.run(SAMPLE_INTERVAL, True)
        gap = O.bodies[top].state.pos[axis] - O.bodies[bottom].state.pos[axis]
        # O.forces holds the last step's forces: the particles push the bottom platen down and
        # the top one up, so the mean compression is half their difference along the axis.
        force = 0.5 * (O.forces.f(top)[axis] - O.forces.f(bottom)[axis])
        _, broken = bond_state()
        sample = {"step": O.iter, "time_s": O.time, "strain": (gap0 - gap) / gap0,
                  "stress_pa": force / UCS_AREA,
                  "platen_force_n": force, "broken_bonds": broken}
        samples.append(sample)
        peak = max(peak, sample["stress_pa"])
        if sample["strain"] >= strain_limit:
            break
        if stop_at_first_break and broken > 0:
            break
        if peak > 0 and broken > 0 and sample["stress_pa"] <= POST_PEAK_FRACTION * peak:
            break
    if curve_path:
        with open(curve_path, "w") as out:
            out.write("step,time_s,strain,stress_pa,platen_force_n,broken_bonds\n")
            for s in samples:
                out.write("%d,%.17g,%.17g,%.17g,%.17g,%d\n" % (s["step"], s["time_s"], s["strain"],
                                                                s["stress_pa"], s["platen_force_n"],
                                                                s["broken_bonds"]))
    return {"dimension": DIMENSION, "particles": len(SPHERES), "bonds": len(BONDS),
            "steps": O.iter, "time_step_s": O.dt, "platen_speed_m_per_s": PLATEN_SPEED,
            "peak_stress_pa": peak, "youngs_modulus_pa": linear_modulus(samples),
            "samples": len(samples), "broken_bonds": samples[-1]["broken_bonds"] if samples else 0}


def main(argv):
    import argparse
    parser = argparse.ArgumentParser(prog="yade -x " + (argv[0] if argv else "this file"),
                                     description="The bonded specimen of this file in Yade.")
    parser.add_argument("--run", choices=["build", "at-rest", "ucs"], default="build",
                        help="build: the scene only (default; run it from the GUI without -x); "
                        "at-rest: STEPS steps without load, then the largest bond force and the "
                        "broken bonds; ucs: the uniaxial compression between the platens")
    parser.add_argument("--steps", type=int, default=1000, help="at-rest: steps (>= 1), default 1000")
    parser.add_argument("--strain-limit", type=float, default=0.02,
                        help="ucs: stop at this platen strain, in (0, 0.5); default 0.02")
    parser.add_argument("--until-first-break", action="store_true",
                        help="ucs: stop at the first broken bond (enough for E)")
    parser.add_argument("--curve", default=None, help="ucs: write the curve to this CSV file")
    parser.add_argument("--json", default=None, help="write the result to this JSON file")
    args = parser.parse_args(argv[1:])
    if args.run == "build":
        build()
        return None
    if args.run == "at-rest":
        if args.steps < 1:
            parser.error("--steps = %d is not allowed: it must be >= 1" % args.steps)
        result = check_at_rest(args.steps)
    else:
        if not 0.0 < args.strain_limit < 0.5:
            parser.error("--strain-limit = %g is not allowed: it must be in (0, 0.5)" % args.strain_limit)
        result = run_ucs(args.strain_limit, args.until_first_break, args.curve)
    report(result, args.json)
    return result


main(sys.argv)
)PY";

}  // namespace

template <int Dim>
void WriteYadeScript(const Packing<Dim>& packing, const YadeExportOptions& options, std::ostream& out) {
  RequireBondedExportable(packing, options.bond_gap_tolerance, "Yade script");
  if (!(options.time_step_safety > 0.0 && options.time_step_safety <= 1.0))
    throw InputError("time_step_safety = " + Number(options.time_step_safety) +
                     " is not allowed: it must be in (0, 1]");
  std::string error;
  if (!options.ucs.IsValid(&error)) throw InputError(error);
  const std::string source = options.parameters_source.empty() ? "the parameters" : options.parameters_source;
  if (options.material)
    RequireRigidPairBonds(*options.material, source, "Yade",
                          "CohFrictPhys checks its moment limits apart from the force, not on the combined "
                          "peripheral stress");

  // The UCS platens need run-test's specimen shapes (a rectangle, a box or a cylinder that
  // the particles fill); another packing is exported without them, the script says why.
  std::optional<LabSpecimen<Dim>> ucs;
  std::string ucs_refusal;
  try {
    ucs = DescribeSpecimen<Dim>(packing, LabTestKind::kUniaxialCompression, options.ucs.strain_boundary_margin);
  } catch (const InputError& e) {
    ucs_refusal = e.what();
  }
  const std::vector<std::array<int, 2>> bonds = ExportedBonds(packing, options.bond_gap_tolerance);
  const MaterialParameters* m = options.material ? &*options.material : nullptr;

  out << "# Bonded specimen for Yade (checked with Yade 2023.02a), written by export-specimen " << kVersion << ".\n"
      << "# packing: " << PythonText(options.packing_source) << " (" << PythonText(packing.created_by) << ")\n"
      << "# parameters: " << (m ? PythonText(source) : std::string("none: set KN ... DENSITY below")) << "\n"
      << "#\n"
      << "#   yade -x -n <this file> --run at-rest [--steps 1000]   bonds at rest, nothing broken\n"
      << "#   yade -x -n <this file> --run ucs [--curve ucs.csv]     uniaxial compression, E and peak\n"
      << "#   yade <this file>                                       the scene in the GUI\n"
      << "#\n"
      << "# Contact law: Law2_ScGeom6D_CohFrictPhys_CohesionMoment. Every bond is made by hand and given\n"
      << "# this toolkit's constants per contact: kn = KN, ks = KT [N/m], normalAdhesion = RN,\n"
      << "# shearAdhesion = RT [N] (strengths as forces), friction tan(phi) = MU, fragile, the shear\n"
      << "# limit RT alone (cohesionDisablesFriction), and unp = its initial penetration depth, so that\n"
      << "# Fn = kn (penetrationDepth - unp) is zero at the packing's gap: the specimen starts at rest.\n"
      << "# Bonds: the listed pairs with |gap| <= " << ExactDouble(options.bond_gap_tolerance)
      << " (ri + rj)/2, as this toolkit's solver bonds them.\n"
      << "#\n"
      << "# Mass convention: "
      << (Dim == 2 ? "2D. The discs are spheres at z = 0 kept in the plane (blockedDOFs zXY) with the\n"
                     "# mass and inertia of discs of thickness THICKNESS = 1 m: m = rho pi r^2 l, J = m r^2 / 2\n"
                     "# (not the sphere's 4/3 pi r^3 rho). KN, KT, RN, RT are per metre of thickness, as in\n"
                     "# this toolkit, so the forces are the same; stresses are per metre of thickness.\n"
                   : "3D spheres, m = 4/3 pi r^3 rho, J = 2/5 m r^2, as in this toolkit.\n")
      << "# DENSITY is the parameter file's density, before run-test's scale_density.\n"
      << "#\n"
      << "# Not carried over: contact dashpots (run-test's dashpot_ratio; only the local damping is),\n"
      << "# run-test's pauses on breakage and its inertia scaling. Contacts Yade makes on its own after\n"
      << "# a bond broke get KN, KT, MU within FRESH_CONTACT_PERIOD steps (set_fresh_contacts).\n"
      << "import json\n"
      << "import math\n"
      << "import sys\n\n"
      << "from yade import utils\n"
      << "from yade.wrapper import *\n\n"
      << "DIMENSION = " << Dim << "\n"
      << "THICKNESS = 1.0  # [m], 2D only\n";
  WritePythonMaterialConstants(m, out);
  out << "R_MEAN = " << ExactDouble(VolumeMeanRadius<Dim>(packing.radii)) << "  # volume-based mean radius [m]\n"
      << "# run-test's UCS (lab/lab_test.h)\n"
      << "LOADING_RATE_GROUP = " << ExactDouble(options.ucs.loading_rate_group) << "\n"
      << "RAMP_TRANSITS = " << ExactDouble(options.ucs.velocity_ramp_transits) << "\n"
      << "PLATEN_STIFFNESS_RATIO = " << ExactDouble(options.ucs.platen_stiffness_ratio) << "\n"
      << "LOCAL_DAMPING = " << ExactDouble(options.ucs.local_damping) << "\n"
      << "SAMPLE_INTERVAL = " << options.ucs.sample_interval_steps << "\n"
      << "LINEAR_PORTION_LOW = " << ExactDouble(options.ucs.linear_portion_low) << "\n"
      << "POST_PEAK_FRACTION = " << ExactDouble(options.ucs.post_peak_stress_fraction) << "\n"
      << "TIME_STEP_SAFETY = " << ExactDouble(options.time_step_safety) << "\n"
      << "FRESH_CONTACT_PERIOD = 100\n";
  if (ucs) {
    out << "UCS_AXIS = " << ucs->axis << "  # loading axis (0 x, 1 y, 2 z)\n"
        << "UCS_HEIGHT = " << ExactDouble(ucs->height_m) << "  # [m], extent of the particles along it\n"
        << "UCS_AREA = " << ExactDouble(ucs->cross_section_m2) << "  # [m^2] (2D: width x 1 m), as run-test\n"
        << "UCS_REFUSAL = None\n";
  } else {
    out << "UCS_AXIS = None\nUCS_HEIGHT = None\nUCS_AREA = None\n"
        << "UCS_REFUSAL = \"" << PythonText(ucs_refusal) << "\"\n";
  }
  out << "# particle i of the packing: (x, y, z, r) [m]" << (Dim == 2 ? ", z = 0" : "") << "\n"
      << "SPHERES = [\n";
  for (int i = 0; i < packing.size(); ++i) {
    const auto& c = packing.centres[i];
    out << "    (" << ExactDouble(c[0]) << ", " << ExactDouble(c[1]) << ", "
        << (Dim == 3 ? ExactDouble(c[Dim - 1]) : std::string("0.0")) << ", " << ExactDouble(packing.radii[i]) << "),\n";
  }
  out << "]\n# bonds: particle indices (i, j)\nBONDS = [\n";
  for (const auto& b : bonds) out << "    (" << b[0] << ", " << b[1] << "),\n";
  out << "]\n" << kPythonReportFunction << kScriptBody;
}

template <int Dim>
void SaveYadeScript(const Packing<Dim>& packing, const YadeExportOptions& options, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { WriteYadeScript(packing, options, out); });
}

template void WriteYadeScript<2>(const Packing<2>&, const YadeExportOptions&, std::ostream&);
template void WriteYadeScript<3>(const Packing<3>&, const YadeExportOptions&, std::ostream&);
template void SaveYadeScript<2>(const Packing<2>&, const YadeExportOptions&, const std::string&);
template void SaveYadeScript<3>(const Packing<3>&, const YadeExportOptions&, const std::string&);

}  // namespace specimen
