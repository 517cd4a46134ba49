#!/usr/bin/env python3
"""Path noise of the strengths on the calibrator's default 2D specimens: how well one UCS and
one Brazilian test at a micro parameter set tell the strengths a step away, the noise the
calibration's tolerances and single runs per round are judged against.

  tools/bench/strength_noise.py [--build build] [--out bench-out/strength_noise]
        [--replicates 6] [--step 0.002] [--points 1,2,...] [--markdown FILE]

At each point of the box (rigid and DDEM; kt/kn, Rt/Rn, kn/(Ep l) in the table) the UCS and
the Brazilian test run at Rn x (1 + step k), k = 0 .. replicates - 1 (Rt/Rn, kn, kt kept), on
the 5,064-disc UCS square and the 3,940-disc Brazilian disc the calibrator generates by
default (regenerated here with generate-packing: the same generator options and seed). Over
so small a span of Rn the strengths follow Rn smoothly; what scatters about the
least-squares line of ln(strength) in ln(Rn) is the path of the cracks, and its standard
deviation (two degrees of freedom taken by the line) is the noise of one run. Each test runs
single-threaded, two at a time.
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_bench import ROOT, deformable_bound, scene, summary  # noqa: E402

TOLERANCES = {"ucs": 0.02, "tensile_strength": 0.05}  # the calibration's (CalibrationOptions)
KN = 3e10   # N/m per metre of thickness
RN = 1e4    # N per metre of thickness
# (label, kt/kn, Rt/Rn, share of the DDEM maps' upper kn/(Ep l) or None for rigid particles)
POINTS = [
    ("rigid, shear-prone", 0.2, 2.5, None),
    ("rigid, low kt/kn, tension", 0.2, 9.5, None),
    ("rigid, middle", 0.5, 5.0, None),
    ("rigid, high kt/kn, shear", 0.8, 2.5, None),
    ("rigid, high kt/kn, tension", 0.8, 9.5, None),
    ("rigid, plateau", 0.32, 10.0, None),
    ("DDEM, shear-prone", 0.4, 4.0, 0.5),
    ("DDEM, tension", 0.4, 9.0, 0.5),
]


def generate(build, out):
    """The calibrator's default specimens: a 50 mm square of 5,000 discs, seed 1, and the
    Brazilian disc of its width at the square's volume-based mean radius."""
    tool = os.path.join(build, "tools", "generate-packing")
    common = ["--seed", "1", "--output", out, "--quiet", "--no-pictures"]
    subprocess.run([tool, "--domain", "rectangle 0 0 0.05 0.05", "--count", "5000", "--name", "ucs"] + common,
                   check=True, capture_output=True)
    with open(os.path.join(out, "ucs_report.json")) as f:
        radius = json.load(f)["metrics"]["mean_radius_m"]
    subprocess.run([tool, "--domain", "disc 0.025 0.025 0.025", "--mean-radius", repr(radius), "--name", "bts"]
                   + common, check=True, capture_output=True)
    return os.path.join(out, "ucs.packing"), os.path.join(out, "bts.packing")


def run_all(build, jobs, workers=2):
    """jobs: (directory, name, scene text); at most `workers` run-test processes at once."""
    pending, running = list(jobs), []
    while pending or running:
        while pending and len(running) < workers:
            directory, name, text = pending.pop(0)
            os.makedirs(directory, exist_ok=True)
            path = os.path.join(directory, name + ".toml")
            with open(path, "w") as f:
                f.write(text)
            command = [os.path.join(build, "tools", "run-test"), path, "--output", directory, "--quiet"]
            running.append((subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True),
                            name))
        time.sleep(0.2)
        for p, name in list(running):
            if p.poll() is not None:
                if p.returncode != 0:
                    raise RuntimeError("%s failed: %s" % (name, p.stderr.read()))
                running.remove((p, name))


def residual_noise(rn, values):
    """Standard deviation of ln(value) about its least-squares line in ln(Rn) (ddof 2)."""
    x = [math.log(r) for r in rn]
    y = [math.log(v) for v in values]
    mx, my = statistics.fmean(x), statistics.fmean(y)
    sxx = sum((a - mx) ** 2 for a in x)
    slope = sum((a - mx) * (b - my) for a, b in zip(x, y)) / sxx
    residuals = [b - my - slope * (a - mx) for a, b in zip(x, y)]
    return math.sqrt(sum(r * r for r in residuals) / (len(x) - 2)), slope


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/strength_noise")
    parser.add_argument("--replicates", type=int, default=6, help="runs per point, >= 3")
    parser.add_argument("--step", type=float, default=0.002, help="relative step of Rn between runs, in (0, 0.05]")
    parser.add_argument("--points", help="comma-separated 1-based indices of POINTS (default: all)")
    parser.add_argument("--markdown", help="the page to write (default OUT/strength_noise.md)")
    args = parser.parse_args()
    chosen = range(1, len(POINTS) + 1)
    if args.points:
        try:
            chosen = sorted(set(int(v) for v in args.points.split(",")))
        except ValueError:
            parser.error("--points: comma-separated integers")
        if not all(1 <= v <= len(POINTS) for v in chosen):
            parser.error("--points must lie in [1, %d]" % len(POINTS))
    if args.replicates < 3:
        parser.error("--replicates must be >= 3 (a line and a residual)")
    if not 0.0 < args.step <= 0.05:
        parser.error("--step must be in (0, 0.05]")
    build, out = os.path.abspath(args.build), os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    start = time.monotonic()
    ucs_packing, bts_packing = generate(build, os.path.join(out, "specimens"))
    bound = deformable_bound(os.path.join(ROOT, "data", "maps"), 2)
    jobs, plan = [], []
    for index in (v - 1 for v in chosen):
        label, kt_kn, rt_rn, share = POINTS[index]
        material = {"normal_stiffness": KN, "tangential_stiffness": kt_kn * KN, "friction_coefficient": 0.8,
                    "density": 2650.0}
        if share is not None:
            if bound is None:
                raise RuntimeError("no DDEM maps in data/maps: their kn/(Ep l) bound sets the DDEM points")
            material["particle_youngs_modulus"] = KN / (share * bound[0])
            material["particle_poisson_ratio"] = bound[1]
        directory = os.path.join(out, "point_%d" % (index + 1))
        rns = [RN * (1.0 + args.step * k) for k in range(args.replicates)]
        for k, rn in enumerate(rns):
            m = dict(material, bond_tensile_strength=rn, bond_shear_strength=rt_rn * rn)
            jobs.append((directory, "ucs_%d" % k, scene(ucs_packing, "ucs", m, "ucs_%d" % k, 0.05)))
            jobs.append((directory, "bts_%d" % k, scene(bts_packing, "brazilian", m, "bts_%d" % k, 0.05)))
        plan.append((label, kt_kn, rt_rn, share, directory, rns))
    run_all(build, jobs)

    rows = []
    for label, kt_kn, rt_rn, share, directory, rns in plan:
        ucs = [summary(directory, "ucs_%d" % k)["peak_stress_pa"] for k in range(len(rns))]
        bts = [summary(directory, "bts_%d" % k)["tensile_strength_pa"] for k in range(len(rns))]
        noise_ucs, slope_ucs = residual_noise(rns, ucs)
        noise_bts, slope_bts = residual_noise(rns, bts)
        rows.append({"label": label, "kt_kn": kt_kn, "rt_rn": rt_rn,
                     "kn_ep_l": None if share is None else share * bound[0],
                     "ucs_mpa": statistics.fmean(ucs) / 1e6, "noise_ucs": noise_ucs, "slope_ucs": slope_ucs,
                     "bts_mpa": statistics.fmean(bts) / 1e6, "noise_bts": noise_bts, "slope_bts": slope_bts,
                     "range_ucs": (max(ucs) - min(ucs)) / statistics.fmean(ucs),
                     "range_bts": (max(bts) - min(bts)) / statistics.fmean(bts)})
    with open(os.path.join(out, "strength_noise.json"), "w") as f:
        json.dump(rows, f, indent=1)

    lines = ["| point | kt/kn | Rt/Rn | kn/(Ep l) | UCS (mean) | UCS noise | sigma_t (mean) | sigma_t noise | "
             "UCS / sigma_t |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| %s | %.2f | %.1f | %s | %.1f MPa | %.2f %% | %.2f MPa | %.2f %% | %.1f |" % (
            r["label"], r["kt_kn"], r["rt_rn"], "-" if r["kn_ep_l"] is None else "%.3f" % r["kn_ep_l"],
            r["ucs_mpa"], 100 * r["noise_ucs"], r["bts_mpa"], 100 * r["noise_bts"], r["ucs_mpa"] / r["bts_mpa"]))
    nu = [r["noise_ucs"] for r in rows]
    nb = [r["noise_bts"] for r in rows]
    lines += ["", "Noise of one run (standard deviation about the line in Rn), median and largest over the points: "
              "UCS %.2f %% and %.2f %%, sigma_t %.2f %% and %.2f %%; the tolerances: UCS %.0f %%, sigma_t %.0f %%. "
              "Points where one run's UCS noise exceeds half its tolerance: %d of %d. Wall time %.0f s." % (
                  100 * statistics.median(nu), 100 * max(nu), 100 * statistics.median(nb), 100 * max(nb),
                  100 * TOLERANCES["ucs"], 100 * TOLERANCES["tensile_strength"],
                  sum(1 for v in nu if v > TOLERANCES["ucs"] / 2), len(nu), time.monotonic() - start)]
    text = "\n".join(lines)
    print(text)
    with open(args.markdown or os.path.join(out, "strength_noise.md"), "w") as f:
        f.write(text + "\n")


if __name__ == "__main__":
    main()
