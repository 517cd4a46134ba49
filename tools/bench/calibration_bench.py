#!/usr/bin/env python3
"""Benchmark of calibrate-to-material (issue 6): prints a table, writes CSV and a plot.

  tools/bench/calibration_bench.py [--build build] [--out bench-out/calibration]
                                   [--skip-ddem] [--skip-study] [--with-3d]
                                   [--only labra,ddem,study,3d] [--ddem-count N] [--count-3d N]

1. 2D, Labra's rock (data/materials/labra2012_rock.toml) on the default 5,000-disc specimen:
   a calibration that builds its maps, then the same calibration with the stored maps.
   Targets: E, nu within 2 %, UCS within 3 %; < 15 min with map building, < 1 min reusing.
2. 2D, a rock whose nu (0.27) is above the rigid-particle limit (data/materials/
   high_poisson_2d.toml): the automatic model must switch to DDEM; E, nu within 3 %.
   The largest nu each model reaches on the packing is read from the reports.
3. Error against run time: the error of the maps' first prediction (round 1, before any
   correction) and the time to it, as the specimen size and the sweep density grow (CSV +
   plot).
4. With --with-3d: the same rock in 3D (20,000 spheres): E, nu within 3 %, UCS within 5 %.
Each calibration is deterministic (same seed, same machine); times are single runs of
several minutes each, measured while the machine is otherwise idle or not (say which).
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import time


def calibrate(build, material, out, name, maps, extra=()):
    command = [os.path.join(build, "tools", "calibrate-to-material"), material, "--output", out, "--name", name,
               "--maps-dir", maps, "--quiet", "--no-pictures"] + list(extra)
    start = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True)
    seconds = time.monotonic() - start
    if result.returncode not in (0, 4):
        raise RuntimeError("calibrate-to-material failed (%d):\n%s%s" % (result.returncode, result.stdout,
                                                                        result.stderr))
    with open(os.path.join(out, name + "_report.json")) as f:
        report = json.load(f)
    report["wall_seconds"] = seconds
    return report


def errors(report, round_index=-1):
    r = report["verification"][round_index]["relative_errors"]
    return r["youngs_modulus"], r["poisson_ratio"], r["ucs"], r["tensile_strength"]


def row(label, report, limits):
    e, nu, ucs, st = errors(report)
    ok = abs(e) <= limits[0] and abs(nu) <= limits[1] and abs(ucs) <= limits[2]
    reach = report["maps"]["rigid_reach"], report["maps"]["deformable_reach"]
    print("%-34s %6s %3d %7.2f%% %7.2f%% %7.2f%% %7.2f%% %8.1f  %-4s %s" % (
        label, report["model"]["used"], len(report["verification"]), 100 * e, 100 * nu, 100 * ucs, 100 * st,
        report["wall_seconds"], "yes" if ok else "NO",
        "rigid nu<=%.3f%s" % (reach[0]["poisson_max"], (", DDEM nu<=%.3f" % reach[1]["poisson_max"])
                              if reach[1]["built"] else "")))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/calibration")
    parser.add_argument("--skip-ddem", action="store_true")
    parser.add_argument("--skip-study", action="store_true")
    parser.add_argument("--with-3d", action="store_true")
    parser.add_argument("--only", default="",
                        help="comma-separated cases to run: labra (maps built + stored), ddem, study, 3d")
    parser.add_argument("--ddem-count", type=int, default=0,
                        help="discs of the nu 0.27 (DDEM) UCS specimen, default: the calibrator's 5,000")
    parser.add_argument("--count-3d", type=int, default=0,
                        help="spheres of the 3D UCS specimen, default: the calibrator's 20,000")
    parser.add_argument("--study-points", default="1000:3,1000:5,2500:3,2500:5,5000:4",
                        help="specimen discs:sweep levels of the error-against-time study")
    args = parser.parse_args()
    try:
        study_points = [tuple(int(v) for v in p.split(":")) for p in args.study_points.split(",")]
        if any(len(p) != 2 or p[0] < 500 or not 3 <= p[1] <= 12 for p in study_points):
            raise ValueError
    except ValueError:
        parser.error("--study-points: expected N:L pairs (N >= 500 discs, L sweep levels in 3..12), got '%s'"
                     % args.study_points)
    cases = {"labra", "ddem", "study"} | ({"3d"} if args.with_3d else set())
    if args.skip_ddem:
        cases.discard("ddem")
    if args.skip_study:
        cases.discard("study")
    if args.only:
        cases = set(c.strip() for c in args.only.split(","))
        unknown = cases - {"labra", "ddem", "study", "3d"}
        if unknown:
            parser.error("--only: unknown case(s) %s; allowed: labra, ddem, study, 3d" % ", ".join(sorted(unknown)))
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    materials = os.path.join(root, "data", "materials")
    shutil.rmtree(args.out, ignore_errors=True)
    os.makedirs(args.out)
    maps = os.path.join(args.out, "maps")

    print("%-34s %6s %3s %8s %8s %8s %8s %8s  %-4s %s" % ("case", "model", "rnd", "E err", "nu err", "UCS err",
                                                          "st err", "time s", "met", "reach"))
    labra = os.path.join(materials, "labra2012_rock.toml")
    results = []
    if "labra" in cases:
        first = calibrate(args.build, labra, args.out, "labra_2d", maps)
        row("2D Labra rock, maps built", first, (0.02, 0.02, 0.03))
        again = calibrate(args.build, labra, args.out, "labra_2d_reuse", maps)
        row("2D Labra rock, stored maps", again, (0.02, 0.02, 0.03))
        results += [("labra_2d", first), ("labra_2d_reuse", again)]
        print("maps built in %.0f s (%d points); stored maps: %s" % (
            first["maps"]["sweep_seconds"], first["maps"]["sweep_points"], first["maps"]["file"]))
        for note in first["notes"]:
            print("  note:", note)
    if "ddem" in cases:
        extra = ["--count", str(args.ddem_count)] if args.ddem_count else []
        high = calibrate(args.build, os.path.join(materials, "high_poisson_2d.toml"), args.out, "high_nu_2d", maps,
                         extra)
        row("2D nu 0.27 (above DEM), auto", high, (0.03, 0.03, 0.03))
        results.append(("high_nu_2d", high))
    if "3d" in cases:
        extra = ["--dimension", "3"] + (["--count", str(args.count_3d)] if args.count_3d else [])
        three = calibrate(args.build, labra, args.out, "labra_3d", maps, extra)
        row("3D Labra rock", three, (0.03, 0.03, 0.05))
        results.append(("labra_3d", three))

    if "study" in cases:
        # Error of the maps' first prediction (round 1) against the time it took, as the
        # specimen grows and the sweep gets denser. Fresh maps each time.
        study = os.path.join(args.out, "error_vs_time.csv")
        with open(study, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["particles", "sweep_levels", "seconds", "error_youngs", "error_poisson", "error_ucs",
                        "rms_error"])
            print("\nerror of the first prediction against run time (fresh maps, one verification round)")
            print("%9s %6s %8s %8s %8s %8s %8s" % ("particles", "levels", "time s", "E err", "nu err", "UCS err",
                                                   "rms"))
            for count, levels in study_points:
                d = os.path.join(args.out, "study_%d_%d" % (count, levels))
                os.makedirs(d)
                r = calibrate(args.build, labra, d, "c", os.path.join(d, "maps"),
                              ["--count", str(count), "--sweep-levels", str(levels), "--rounds", "1"])
                e, nu, ucs, _ = errors(r, 0)
                rms = ((e * e + nu * nu + ucs * ucs) / 3) ** 0.5
                w.writerow([r["specimens"]["ucs"]["particles"], levels, "%.1f" % r["wall_seconds"], e, nu, ucs, rms])
                print("%9d %6d %8.1f %7.2f%% %7.2f%% %7.2f%% %7.2f%%" % (
                    r["specimens"]["ucs"]["particles"], levels, r["wall_seconds"], 100 * e, 100 * nu, 100 * ucs,
                    100 * rms))
        if shutil.which("gnuplot"):
            png = os.path.join(args.out, "error_vs_time.png")
            script = ("set terminal pngcairo size 900,650; set output '%s'; set datafile separator ',';"
                      "set logscale y; set xlabel 'wall time to the first prediction [s]';"
                      "set ylabel 'RMS relative error of E, nu, UCS (round 1)'; set grid; set key bottom right;"
                      "plot '%s' every ::1 using 3:(100*$7):(sprintf('%%d, %%d', $1, $2)) with labels offset 0,1 "
                      "notitle, '' every ::1 using 3:(100*$7) with points pt 7 ps 1.5 title 'N discs, sweep levels'"
                      % (png, study))
            subprocess.run(["gnuplot", "-e", script], check=False)
            print("plot:", png)
    summary = os.path.join(args.out, "summary.csv")
    with open(summary, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "model", "rounds", "error_youngs", "error_poisson", "error_ucs", "error_tensile",
                    "seconds", "converged"])
        for name, r in results:
            e, nu, ucs, st = errors(r)
            w.writerow([name, r["model"]["used"], len(r["verification"]), e, nu, ucs, st,
                        "%.1f" % r["wall_seconds"], r["converged"]])
    print("tables:", summary)


if __name__ == "__main__":
    sys.exit(main())
