#!/usr/bin/env python3
"""calibrate-to-material --model lattice on the published rocks: prints a table and writes
it next to this script (lattice_calibration_bench.md; --markdown to write it elsewhere).

  tools/bench/lattice_calibration_bench.py [--build build] [--out bench-out/lattice_calibration]
        [--only name,name] [--count 5000] [--markdown FILE] [--no-baseline]

For every material of data/materials/published/ and the bundled Labra rock: what the strength
map says before round 1 (the interval of UCS / sigma_t the lattice reaches at the rock's nu),
the rounds, the best round's errors (E, nu from the UCS's linear portion; UCS, sigma_t), the
outcome (converged; sigma_t given up when out of reach; not converged within the rounds) and
the wall time. Tolerances: E, nu 1.5 %, UCS 2 %, sigma_t 5 %. The map is the stored one of the
default specimens (data/maps/maps_2d_lattice_*.json; rows a rock needs and the map lacks are
measured by its run, and the wall time includes them). Unless --no-baseline, each rock is also
calibrated without the map (--lattice-map none: the rounds start from the closed form), side
by side in the same run.
"""
import argparse
import glob
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(tool, material, d, name, count, extra):
    """One calibration; its figures from the report."""
    command = [tool, material, "--model", "lattice", "--output", d, "--name", name, "--quiet", "--no-pictures"] + extra
    if count > 0:
        command += ["--count", str(count)]
    start = time.monotonic()
    p = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    seconds = time.monotonic() - start
    if p.returncode not in (0, 4):
        raise RuntimeError("%s failed (%d): %s" % (name, p.returncode, p.stderr))
    with open(os.path.join(d, name + "_report.json")) as f:
        r = json.load(f)
    best = r["rounds"][r["best_round"] - 1]["relative_errors"]
    if "sigma_t" in r["given_up"]:
        outcome = "UCS met, sigma_t given up" if r["converged"] else "sigma_t given up, **UCS not met**"
    else:
        outcome = "converged" if r["converged"] else "**not converged**"
    reach = "none"
    if r.get("map", {}).get("used"):
        m = r["map"]
        reach = "%s %.1f-%.0f" % ("in" if m["reachable"] else "**out of reach**,", m["ratio_low"], m["ratio_high"])
    target = r["target"]
    return {"name": target["name"], "nu": target["poisson_ratio"], "rounds": len(r["rounds"]),
            "best": r["best_round"], "errors": best, "outcome": outcome, "seconds": seconds, "reach": reach,
            "ratio": target["ucs_pa"] / target["tensile_strength_pa"]}


def summary_line(rows, label):
    converged = sum(1 for row in rows if row["outcome"] == "converged")
    capped = sum(1 for row in rows if row["outcome"].startswith("UCS met"))
    return ("%s: %d of %d converged on every property, %d more met the UCS with sigma_t given up (declared in "
            "the report); %d rounds in all; median wall time %.0f s." % (
                label, converged, len(rows), capped, sum(row["rounds"] for row in rows),
                statistics.median(row["seconds"] for row in rows) if rows else 0.0))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--out", default=os.path.join(ROOT, "bench-out", "lattice_calibration"))
    parser.add_argument("--only", default="", help="comma-separated file names without .toml")
    parser.add_argument("--count", type=int, default=0, help="UCS specimen size (0: the calibrator's default)")
    parser.add_argument("--no-baseline", action="store_true", help="skip the runs without the map")
    parser.add_argument("--markdown", default=os.path.join(ROOT, "tools", "bench", "lattice_calibration_bench.md"),
                        help="the page to write")
    args = parser.parse_args()
    tool = os.path.join(os.path.abspath(args.build), "tools", "calibrate-to-material")
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    materials = sorted(glob.glob(os.path.join(ROOT, "data", "materials", "published", "*.toml")))
    materials.append(os.path.join(ROOT, "data", "materials", "labra2012_rock.toml"))
    if args.only:
        wanted = set(args.only.split(","))
        materials = [m for m in materials if os.path.basename(m)[:-5] in wanted]
    rows = []
    for material in materials:
        name = os.path.basename(material)[:-5]
        row = run(tool, material, os.path.join(out, name), name, args.count, [])
        if not args.no_baseline:
            row["baseline"] = run(tool, material, os.path.join(out, name + "_closed_form"), name, args.count,
                                  ["--lattice-map", "none"])
        rows.append(row)
        print("  %s: %s in %d rounds, %.0f s%s" % (
            name, row["outcome"], row["rounds"], row["seconds"],
            "" if args.no_baseline else "; without the map %s in %d rounds, %.0f s" % (
                row["baseline"]["outcome"], row["baseline"]["rounds"], row["baseline"]["seconds"])), flush=True)
    lines = ["| material | nu | sigma_c / sigma_t | map before round 1 | rounds (best) | E | nu | UCS | sigma_t | "
             "outcome | wall |" + ("" if args.no_baseline else " without the map: rounds, outcome, wall |"),
             "|---|---|---|---|---|---|---|---|---|---|---|" + ("" if args.no_baseline else "---|")]
    for row in rows:
        e = row["errors"]
        line = "| %s | %.2f | %.1f | %s | %d (%d) | %+.2f %% | %+.2f %% | %+.2f %% | %+.2f %% | %s | %.0f s |" % (
            row["name"], row["nu"], row["ratio"], row["reach"], row["rounds"], row["best"], 100 * e["youngs_modulus"],
            100 * e["poisson_ratio"], 100 * e["ucs"], 100 * e["tensile_strength"], row["outcome"], row["seconds"])
        if not args.no_baseline:
            b = row["baseline"]
            line += " %d, %s, %.0f s |" % (b["rounds"], b["outcome"], b["seconds"])
        lines.append(line)
    lines.append("")
    lines.append(summary_line(rows, "from the map"))
    if not args.no_baseline:
        lines.append("")
        lines.append(summary_line([row["baseline"] for row in rows], "without the map (side by side)"))
    text = "\n".join(lines)
    print(text)
    command = "python3 tools/bench/lattice_calibration_bench.py" + (" --only " + args.only if args.only else "") + (
        " --count %d" % args.count if args.count > 0 else "") + (" --no-baseline" if args.no_baseline else "")
    header = ["# calibrate-to-material --model lattice on published rocks", "",
              "Reproduce: `OMP_WAIT_POLICY=passive %s` (2 cores). The six-spring lattice (2D, plane strain) "
              "takes E and nu as inputs (the linear portion of each round's UCS checks them) and finds the "
              "triangles' cohesion and tensile strength by rounds of UCS and Brazilian tests on the "
              "calibrator's default specimens, from the start the stored strength map gives (the column "
              "'map before round 1': the interval of UCS / sigma_t it reaches at the rock's nu, and whether "
              "the rock's lies in it); the friction angle is the material's when it gives one, else free. "
              "'Without the map': the same rock from the closed-form start (--lattice-map none), run side "
              "by side. Tolerances: E, nu 1.5 %%, UCS 2 %%, sigma_t 5 %%." % command, ""]
    with open(args.markdown, "w") as f:
        f.write("\n".join(header) + "\n" + text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
