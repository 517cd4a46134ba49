# Yade side of the solver speed benchmark ("Speed"): the bonded specimen of
# solver-throughput, built in Yade with CohFrictMat and compressed between two walls.
# Run inside Yade (tools/bench/solver_bench.py does this when yade is installed):
#
#   SOLVER_YADE_PACKING=bench-out/solver/specimens/sphere3d_30k.packing \
#   SOLVER_YADE_STEPS=300 yade -n -x -j 2 tools/bench/solver_yade.py
#
# The scene matches solver-throughput's 3D scene as far as Yade's model allows:
#  - the same spheres (read from the .packing file) and exactly the packing's contact pairs
#    as cohesive bonds (utils.createInteraction, then CohFrictPhys with setCohesionNow);
#    strengths far out of reach (the failure check runs, nothing breaks), no moment law
#    (our law has no rolling or twisting resistance), hence no relative rotations in the
#    geometry either (updateRotations=False: Yade's fastest set-up for it, 5-10 % faster);
#  - Coulomb friction 0.5 on unbonded contacts, found by Yade's collider (the neighbour
#    search), and shear stiffness 0.5 kn (CohFrictMat.poisson is ks/kn);
#  - non-viscous local damping 0.1 (NewtonIntegrator), no gravity, rotation on;
#  - two frictionless walls across z at the specimen's bounds, the upper one moving down
#    by 0.02 mean radii per 1000 steps, as in solver-throughput.
# The time step is 0.5 of Yade's p-wave estimate (it sets how often the collider runs, not
# the cost of a step). Timed: O.run(steps, True) after the warm-up, wall clock.
# Prints one line "YADE_RESULT {json}".
import json
import math
import os
import resource
import sys
import time

from yade import O, utils
# Engines, functors and materials (CohFrictMat, InteractionLoop, ...) are the names Yade
# puts in the script's globals.


def rss_bytes():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    return 0


def yade_version():
    try:
        import yade.config
        return str(yade.config.version)
    except Exception:  # older or newer layouts: the version is informative only
        return ""


def read_packing(path):
    """Centres, radii and contact pairs of a specimen .packing file (3D)."""
    spheres, pairs = [], []
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip() and not l.startswith("#")]
    k = 0
    dimension = 3
    while k < len(lines) and not lines[k].startswith("particles"):
        if lines[k].startswith("dimension"):
            dimension = int(lines[k].split()[1])
        k += 1
    if dimension != 3:
        raise SystemExit("solver_yade.py: the Yade comparison is 3D only")
    count = int(lines[k].split()[1])
    for line in lines[k + 1:k + 1 + count]:
        x, y, z, r = map(float, line.split())
        spheres.append((x, y, z, r))
    k += 1 + count
    contacts = int(lines[k].split()[1])
    for line in lines[k + 1:k + 1 + contacts]:
        i, j = map(int, line.split())
        pairs.append((i, j))
    return spheres, pairs


def main():
    path = os.environ["SOLVER_YADE_PACKING"]
    steps = int(os.environ.get("SOLVER_YADE_STEPS", "300"))
    warmup = int(os.environ.get("SOLVER_YADE_WARMUP", "50"))
    threads = int(getattr(O, "numThreads", 0) or os.environ.get("OMP_NUM_THREADS", "1"))
    rss_start = rss_bytes()
    build_start = time.time()
    spheres, pairs = read_packing(path)
    n = len(spheres)
    r_mean = (sum(s[3] ** 3 for s in spheres) / n) ** (1.0 / 3.0)
    lower = min(s[2] - s[3] for s in spheres)
    upper = max(s[2] + s[3] for s in spheres)

    young = 1e9
    bonded = O.materials.append(
        CohFrictMat(young=young, poisson=0.5, density=2600, frictionAngle=math.atan(0.5),
                    normalCohesion=1e15, shearCohesion=1e15, isCohesive=True,
                    momentRotationLaw=False, fragile=True, label="bonded"))
    wall_material = O.materials.append(
        FrictMat(young=young, poisson=0.5, density=2600, frictionAngle=0.0, label="walls"))
    O.bodies.append([utils.sphere((x, y, z), r, material=bonded) for x, y, z, r in spheres])

    ip2_cohesive = Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True,
                                                            setCohesionOnNewContacts=False)
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom6D(updateRotations=False), Ig2_Wall_Sphere_ScGeom()],
            [ip2_cohesive, Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(), Law2_ScGeom_FrictPhys_CundallStrack()]),
        NewtonIntegrator(damping=0.1, gravity=(0, 0, 0)),
    ]
    # The bonds: exactly the packing's pairs.
    for i, j in pairs:
        utils.createInteraction(i, j)
    dt = 0.5 * utils.PWaveTimeStep()
    O.dt = dt
    O.step()  # cohesion is set on the existing interactions at this step
    bonds = sum(1 for i in O.interactions if i.isReal and getattr(i.phys, "cohesionBroken", True) is False)

    bottom = O.bodies.append(utils.wall((0, 0, lower), axis=2, sense=1, material=wall_material))
    top = O.bodies.append(utils.wall((0, 0, upper), axis=2, sense=-1, material=wall_material))
    speed = 0.02 * r_mean / (1000.0 * dt)
    O.bodies[top].state.vel = Vector3(0, 0, -speed)
    build_seconds = time.time() - build_start

    if warmup > 0:
        O.run(warmup, True)
    start = time.time()
    cpu_start = time.process_time()
    O.run(steps, True)
    seconds = time.time() - start
    cpu_seconds = time.process_time() - cpu_start
    real = sum(1 for i in O.interactions if i.isReal)
    wall_contacts = sum(1 for i in O.interactions
                        if i.isReal and (i.id1 in (bottom, top) or i.id2 in (bottom, top)))
    intact = sum(1 for i in O.interactions
                 if i.isReal and hasattr(i.phys, "cohesionBroken") and not i.phys.cohesionBroken)
    result = {
        "engine": "yade",
        "yade_version": yade_version(),
        "packing": path,
        "particles": n,
        "bonds": bonds,
        "bonds_intact": intact,
        "contacts": real - wall_contacts,
        "contacts_per_particle": (real - wall_contacts) / n,
        "bonds_per_particle": bonds / n,
        "wall_contacts": wall_contacts,
        "threads": threads,
        "steps": steps,
        "warmup_steps": warmup,
        "seconds": seconds,
        "cpu_seconds": cpu_seconds,
        "particle_steps_per_second": n * steps / seconds,
        "bytes_per_particle_rss": (rss_bytes() - rss_start) / n,
        "peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
        "time_step_s": dt,
        "build_seconds": build_seconds,
        "upper_wall_force_n": O.forces.f(top)[2],
    }
    print("YADE_RESULT " + json.dumps(result))
    sys.stdout.flush()


main()
