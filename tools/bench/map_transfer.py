#!/usr/bin/env python3
"""Transfer of the maps: how well the stored 2D maps (data/maps) predict sigma_c / sigma_t on
the calibrator's real specimens before any round, at every strength round the calibration
benchmark measured (twins and published rocks, rigid and DDEM).

  tools/bench/map_transfer.py [--build build] [--rounds bench-out/calibration] [--maps data/maps]
        [--out bench-out/map_transfer] [--markdown FILE]

Run after tools/bench/calibration_bench.py (its output directory holds the rounds: every
*_verification.csv, with the micro parameters and the measured UCS and Brazilian strength).
Four predictions of each measured ratio, by tools/bench/map-transfer: the fitted surfaces
(total degree 2 in the dimensionless groups) and the sweep grid (the tensor-product
interpolant through the sweep points), each as fitted and as corrected by the measurements
stored with the maps (the calibration's state before its first round). The table gives the
error of each, ln(predicted / measured): median of its absolute value, root mean square,
largest, and the share within the slack of a calibration round (the sigma_t tolerance, 5 %).
Only rounds inside the maps' box count (the others are clamped by the surrogate).
"""
import argparse
import csv
import glob
import json
import math
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_bench import ROOT  # noqa: E402
from strength_noise import generate  # noqa: E402

PREDICTORS = [("surfaces", "surfaces, fitted"), ("surfaces_corrected", "surfaces, corrected"),
              ("grid", "sweep grid, fitted"), ("grid_corrected", "sweep grid, corrected")]


def box_of(maps_path):
    with open(maps_path) as f:
        j = json.load(f)
    box = {a["ratio"]: (a["lower"], a["upper"]) for a in j["design"]["axes"]}
    return box, j["design"]["fixed"]


def inside(box, name, value):
    if name not in box:
        return True
    lo, hi = box[name]
    return lo * (1 - 1e-9) <= value <= hi * (1 + 1e-9)


def collect(rounds_dir, boxes):
    """{model: [(label, kt/kn, kn/(Ep l), Rt/Rn, ucs, sigma_t)]} from every verification CSV."""
    points = {"dem": [], "ddem": []}
    for path in sorted(glob.glob(os.path.join(rounds_dir, "**", "*_verification.csv"), recursive=True)):
        case = os.path.relpath(os.path.dirname(path), rounds_dir)
        if "3d" in case.lower():
            continue
        with open(path) as f:
            for row in csv.DictReader(f):
                if row.get("failed") == "1" or not row["ucs_pa"] or float(row["ucs_pa"]) <= 0:
                    continue
                kn, kt = float(row["kn_n_per_m_per_m"]), float(row["kt_n_per_m_per_m"])
                ep = float(row["particle_youngs_modulus_pa"] or 0.0)
                model = "ddem" if ep > 0 else "dem"
                ratios = {"kt/kn": kt / kn, "Rt/Rn": float(row["rt_n_per_m"]) / float(row["rn_n_per_m"]),
                          "kn/(Ep l)": kn / ep if ep > 0 else 0.0}
                box, fixed = boxes[model]
                if abs(float(row["friction"]) - fixed["friction"]) > 1e-9:
                    continue
                if not all(inside(box, k, v) for k, v in ratios.items()):
                    continue
                points[model].append(("%s round %s" % (case, row["round"]), ratios["kt/kn"], ratios["kn/(Ep l)"],
                                      ratios["Rt/Rn"], float(row["ucs_pa"]), float(row["tensile_strength_pa"])))
    return points


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--rounds", default="bench-out/calibration", help="the calibration benchmark's output")
    parser.add_argument("--maps", default=os.path.join(ROOT, "data", "maps"))
    parser.add_argument("--out", default="bench-out/map_transfer")
    parser.add_argument("--markdown", help="the page to write (default OUT/map_transfer.md)")
    args = parser.parse_args()
    build, out = os.path.abspath(args.build), os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    ucs_packing, bts_packing = generate(build, os.path.join(out, "specimens"))
    maps = {}
    for model in ("dem", "ddem"):
        found = glob.glob(os.path.join(args.maps, "maps_2d_%s_*.json" % model))
        if len(found) != 1:
            sys.exit("map_transfer.py: expected one 2D %s map file in %s, found %d" % (model, args.maps, len(found)))
        maps[model] = found[0]
    boxes = {m: box_of(p) for m, p in maps.items()}
    points = collect(os.path.abspath(args.rounds), boxes)
    lines = ["| maps | rounds | prediction | median abs. error | rms | largest | within 5 % |", "|---|---|---|---|---|---|---|"]
    for model in ("dem", "ddem"):
        if not points[model]:
            continue
        path = os.path.join(out, "points_%s.csv" % model)
        with open(path, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["label", "kt_over_kn", "kn_over_ep_l", "rt_over_rn", "ucs_pa", "tensile_strength_pa"])
            for p in points[model]:
                w.writerow([p[0].replace(",", " ")] + ["%r" % v for v in p[1:]])
        result = subprocess.run([os.path.join(build, "tools", "bench", "map-transfer"), "--maps", maps[model],
                                 "--ucs-packing", ucs_packing, "--bts-packing", bts_packing, "--points", path],
                                capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit("map-transfer failed: " + result.stderr)
        with open(os.path.join(out, "predictions_%s.csv" % model), "w") as f:
            f.write(result.stdout)
        rows = list(csv.DictReader(result.stdout.splitlines()))
        name = "rigid (%s)" % os.path.basename(maps[model]) if model == "dem" else "DDEM (%s)" % os.path.basename(
            maps[model])
        for key, label in PREDICTORS:
            errors = [math.log(float(r[key]) / float(r["measured"])) for r in rows]
            absolute = [abs(e) for e in errors]
            lines.append("| %s | %d | %s | %.1f %% | %.1f %% | %.1f %% | %d of %d |" % (
                name, len(rows), label, 100 * statistics.median(absolute),
                100 * math.sqrt(statistics.fmean(e * e for e in errors)), 100 * max(absolute),
                sum(1 for a in absolute if a <= math.log(1.05)), len(rows)))
        lines.append("| | | (stored measurements with the maps: %s; the spread of their corrections, the reach's "
                     "transfer uncertainty: %.1f %%; their leave-one-out error, rms: %.1f %%) | | | | |" % (
                         rows[0]["stored_measurements"], 100 * float(rows[0]["correction_spread"]),
                         100 * float(rows[0]["correction_leave_one_out_rms"])))
    text = "\n".join(lines)
    print(text)
    with open(args.markdown or os.path.join(out, "map_transfer.md"), "w") as f:
        f.write(text + "\n")


if __name__ == "__main__":
    main()
