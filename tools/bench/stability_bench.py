#!/usr/bin/env python3
"""Benchmark of stability-limit: predicted against measured limits, and speed.

  tools/bench/stability_bench.py [--build build] [--out bench-out/stability]
                                 [--quick] [--only REGEX] [--skip-grid] [--skip-timing] [--runs 3]

1. Packings by generate-packing (r_max/r_min <= 10): 2D 500 discs, 3D 500 spheres, 2D with a
   mean radius of 1e-5 m; and Madan's SC 9x20 / HCP 110-disc lattices (written by
   stability-bench --write-lattices) for the wall rows.
2. The grid of the issue, each row one stability-bench run (tools/bench/stability_bench.cpp):
   the certified prediction of the analysis against a bisection with real, undamped solver
   runs (stable = the energy stays bounded over a fixed number of steps, from random initial
   velocities), on the time step (--mode dt) or on kn/(Ep l) at a small fixed step (--mode ep).
   ratio = predicted / largest stable value: it must be <= 1 (never unsafe) and >= 0.97.
   Rows with walls (unilateral contacts: impacts) are scanned instead (--mode scan): runs at
   0.80 .. 1.02 of the linear certified step, each with three press-in durations and a
   loaded wall contact that chatters counted as a failure; measured = the largest probed
   step below which every run was bounded (the bounded/unbounded boundary is not monotonic
   there).
3. The full analysis of 50,000-particle packings (2D and 3D): wall and CPU time of
   stability-limit, median of --runs; with --baseline BUILD_DIR, that build's side by side.
Prints the tables (Markdown) and writes CSV and JSON into --out.
"""
import argparse
import csv
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import time


def run_bench(build, args):
    command = [os.path.join(build, "tools", "stability-bench")] + [str(a) for a in args]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError("failed: %s\n%s%s" % (" ".join(command), result.stdout, result.stderr))
    return json.loads(result.stdout.strip().splitlines()[-1])


def generate(build, out, name, domain, size_flag, size, seed=1):
    path = os.path.join(out, name, "packing.packing")
    if os.path.exists(path):
        return path
    command = [os.path.join(build, "tools", "generate-packing"), "--domain", domain, size_flag,
               str(size), "--radius-ratio", "10", "--seed", str(seed), "--output",
               os.path.join(out, name), "--quiet", "--no-pictures"]
    subprocess.run(command, check=True, capture_output=True)
    return path


def grid(packings, quick):
    """(label, packing key, stability-bench arguments). The scene of every row: kn = 7e10 N/m,
    density 2000 kg/m^3, plane strain, undamped unless stated."""
    rows = []
    for dim in ("2D", "3D"):
        p = dim
        rows += [
            ("%s DEM kt=0" % dim, p, []),
            ("%s DEM kt/kn=1" % dim, p, ["--kt-ratio", 1]),
            ("%s DEM kt/kn=1.25" % dim, p, ["--kt-ratio", 1.25]),
            ("%s Ep->inf (Ep=1e30 Pa)" % dim, p, ["--kn-over-ep", 1e-19]),
        ]
        nus = [0.0, 0.25, 0.45, 0.49, 0.499] if dim == "2D" or not quick else [0.25, 0.49]
        for nu in nus:
            rows.append(("%s DDEM nu_p=%g kn/Ep=0.5 lim" % (dim, nu), p,
                         ["--nu-p", nu, "--kn-over-ep-fraction", 0.5]))
        for nu in ([0.25, 0.45] if dim == "2D" else [0.25]):
            rows.append(("%s DDEM nu_p=%g kn/Ep=0.9 lim" % (dim, nu), p,
                         ["--nu-p", nu, "--kn-over-ep-fraction", 0.9]))
            # Near rho(B) = 1 the lag modes grow slowly: longer runs.
            rows.append(("%s DDEM nu_p=%g kn/Ep=0.97 lim" % (dim, nu), p,
                         ["--nu-p", nu, "--kn-over-ep-fraction", 0.97, "--steps", 30000]))
        # DDEM with kt > 0 is not conservative (flutter): damped, as the analysis asks.
        for kt in (1, 1.25):
            rows.append(("%s DDEM kt/kn=%g nu_p=0.35 0.5 lim, alpha=0.1" % (dim, kt), p,
                         ["--kt-ratio", kt, "--nu-p", 0.35, "--kn-over-ep-fraction", 0.5,
                          "--damping", 0.1]))
        sides = "left,right,bottom,top" + (",back,front" if dim == "3D" else "")
        # Walls hold only in compression (impacts): scanned, not bisected (stability_bench.cpp).
        for damping in ((0.0, 0.05, 0.1) if dim == "2D" else (0.0, 0.05, 0.1, 0.2)):
            rows.append(("%s walls 10 kn, all sides, alpha=%g (scan)" % (dim, damping), p,
                         ["--walls", sides, "--wall-factor", 10, "--damping", damping,
                          "--mode", "scan"]))
        rows.append(("%s dashpots xi=0.3" % dim, p, ["--dashpot", 0.3]))
        # kn/(Ep l) limit itself: bisection on Ep at a small step.
        for nu in ([0.0, 0.25, 0.45, 0.49, 0.499] if dim == "2D" else [0.25, 0.49]):
            rows.append(("%s kn/Ep limit nu_p=%g (ep mode)" % (dim, nu), p,
                         ["--mode", "ep", "--nu-p", nu, "--steps", 20000,
                          "--ep-step-fraction", 0.1]))
    rows += [
        ("2D R~1e-5 m DEM", "small", []),
        ("2D R~1e-5 m DDEM nu_p=0.45 0.5 lim", "small", ["--nu-p", 0.45,
                                                          "--kn-over-ep-fraction", 0.5]),
        ("2D R~1e-5 m kt/kn=1", "small", ["--kt-ratio", 1]),
        # kt > 0: with kt = 0 the square lattice is a mechanism, which buckles between the
        # preloaded walls at any step (a physical instability, outside a time-step limit).
        ("SC 9x20 kt/kn=0.5 walls 10 kn top/bottom (scan)", "sc",
         ["--kt-ratio", 0.5, "--walls", "bottom,top", "--wall-factor", 10, "--mode", "scan"]),
        ("HCP 110 kt/kn=0.5 walls 10 kn top/bottom (scan)", "hcp",
         ["--kt-ratio", 0.5, "--walls", "bottom,top", "--wall-factor", 10, "--mode", "scan"]),
        ("SC 9x20 DDEM Ep=2e11 nu_p=0.35 (A5)", "sc", ["--kn-over-ep", 0.35]),
        ("HCP 110 DDEM Ep=2e11 nu_p=0.35 (A6)", "hcp", ["--kn-over-ep", 0.35]),
    ]
    if quick:
        rows = [r for r in rows if "ep mode" not in r[0] or "0.25" in r[0]]
    return rows


def time_analysis(builds, packing, arguments, runs, threads):
    """Per build: median wall time and CPU (user + system) time of stability-limit, and the
    analysis. The builds run in turn within every repetition (side by side: the same load);
    the machine may be shared, so the CPU time of a one-thread run is the steadier figure."""
    seconds = [[] for _ in builds]
    cpu = [[] for _ in builds]
    analyses = [None for _ in builds]
    for _ in range(runs):
        for k, build in enumerate(builds):
            out = "/tmp/specimen_stability_timing"
            command = [os.path.join(build, "tools", "stability-limit"), "--packing", packing,
                       "--output", out, "--quiet", "--threads", str(threads)] + \
                [str(a) for a in arguments]
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.time()
            subprocess.run(command, check=True, capture_output=True)
            seconds[k].append(time.time() - start)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu[k].append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
            with open(os.path.join(out, "packing_stability.json")) as f:
                analyses[k] = json.load(f)["analysis"]
    return ([statistics.median(x) for x in seconds], [statistics.median(x) for x in cpu],
            analyses)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/stability")
    parser.add_argument("--quick", action="store_true", help="fewer rows")
    parser.add_argument("--skip-grid", action="store_true")
    parser.add_argument("--skip-timing", action="store_true")
    parser.add_argument("--only", default="",
                        help="grid and timing rows whose case matches this regular expression "
                             "(e.g. walls)")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--baseline", default="",
                        help="another build directory, timed side by side with --build")
    parser.add_argument("--threads", type=int, default=0,
                        help="stability-limit --threads for the timings (0: the idle cores)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    data = os.path.join(args.out, "packings")
    os.makedirs(data, exist_ok=True)

    # 1. Packings.
    packings = {
        "2D": generate(args.build, data, "2d_500", "rectangle 0 0 0.01 0.01", "--count", 500),
        "3D": generate(args.build, data, "3d_500", "box 0 0 0 0.01 0.01 0.01", "--count", 500),
        "small": generate(args.build, data, "2d_small", "rectangle 0 0 0.0006 0.0006",
                          "--mean-radius", 1e-5),
    }
    subprocess.run([os.path.join(args.build, "tools", "stability-bench"), "--write-lattices",
                    data], check=True, capture_output=True)
    packings["sc"] = os.path.join(data, "sc_9x20.packing")
    packings["hcp"] = os.path.join(data, "hcp_110.packing")

    # 2. The grid.
    results = []
    if not args.skip_grid:
        rows = [r for r in grid(packings, args.quick) if re.search(args.only, r[0])]
        print("| case | particles | R_max/R_min | predicted | measured (stable / unstable) | "
              "ratio | ratio (Ritz) | DDEM reduction | rho(B) | s |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for label, key, extra in rows:
            steps = [] if "--steps" in extra else ["--steps", 5000]
            r = run_bench(args.build, ["--packing", packings[key], "--kn", 7e10] + steps + extra)
            a = r["analysis"]
            ts = a["time_step"]
            reduction = ts.get("ddem_reduction_percent")
            rho = a["ddem_convergence"].get("spectral_radius")
            ok = r["ratio"] <= 1.0 and r["ratio"] >= 0.97
            results.append({"case": label, "particles": r["particles"],
                            "radius_ratio": r["radius_ratio"], "min_radius_m": r["min_radius_m"],
                            "mode": r["mode"], "predicted": r["predicted"],
                            "predicted_ritz": r["predicted_ritz"],
                            "measured_stable": r["measured_stable"],
                            "measured_unstable": r["measured_unstable"], "ratio": r["ratio"],
                            "ratio_ritz": r["ratio_ritz"], "ddem_reduction_percent": reduction,
                            "spectral_radius": rho, "kn_over_ep": r["kn_over_ep"],
                            "within_3_percent_and_safe": ok, "seconds": r["seconds"]})
            unit = " (kn/Ep)" if r["mode"] == "ep" else ""
            if r["mode"] == "scan":
                r["measured_unstable"] = r["measured_unstable"] or float("nan")
            print("| %s%s | %d | %.2f | %.5g | %.5g / %.5g | %.4f%s | %.4f | %s | %s | %.1f |" % (
                label, unit, r["particles"], r["radius_ratio"], r["predicted"],
                r["measured_stable"], r["measured_unstable"], r["ratio"], "" if ok else " (!)",
                r["ratio_ritz"], "%.2f %%" % reduction if reduction is not None else "-",
                "%.3f" % rho if rho is not None else "-", r["seconds"]))
            sys.stdout.flush()
        with open(os.path.join(args.out, "grid.csv"), "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(results[0].keys()))
            writer.writeheader()
            writer.writerows(results)
        passed = sum(1 for r in results if r["within_3_percent_and_safe"])
        print("\n%d of %d rows within 3 %% and on the safe side" % (passed, len(results)))

    # 3. Speed: the full analysis of 50,000 particles.
    timings = []
    if not args.skip_timing:
        big2 = generate(args.build, data, "2d_50k", "rectangle 0 0 0.1 0.1", "--count", 50000)
        big3 = generate(args.build, data, "3d_50k", "box 0 0 0 0.03 0.03 0.03", "--count", 50000)
        with open(os.path.join(os.path.dirname(big3), "packing_report.json")) as f:
            mean_radius_3d = json.load(f)["metrics"]["mean_radius"]
        cases = [
            ("2D 50k, rigid, kt=0", big2, ["--kn", 7e10, "--density", 2000]),
            ("2D 50k, rigid, kt=kn/2", big2, ["--kn", 7e10, "--kt", 3.5e10, "--density", 2000]),
            ("2D 50k, DDEM kn/Ep=0.35 nu_p=0.35, kt=0", big2,
             ["--kn", 7e10, "--density", 2000, "--Ep", 2e11, "--nu-p", 0.35]),
            ("2D 50k, DDEM kn/Ep=0.35, kt=kn/2, alpha=0.1", big2,
             ["--kn", 7e10, "--kt", 3.5e10, "--density", 2000, "--Ep", 2e11, "--nu-p", 0.35,
              "--damping", 0.1]),
            ("3D 50k, rigid, kt=0", big3, ["--kn", 7e10, "--density", 2000]),
            ("3D 50k, DDEM kn/(Ep R)=0.3 nu_p=0.35, kt=0", big3,
             ["--kn", 7e10, "--density", 2000, "--Ep", "%g" % (7e10 / 0.3 / mean_radius_3d),
              "--nu-p", 0.35]),
            ("3D 50k, DDEM kn/(Ep R)=0.3 nu_p=0.35, kt=kn/2, alpha=0.1", big3,
             ["--kn", 7e10, "--kt", 3.5e10, "--density", 2000, "--Ep",
              "%g" % (7e10 / 0.3 / mean_radius_3d), "--nu-p", 0.35, "--damping", 0.1]),
        ]
        print("\nload average before the timings: %.2f (%d cores), --threads %d" %
              (os.getloadavg()[0], os.cpu_count(), args.threads))
        builds = [args.build] + ([args.baseline] if args.baseline else [])
        if args.baseline:
            print("\nbaseline %s against build %s, side by side (baseline -> build)" %
                  (args.baseline, args.build))
        print("\n| analysis | particles | links | median wall time [s] | CPU time [s] | "
              "of which DDEM step [s] |")
        print("|---|---|---|---|---|---|")
        for label, packing, arguments in [c for c in cases if re.search(args.only, c[0])]:
            seconds, cpu, analyses = time_analysis(builds, packing, arguments, args.runs,
                                                   args.threads)
            ddem = [a["time_step"].get("ddem_eigenvalue", {}).get("seconds", 0.0)
                    for a in analyses]
            a = analyses[0]
            timings.append({"case": label, "particles": a["scene"]["particles"],
                            "links": a["scene"]["links"], "median_seconds": seconds[0],
                            "cpu_seconds": cpu[0], "ddem_seconds": ddem[0],
                            "threads": args.threads})
            if args.baseline:
                timings[-1].update({"baseline_median_seconds": seconds[1],
                                    "baseline_cpu_seconds": cpu[1],
                                    "baseline_ddem_seconds": ddem[1]})
                print("| %s | %d | %d | %.2f -> %.2f | %.2f -> %.2f | %.2f -> %.2f |" % (
                    label, a["scene"]["particles"], a["scene"]["links"], seconds[1],
                    seconds[0], cpu[1], cpu[0], ddem[1], ddem[0]))
            else:
                print("| %s | %d | %d | %.2f | %.2f | %.2f |" % (
                    label, a["scene"]["particles"], a["scene"]["links"], seconds[0], cpu[0],
                    ddem[0]))
            sys.stdout.flush()
    with open(os.path.join(args.out, "stability_bench.json"), "w") as f:
        json.dump({"grid": results, "timings": timings}, f, indent=2)


if __name__ == "__main__":
    main()
