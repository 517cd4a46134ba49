#!/usr/bin/env python3
"""Benchmark of generate-packing: prints a table, writes CSV and pictures.

  tools/bench/generator_bench.py [--build build] [--out bench-out/generator]
                                 [--runs 3] [--quick] [--skip-scaling] [--only 2d|3d]
                                 [--generator-args "--compaction off"] [--no-competitors]

1. The two target cases, median of --runs runs (seeds 1..runs) on this machine:
   2D square of side 100, mean radius 0.223 (~56,000 discs), r_max/r_min <= 10;
   3D cylinder of unit diameter and length, 30,000 spheres, r_max/r_min <= 10.
2. Side by side in the same run, when installed: GenGeo (Debian python3-gengeo, ESyS-Particle's
   insertion generator) on the same domains, and Yade's randomDensePack (Debian yade).
3. Time and peak memory against N (2D 1k, 10k, 56k, 200k; 3D 1k, 10k, 30k, 100k) with the
   fitted growth exponent of time ~ N^b.
4. Error against run time: porosity and largest overlap after each round of the 56k 2D run,
   against cumulative Levenberg-Marquardt iterations and wall time (CSV + plot).
Medians of several runs because the machine is noisy; comparisons are made in one run.
"""
import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

PYTHON_WITH_GENGEO = None


def run_timed(command, cwd=None):
    """Runs a command under GNU time; returns (wall seconds, CPU seconds, peak RSS in MiB, stdout)."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as timing:
        full = ["/usr/bin/time", "-f", "%e %U %S %M", "-o", timing.name] + command
        result = subprocess.run(full, cwd=cwd, capture_output=True, text=True)
        if result.returncode != 0:
            raise RuntimeError("command failed: %s\n%s%s" % (" ".join(command), result.stdout, result.stderr))
        seconds, user, system, kib = timing.read().split()[-4:]
    return float(seconds), float(user) + float(system), float(kib) / 1024.0, result.stdout


def generate(build, out, domain, size_flag, size, seed, name, trace=False, extra=()):
    command = [os.path.join(build, "tools", "generate-packing"), "--domain", domain, size_flag, str(size),
               "--radius-ratio", "10", "--seed", str(seed), "--output", out, "--name", name, "--quiet",
               "--no-pictures"] + (["--trace"] if trace else []) + list(extra)
    seconds, cpu, mib, _ = run_timed(command)
    with open(os.path.join(out, name + "_report.json")) as f:
        report = json.load(f)
    m = report["metrics"]
    return {
        "seconds": seconds, "cpu_seconds": cpu, "peak_mib": mib, "particles": m["particle_count"],
        "porosity": m["nominal_porosity"], "corrected_porosity": m["corrected_porosity"],
        "coordination": m["coordination_number"], "max_overlap": m["max_overlap"],
        "fabric": m["fabric_eigenvalues"], "radius_ratio": m["radius_ratio"],
        "mean_radius": m["mean_radius"], "report": report,
    }


def find_gengeo_python():
    for python in [os.environ.get("SPECIMEN_PYTHON", ""), "python3", "/usr/bin/python3"]:
        if python and shutil.which(python) and subprocess.run([python, "-c", "import gengeo"],
                                                              capture_output=True).returncode == 0:
            return python
    return None


GENGEO_2D = r"""
import json, sys, time
from gengeo import *
side, rmin, rmax = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
lo, hi = Vector3(0, 0, 0), Vector3(side, side, 0)
box = BoxWithLines2D(minPoint=lo, maxPoint=hi)
for a, b in [((0, 0), (side, 0)), ((side, 0), (side, side)), ((side, side), (0, side)), ((0, side), (0, 0))]:
    box.addLine(Line2D(startPoint=Vector3(a[0], a[1], 0), endPoint=Vector3(b[0], b[1], 0)))
table = MNTable2D(minPoint=lo, maxPoint=hi, gridSize=2.5 * rmax)
start = time.time()
InsertGenerator2D(minRadius=rmin, maxRadius=rmax, insertFails=1000, maxIterations=1000,
                  tolerance=1e-6, seed=False).generatePacking(volume=box, ntable=table, tag=0)
seconds = time.time() - start
table.generateBonds(tolerance=1e-5, bondID=0)
n = table.getNumParticles()
bonds = len(table.getBondList(0))
print(json.dumps({"seconds": seconds, "particles": n, "porosity": 1 - table.getSumVolume() / side ** 2,
                  "coordination": 2.0 * bonds / n}))
"""

GENGEO_3D = r"""
import json, sys, time
from gengeo import *
rmin, rmax = float(sys.argv[1]), float(sys.argv[2])
vol = CylinderVol(origin=Vector3(0, 0, 0), axis=Vector3(0, 0, 1), length=1.0, radius=0.5)
table = MNTable3D(minPoint=Vector3(-0.5, -0.5, 0), maxPoint=Vector3(0.5, 0.5, 1), gridSize=2.5 * rmax)
start = time.time()
InsertGenerator3D(minRadius=rmin, maxRadius=rmax, insertFails=1000, maxIterations=1000,
                  tolerance=1e-6, seed=False).generatePacking(volume=vol, ntable=table, tag=0)
seconds = time.time() - start
table.generateBonds(groupID=0, tolerance=1e-5, bondID=0)
import os, tempfile
path = tempfile.mktemp(suffix=".geo")
table.write(path, 1)
lines = open(path).read().split("\n")
os.unlink(path)
n = int(lines[lines.index("BeginParticles") + 2])
bonds = int(lines[lines.index("BeginConnect") + 1])
print(json.dumps({"seconds": seconds, "particles": n, "porosity": 1 - table.getSumVolume(groupID=0) / (3.141592653589793 * 0.25),
                  "coordination": 2.0 * bonds / n}))
"""

YADE_3D = r"""
import json, time
from yade import pack
start = time.time()
sp = pack.randomDensePack(pack.inCylinder((0, 0, 0), (0, 0, 1), 0.5), radius=RADIUS, rRelFuzz=0.5,
                          spheresInCell=2000, returnSpherePack=True)
seconds = time.time() - start
n = len(sp)
volume = sum(4.0 / 3.0 * 3.141592653589793 * r ** 3 for c, r in sp)
print("RESULT " + json.dumps({"seconds": seconds, "particles": n, "porosity": 1 - volume / (3.141592653589793 * 0.25),
                              "coordination": float("nan")}))
"""


def run_gengeo(python, script, args):
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
        f.write(script)
        path = f.name
    try:
        result = subprocess.run([python, path] + [str(a) for a in args], capture_output=True, text=True, timeout=3600)
        if result.returncode != 0:
            return {"error": result.stderr.strip().splitlines()[-1] if result.stderr.strip() else "failed"}
        return json.loads(result.stdout.strip().splitlines()[-1])
    finally:
        os.unlink(path)


def run_yade(radius):
    if not shutil.which("yade"):
        return None
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
        f.write(YADE_3D.replace("RADIUS", repr(radius)))
        path = f.name
    try:
        result = subprocess.run(["yade", "-n", "-x", path], capture_output=True, text=True, timeout=3600)
        for line in result.stdout.splitlines():
            if line.startswith("RESULT "):
                return json.loads(line[len("RESULT "):])
        return {"error": "no result from yade"}
    finally:
        os.unlink(path)


def median_row(rows, key):
    return statistics.median(r[key] for r in rows)


def fit_exponent(ns, ts):
    xs = [math.log(n) for n in ns]
    ys = [math.log(t) for t in ts]
    mx, my = statistics.mean(xs), statistics.mean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def gnuplot(script, png):
    if not shutil.which("gnuplot"):
        return False
    full = "set terminal pngcairo size 1000,700 enhanced font 'sans,11'\nset output '%s'\n%s\n" % (png, script)
    return subprocess.run(["gnuplot"], input=full, text=True, capture_output=True).returncode == 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/generator")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="small sizes only (a smoke test of the script)")
    parser.add_argument("--skip-scaling", action="store_true")
    parser.add_argument("--only", choices=["2d", "3d"], help="run only this target case (and its scaling sizes)")
    parser.add_argument("--generator-args", default="",
                        help='extra generate-packing arguments, e.g. "--compaction off" for a side-by-side run')
    parser.add_argument("--no-competitors", action="store_true", help="do not run GenGeo and Yade")
    args = parser.parse_args()
    extra = args.generator_args.split()
    os.makedirs(args.out, exist_ok=True)
    work = os.path.join(args.out, "runs")
    os.makedirs(work, exist_ok=True)

    scale = 0.1 if args.quick else 1.0
    side2d = 100.0 * math.sqrt(scale)
    cases = [
        ("2D square %g, r_mean 0.223" % side2d, "rectangle 0 0 %r %r" % (side2d, side2d), "--mean-radius", 0.223, 2),
        ("3D cylinder 1 x 1, %d spheres" % int(30000 * scale), "cylinder 0 0 0.5 0 1", "--count", int(30000 * scale), 3),
    ]
    if args.only:
        cases = [c for c in cases if "%dd" % c[4] == args.only]
    summary_rows = []
    trace_report = None
    radius_range_3d = (0.0045, 0.045)
    for label, domain, flag, size, dim in cases:
        rows = []
        for seed in range(1, args.runs + 1):
            rows.append(generate(args.build, work, domain, flag, size, seed, "case%dd_seed%d" % (dim, seed),
                                 extra=extra))
            if dim == 2 and seed == 1:
                # A separate traced run: recording costs time, so it is not one of the timed runs.
                trace_report = generate(args.build, work, domain, flag, size, seed, "trace2d", trace=True,
                                        extra=extra)["report"]
            last = rows[-1]
            print("  %s seed %d: %.1f s wall, %.1f s CPU, %d particles, porosity %.4f, nc %.3f, max overlap %.3g, "
                  "fabric %s" % (label, seed, last["seconds"], last["cpu_seconds"], last["particles"], last["porosity"],
                                 last["coordination"], last["max_overlap"], " ".join("%.4f" % v for v in last["fabric"])),
                  file=sys.stderr)
        if dim == 3:
            m0 = rows[0]["report"]["metrics"]
            radius_range_3d = (m0["min_radius"], m0["max_radius"])
        fabric = [statistics.median(r["fabric"][k] for r in rows) for k in range(dim)]
        summary_rows.append({
            "case": label, "generator": "specimen (this toolkit)", "particles": median_row(rows, "particles"),
            "porosity": median_row(rows, "porosity"), "corrected_porosity": median_row(rows, "corrected_porosity"),
            "coordination": median_row(rows, "coordination"), "max_overlap": median_row(rows, "max_overlap"),
            "fabric": fabric, "radius_ratio": median_row(rows, "radius_ratio"), "seconds": median_row(rows, "seconds"),
            "cpu_seconds": median_row(rows, "cpu_seconds"), "peak_mib": median_row(rows, "peak_mib")})

    # Side-by-side competitors on the same domains.
    python = None if args.no_competitors else find_gengeo_python()
    if python:
        g2 = {"error": "not run"} if args.only == "3d" else run_gengeo(python, GENGEO_2D, [side2d, 0.05, 0.5])
        if "error" not in g2:
            summary_rows.append({"case": cases[0][0], "generator": "GenGeo InsertGenerator2D, r 0.05-0.5", **g2,
                                 "corrected_porosity": float("nan"), "max_overlap": float("nan"),
                                 "fabric": [], "radius_ratio": 10.0, "peak_mib": float("nan")})
        # 3D: the radius range of our own 3D run, so both fill the cylinder with the same sizes.
        g3 = {"error": "not run"} if args.only == "2d" else run_gengeo(python, GENGEO_3D, [radius_range_3d[0], radius_range_3d[1]])
        if "error" not in g3:
            summary_rows.append({"case": cases[1][0], "generator": "GenGeo InsertGenerator3D", **g3,
                                 "corrected_porosity": float("nan"), "max_overlap": float("nan"), "fabric": [],
                                 "radius_ratio": 10.0, "peak_mib": float("nan")})
    elif not args.no_competitors:
        print("  GenGeo not installed (apt-get install python3-gengeo): no side-by-side run", file=sys.stderr)
    yade = None if args.no_competitors or args.only == "2d" else run_yade(0.015 if not args.quick else 0.035)
    if yade and "error" not in yade:
        summary_rows.append({"case": cases[1][0], "generator": "Yade randomDensePack", **yade,
                             "corrected_porosity": float("nan"), "max_overlap": float("nan"), "fabric": [],
                             "radius_ratio": 3.0, "peak_mib": float("nan")})
    elif yade is None and not (args.no_competitors or args.only == "2d"):
        print("  yade not installed (apt-get install yade): no side-by-side run", file=sys.stderr)

    with open(os.path.join(args.out, "targets.csv"), "w") as f:
        f.write("case,generator,particles,nominal_porosity,corrected_porosity,coordination,max_overlap_per_rmean,"
                "fabric_eigenvalues,radius_ratio,seconds,peak_mib\n")
        for r in summary_rows:
            f.write('"%s","%s",%d,%.5f,%.5f,%.4f,%.3g,"%s",%.3g,%.2f,%.0f\n' % (
                r["case"], r["generator"], r["particles"], r["porosity"], r["corrected_porosity"],
                r["coordination"], r["max_overlap"], " ".join("%.4f" % v for v in r["fabric"]),
                r["radius_ratio"], r["seconds"], r["peak_mib"]))

    print("\n| case | generator | N | porosity (nominal) | porosity (corrected) | nc | max overlap / r_mean | fabric eigenvalues | r_max/r_min | time [s] | CPU [s] | peak MiB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in summary_rows:
        print("| %s | %s | %d | %.2f %% | %s | %s | %s | %s | %.2f | %.1f | %s | %s |" % (
            r["case"], r["generator"], r["particles"], 100 * r["porosity"],
            "%.2f %%" % (100 * r["corrected_porosity"]) if not math.isnan(r["corrected_porosity"]) else "-",
            "%.3f" % r["coordination"] if not math.isnan(r["coordination"]) else "-",
            "%.2g" % r["max_overlap"] if not math.isnan(r["max_overlap"]) else "-",
            " ".join("%.4f" % v for v in r["fabric"]) or "-", r["radius_ratio"], r["seconds"],
            "%.1f" % r["cpu_seconds"] if "cpu_seconds" in r else "-",
            "%.0f" % r["peak_mib"] if not math.isnan(r["peak_mib"]) else "-"))

    # Error against run time: porosity and largest overlap after every LM iteration of a
    # traced 2D run (the last point is after the final projection).
    if trace_report:
        path = os.path.join(args.out, "convergence_2d.csv")
        with open(path, "w") as f:
            f.write("round,cumulative_lm_iterations,seconds,nominal_porosity,max_overlap_per_rmean\n")
            for t in trace_report["generator"]["trace"]:
                f.write("%d,%d,%.3f,%.6f,%.6g\n" % (t["round"], t["lm_iterations"], t["seconds"],
                                                   t["nominal_porosity"], max(t["max_overlap"], 1e-6)))
        for column, label, png in [(3, "wall time [s]", "convergence_2d.png"),
                                   (2, "Levenberg-Marquardt iterations (cumulative)", "convergence_2d_iterations.png")]:
            gnuplot("set datafile separator ','\nset key top right\nset xlabel '%s'\n"
                    "set ylabel 'nominal porosity'\nset yrange [0.085:0.12]\nset y2label 'largest overlap / r_{mean}'\n"
                    "set y2tics\nset logscale y2\nset grid\n"
                    "set title 'generate-packing, 2D ~56k discs: error against run time (first point after round 0 start)'\n"
                    "plot '%s' every ::1 using %d:4 with lines lw 2 title 'nominal porosity', "
                    "'' every ::1 using %d:5 axes x1y2 with lines lw 2 title 'largest overlap (1e-6 = none)'"
                    % (label, path, column, column), os.path.join(args.out, png))
        print("\nconvergence (2D, traced run): %s" % path)

    if not args.skip_scaling:
        sizes = {2: [1000, 10000, 56000, 200000], 3: [1000, 10000, 30000, 100000]}
        if args.quick:
            sizes = {2: [500, 2000], 3: [500, 2000]}
        if args.only:
            sizes = {d: ns for d, ns in sizes.items() if "%dd" % d == args.only}
        path = os.path.join(args.out, "scaling.csv")
        with open(path, "w") as f:
            f.write("dimension,particles_requested,particles,seconds,peak_mib\n")
            print("\n| dimension | N | time [s] | peak MiB |\n|---|---|---|---|")
            for dim, ns in sizes.items():
                measured = []
                for n in ns:
                    side = (n * math.pi * 0.223 ** 2 / 0.91) ** 0.5
                    domain = "rectangle 0 0 %r %r" % (side, side) if dim == 2 else "cylinder 0 0 0.5 0 1"
                    runs = [generate(args.build, work, domain, "--count", n, seed, "scale%dd" % dim, extra=extra)
                            for seed in range(1, (args.runs if n <= 30000 else 1) + 1)]
                    t = statistics.median(r["seconds"] for r in runs)
                    mem = statistics.median(r["peak_mib"] for r in runs)
                    got = int(statistics.median(r["particles"] for r in runs))
                    measured.append((got, t))
                    f.write("%d,%d,%d,%.3f,%.1f\n" % (dim, n, got, t, mem))
                    print("| %dD | %d | %.2f | %.0f |" % (dim, got, t, mem))
                print("| %dD | growth exponent b (t ~ N^b, N >= 10k) | %.2f | |" % (
                    dim, fit_exponent([m[0] for m in measured[1:]], [m[1] for m in measured[1:]])
                    if len(measured) > 2 else float("nan")))
        gnuplot("set datafile separator ','\nset logscale xy\nset xlabel 'particles'\nset ylabel 'time [s]'\n"
                "set key top left\nset title 'generate-packing: run time against size'\n"
                "plot '%s' using ($1==2?$3:1/0):4 with linespoints lw 2 title '2D', "
                "'' using ($1==3?$3:1/0):4 with linespoints lw 2 title '3D'" % path,
                os.path.join(args.out, "scaling.png"))


if __name__ == "__main__":
    main()
