#!/usr/bin/env python3
"""Benchmark of stability-limit: predicted against measured limits, and speed.

  tools/bench/stability_bench.py [--build build] [--out bench-out/stability]
                                 [--quick] [--only REGEX] [--skip-grid] [--skip-timing] [--runs 3]
                                 [--markdown PATH] [--merge JSON]

1. Packings by generate-packing (r_max/r_min <= 10): 2D 500 discs, 3D 500 spheres, 2D with a
   mean radius of 1e-5 m; and Madan's SC 9x20 / HCP 110-disc lattices (written by
   stability-bench --write-lattices) for the wall rows.
2. The grid of cases, each row one stability-bench run (tools/bench/stability_bench.cpp):
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
4. The tables as Markdown with the command and the machine (write_markdown): OUT/stability_bench.md,
   or --markdown PATH (tools/bench/stability_bench.md is the committed one). --merge JSON keeps
   the rows of an earlier run's stability_bench.json that this run did not measure (a run with
   --only or --skip-grid then still writes the whole table).
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


def _range(low, high, fmt="%.1f"):
    """"a-b", or "a" when both print alike."""
    a, b = fmt % low, fmt % high
    return a if a == b else "%s-%s" % (a, b)


def _share(value, linear):
    """value / linear as a share with two decimals, or None."""
    if value is None or linear is None or not linear or value != value:
        return None
    return value / linear


def _number(value, fmt="%.5g"):
    return "-" if value is None or value != value else fmt % value


def _grid_line(r):
    """One row of the grid table (the columns of main()'s printout, without the seconds)."""
    unit = ""
    if r.get("mode") == "ep":
        unit = " (kn/(Ep R))" if r["case"].startswith("3D") else " (kn/Ep)"
    unstable = r.get("measured_unstable")
    if unstable is None or unstable != unstable:
        measured = "%s / none up to 1.02" % _number(r.get("measured_stable"))
    else:
        measured = "%s / %s" % (_number(r.get("measured_stable")), _number(unstable))
    ok = r.get("within_3_percent_and_safe")
    if ok is None:
        ok = 0.97 <= r["ratio"] <= 1.0
    flag = "" if ok else (" (unsafe)" if r["ratio"] > 1.0 else " (!)")
    reduction = r.get("ddem_reduction_percent")
    rho = r.get("spectral_radius")
    return "| %s%s | %d | %.2f | %s | %s | %.4f%s | %s | %s | %s |" % (
        r["case"], unit, r["particles"], r["radius_ratio"], _number(r["predicted"]), measured,
        r["ratio"], flag, _number(r.get("ratio_ritz"), "%.4f"),
        "%.2f %%" % reduction if reduction is not None else "-",
        "%.3f" % rho if rho is not None else "-")


def write_markdown(path, grid_rows, timings, command, machine_note, notes=()):
    """Writes tools/bench/stability_bench.md: the grid (predicted against measured limits),
    the first failures of the wall scans as shares of the linear limit, and the timings of
    the full analysis on 50,000 particles, with the command and the machine.

    grid_rows: the dictionaries main() collects (case, particles, radius_ratio, mode,
    predicted, measured_stable, measured_unstable, ratio, ratio_ritz, ddem_reduction_percent,
    spectral_radius, within_3_percent_and_safe; scan rows also linear_critical_time_step_s).
    timings: case, particles, links, threads, median_seconds, cpu_seconds, ddem_seconds.
    command: Markdown, the command(s) that reproduce the tables (in backquotes).
    notes: further sentences on the grid (one bullet each). Either list may be empty (that
    section is then left out)."""
    lines = [
        "# stability-limit benchmark: predicted against measured limits, and speed",
        "",
        "Reproduce: %s" % command,
        "(`--only REGEX` selects rows, `--skip-grid`, `--skip-timing`, `--runs`, `--threads`;",
        "`--markdown PATH` writes this file,",
        "`--merge JSON` keeps the rows of an earlier run's `stability_bench.json` that this run did",
        "not measure). Machine: %s." % machine_note,
        "",
    ]
    if grid_rows:
        passed = [r for r in grid_rows if r.get("within_3_percent_and_safe",
                                                0.97 <= r["ratio"] <= 1.0)]
        missed = [r for r in grid_rows if r not in passed]
        unsafe = [r for r in missed if r["ratio"] > 1.0]
        lines += [
            "## Predicted against measured",
            "",
            "Each row is one `stability-bench` run (`tools/bench/stability_bench.cpp`). Predicted:",
            "the certified critical step of the analysis (`critical_time_step_s`), or for the",
            "\"kn/Ep limit\" rows the admissible kn/(Ep l) (3D: kn/(Ep R_mean)) at rho(B) = 1.",
            "Measured: bisection with real solver runs from random velocities (and spins when",
            "kt > 0), undamped unless stated; a run is stable when the solver's divergence guard",
            "(kinetic energy 1e6 x the energy supplied, a contact force beyond what that energy",
            "could hold, or NaN) does not fire within 5,000 steps (20,000-30,000 near rho(B) = 1).",
            "The \"kn/Ep limit\" rows bisect on Ep at 0.1 x the DEM critical step. Ratio =",
            "predicted / largest stable value: it must be <= 1 (never on the unsafe side) and",
            ">= 0.97 (within 3 %). \"Ratio (Ritz)\" uses the Ritz value, the sharp estimate (on",
            "the unsafe side by construction). Packings by generate-packing with `--radius-ratio",
            "10`, kn = 7e10 N/m, 2000 kg/m^3, plane strain; \"x lim\" = kn/(Ep l) as that share of",
            "the packing's own limit rho(B) = 1. Rows marked (scan) are scanned, not bisected",
            "(below).",
            "",
            "| case | particles | R_max/R_min | predicted | measured (stable / unstable) | ratio "
            "| ratio (Ritz) | DDEM reduction | rho(B) |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        lines += [_grid_line(r) for r in grid_rows]
        summary = "%d of %d rows within 3 %% and on the safe side." % (len(passed), len(grid_rows))
        if missed:
            walls = [r for r in missed if "walls" in r["case"]]
            summary += " The %d other%s: %d wall row%s" % (
                len(missed), "" if len(missed) == 1 else "s", len(walls),
                "" if len(walls) == 1 else "s")
            if len(walls) < len(missed):
                summary += " and %d other%s" % (len(missed) - len(walls),
                                                "" if len(missed) - len(walls) == 1 else "s")
            safe = [r for r in missed if r["ratio"] <= 1.0]
            if safe:
                summary += "; %d on the safe side but %s %% conservative" % (
                    len(safe), _range(100.0 * (1.0 - max(r["ratio"] for r in safe)),
                                      100.0 * (1.0 - min(r["ratio"] for r in safe)), "%.0f"))
            summary += "; %d on the unsafe side." % len(unsafe)
        lines += ["", summary, ""]
        bonded = [r for r in grid_rows if r.get("mode") == "dt" and "walls" not in r["case"]]
        ddem = [r for r in bonded if r.get("ddem_reduction_percent") is not None
                and r["ddem_reduction_percent"] > 0.0]
        limits = [r for r in grid_rows if r.get("mode") == "ep"]
        if bonded:
            lines.append("- Bonded networks without walls (%d row%s): the certified prediction is "
                         "%s %% below the measured limit, the Ritz value at %s of it." % (
                             len(bonded), "" if len(bonded) == 1 else "s",
                             _range(100.0 * (1.0 - max(r["ratio"] for r in bonded)),
                                    100.0 * (1.0 - min(r["ratio"] for r in bonded))),
                             _range(min(r["ratio_ritz"] for r in bonded),
                                    max(r["ratio_ritz"] for r in bonded), "%.4f")))
        if ddem:
            lines.append("- DDEM lowers the critical step by %s %% (the most near rho(B) = 1: "
                         "the two limits interact)." % _range(
                             min(r["ddem_reduction_percent"] for r in ddem),
                             max(r["ddem_reduction_percent"] for r in ddem), "%.2f"))
        if limits:
            lines.append("- The admissible kn/(Ep l) is %s %% below the measured limit of the "
                         "runs." % _range(100.0 * (1.0 - max(r["ratio"] for r in limits)),
                                          100.0 * (1.0 - min(r["ratio"] for r in limits)), "%.2f"))
        lines += ["- %s" % note for note in notes]
        lines.append("")
        scans = [r for r in grid_rows if r.get("mode") == "scan"]
        if scans:
            lines += [
                "## Walls: impacts (unilateral contacts)",
                "",
                "Walls hold only in compression. When a wall contact opens and closes the scheme is",
                "piecewise linear, and central differences on such a system can grow at steps below",
                "the linear limit; the boundary between bounded and diverging runs is not monotonic",
                "in the step. The wall rows are therefore scanned at 0.80-1.02 of the linear",
                "certified step, 0.01 apart; measured = the largest probed step below which every",
                "run was bounded, and the first probe that failed. Every probe presses the walls in",
                "by 1e-3 mean radii three times, over 4,000, 8,000 and 16,000 steps (the worst",
                "counts), and a run fails when the kinetic energy grows 1e4-fold after the press-in,",
                "the solver's guard fires, or a loaded wall contact chatters (it opens 10 times",
                "within 100 steps with a peak force above its force after the press-in). The top",
                "mode of these scenes sits on one particle whose wall contact opens and closes: an",
                "impact oscillator. One particle on a spring k against a wall 10 k (no preload)",
                "grows a millionfold within 4,000 steps at 0.42, 0.66, 0.73, 0.81-0.82, 0.90-0.92",
                "and 0.98 of its closed-contact limit undamped, and at 0.75, 0.82-0.85 and 0.95 with",
                "local damping 0.1.",
                "",
                "The analysis holds a scene with wall links to a factor x the linear limit",
                "(`DampedUnilateralFactor` in `solver/stability_limits.h`; damping = the larger",
                "of alpha and the dashpot ratios): 0.85 below 0.05; from 0.05 to 0.1, 0.94 (2D) and",
                "0.92 (3D); from 0.1 to 0.3, 1 (2D) and 0.96 (3D); 1 from 0.3. Shares of the linear",
                "limit (the predicted step divided by that factor):",
                "",
                "| case | factor | largest bounded | first failure |",
                "|---|---|---|---|",
            ]
            for r in scans:
                linear = r.get("linear_critical_time_step_s")
                factor = r["predicted"] / linear if linear else None
                first = _share(r.get("measured_unstable"), linear)
                lines.append("| %s | %s | %s | %s |" % (
                    r["case"], _number(factor, "%.2f"),
                    _number(_share(r.get("measured_stable"), linear), "%.2f"),
                    "%.2f" % first if first is not None else "none up to 1.02"))
            lines += [
                "",
                "No factor is a proof for impacts: the threshold of an impact oscillator moves",
                "between packings by more than the 3 % band, so the factors take the worst packing",
                "measured and are conservative on others. The virtual laboratory's damping (0.7)",
                "gets no factor. The lattice rows fail at the linear limit itself (their wall",
                "contacts stay closed); they use kt/kn = 0.5 because with kt = 0 the square lattice",
                "between preloaded walls is a mechanism and buckles at any step. In rho(B) the",
                "analysis counts a wall link like a bond (its force enters the particle stress, its",
                "gap is corrected by the strain); a wall holds only in compression, which clamps",
                "the alternating mode of the force iteration, so with walls much stiffer than kn",
                "the admissible kn/(Ep l) is on the safe side but about 2x too strict.",
                "",
            ]
    if timings:
        threads = sorted({t["threads"] for t in timings})
        label = lambda n: "the idle cores" if n == 0 else "%d thread%s" % (n, "" if n == 1 else "s")
        header = "| analysis | particles | links |"
        rule = "|---|---|---|"
        for n in threads:
            header += " wall time, %s [s] | of which DDEM step [s] |" % label(n)
            rule += "---|---|"
        lines += [
            "## Speed: the full analysis of 50,000 particles",
            "",
            "`stability-limit` on generate-packing packings (2D rectangle 0.1 m, 3D box 0.03 m),",
            "wall time including reading the packing and writing the JSON, median of the runs;",
            "\"-\": no DDEM step, or not measured.",
            "",
            header,
            rule,
        ]
        cases = []
        for t in timings:
            if t["case"] not in cases:
                cases.append(t["case"])
        for case in cases:
            rows = {t["threads"]: t for t in timings if t["case"] == case}
            first = next(iter(rows.values()))
            line = "| %s | %d | %d |" % (case, first["particles"], first["links"])
            for n in threads:
                t = rows.get(n)
                ddem = t.get("ddem_seconds") if t else None
                line += " %s | %s |" % (
                    _number(t.get("median_seconds") if t else None, "%.2f"),
                    "%.2f" % ddem if ddem else "-")
            lines.append(line)
        lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines))


def merge_rows(new, old, key):
    """The rows of `old` with those of `new` in their place (same key), new ones appended."""
    fresh = {key(r): r for r in new}
    merged = [fresh.pop(key(r), r) for r in old]
    return merged + [r for r in new if key(r) in fresh]


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
    parser.add_argument("--markdown", default=None,
                        help="where to write the tables as Markdown (default "
                             "OUT/stability_bench.md; tools/bench/stability_bench.md is the "
                             "committed one)")
    parser.add_argument("--merge", default=None,
                        help="an earlier run's stability_bench.json: its rows that this run did "
                             "not measure are kept in the Markdown")
    args = parser.parse_args()
    load_before = " ".join("%.1f" % v for v in os.getloadavg())
    earlier = {}
    if args.merge:  # read now: this run may write the same file
        with open(args.merge) as f:
            earlier = json.load(f)
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
                            "within_3_percent_and_safe": ok, "seconds": r["seconds"],
                            "linear_critical_time_step_s": ts.get("linear_critical_time_step_s"),
                            "unilateral_factor": ts.get("unilateral_factor")})
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
            mean_radius_3d = json.load(f)["metrics"]["mean_radius_m"]
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
            ddem = [a["time_step"].get("ddem_eigenvalue", {}).get("wall_time_s", 0.0)
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

    # 4. The Markdown tables.
    grid_rows, timing_rows = results, timings
    if args.merge:
        grid_rows = merge_rows(results, earlier.get("grid", []), lambda r: r["case"])
        timing_rows = merge_rows(timings, earlier.get("timings", []),
                                 lambda r: (r["case"], r["threads"]))
    markdown = args.markdown or os.path.join(args.out, "stability_bench.md")
    command = "`%s`" % " ".join(["tools/bench/stability_bench.py"] + sys.argv[1:])
    if args.merge:
        command += ", with the rows of `%s` that it did not measure" % args.merge
    load_after = " ".join("%.1f" % v for v in os.getloadavg())
    write_markdown(markdown, grid_rows, timing_rows, command,
                   "%d cores, load average %s before and %s after the runs" % (
                       os.cpu_count() or 0, load_before, load_after))
    print("\nwritten: %s/grid.csv, %s/stability_bench.json, %s" % (args.out, args.out, markdown))


if __name__ == "__main__":
    main()
