#!/usr/bin/env python3
"""Benchmark of calibrate-to-material on targets it was not tuned on: prints tables, writes
CSV files and a plot of the error of every property against the strength round.

  tools/bench/calibration_bench.py [--build build] [--out bench-out/calibration]
        [--twins 16] [--ddem-twins 6] [--first-twin 1] [--pick 4,9] [--twins-3d 0] [--count-3d 20000] [--seed 1]
        [--only maps,twins,published,3d] [--reuse-shipped-maps] [--anchor-levels 2]

1. Maps (unless --reuse-shipped-maps): the bundled Labra rock (2D, rigid) and the bundled
   nu 0.27 rock (2D, DDEM) calibrated from an empty map directory: maps built (sweep and
   transfer anchors) and the calibration, timed. Target: <= 12 min each. The maps they
   build, stripped of the two calibrations' own runs (only the transfer anchors stay), are
   the master maps of what follows; with --reuse-shipped-maps the master is data/maps.
   --anchor-levels 3: the maps built with 13 transfer anchors, or the shipped ones completed
   to them (one round of each bundled rock measures the anchors they lack; its own runs are
   stripped); `--only maps --reuse-shipped-maps --anchor-levels 3` makes OUT/maps_master so.
2. Twin experiments: targets made by forward runs (run-test: the elastic run, the UCS and
   the Brazilian test, as the calibrator runs them) at hidden micro parameters drawn across
   the admissible box, rigid and DDEM, on the calibrator's own default specimens. The
   calibrator gets only E, nu, UCS and sigma_t, and a fresh copy of the master maps (which
   hold no measurement of that target). Target: every twin within E, nu 1.5 %, UCS 2 %,
   sigma_t 5 % in at most 3 strength rounds; median wall time <= 3 min.
3. Published rocks (data/materials/published/, each file citing its source, and the
   bundled granitic gneiss): each either converges, or is declared out of reach before the
   first strength round (the report names what is given up), exit status 4.
4. --twins-3d N: N 3D twins (rigid) on --count-3d spheres (maps built for that size first).
5. 3d_low (--only 3d_low, after a 3d run into the same --out): two 3D twins made by rigid
   spheres at kt/kn 0.06 and 0.1, below the maps' default box (nu 0.26-0.28, beyond its
   reach), calibrated with the box widened (--sweep-stiffness-ratio 0.04 0.9); the first
   builds the maps from an empty directory, the second gets them stripped to their anchors.
Times are wall times of single runs on this machine; say how loaded it was.
"""
import argparse
import csv
import glob
import hashlib
import json
import math
import os
import random
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOLERANCES = {"youngs_modulus": 0.015, "poisson_ratio": 0.015, "ucs": 0.02, "tensile_strength": 0.05}
MAX_ROUNDS = 3  # the target: converged within this many strength rounds


def run(command, **kwargs):
    return subprocess.run(command, capture_output=True, text=True, **kwargs)


def sha(path):
    """Of a packing's content: its created_by line (the program version) left out."""
    with open(path, "rb") as f:
        return hashlib.sha256(b"".join(l for l in f if not l.startswith(b"created_by "))).hexdigest()


def calibrate(build, material, out, name, maps, extra=()):
    os.makedirs(out, exist_ok=True)
    command = [os.path.join(build, "tools", "calibrate-to-material"), material, "--output", out, "--name", name,
               "--maps-dir", maps, "--quiet", "--no-pictures"] + list(extra)
    start = time.monotonic()
    result = run(command)
    seconds = time.monotonic() - start
    if result.returncode not in (0, 4):
        raise RuntimeError("calibrate-to-material %s failed (%d):\n%s%s" % (material, result.returncode,
                                                                           result.stdout[-3000:], result.stderr))
    with open(os.path.join(out, name + "_report.json")) as f:
        report = json.load(f)
    report["wall_seconds"] = seconds
    report["exit_status"] = result.returncode
    return report


def strip_to_anchors(maps_dir):
    """Keeps only the transfer anchors of every map file (a calibration's own runs go)."""
    for path in glob.glob(os.path.join(maps_dir, "maps_*.json")):
        with open(path) as f:
            j = json.load(f)
        j["verified"] = [v for v in j.get("verified", []) if v.get("origin") == "anchor"]
        with open(path, "w") as f:
            json.dump(j, f)


def fresh_maps(master, where):
    shutil.rmtree(where, ignore_errors=True)
    shutil.copytree(master, where)
    return where


def deformable_bound(maps_dir, dimension):
    """kn/(Ep l) upper end and nu_p of the DDEM maps in the directory (None if none)."""
    for path in glob.glob(os.path.join(maps_dir, "maps_%dd_ddem_*.json" % dimension)):
        with open(path) as f:
            j = json.load(f)
        for axis in j["design"]["axes"]:
            if axis["ratio"] == "kn/(Ep l)":
                return axis["upper"], j["design"]["fixed"]["particle_poisson_ratio"]
    return None


# --- Forward runs of a twin: run-test, as the calibrator runs its tests --------------------

def scene(packing, kind, material, name, strain_limit, sample_interval=None):
    lines = ["[specimen]", 'packing = "%s"' % packing, "scale_density = true", "", "[material]"]
    for key in ("normal_stiffness", "tangential_stiffness", "bond_tensile_strength", "bond_shear_strength",
                "friction_coefficient", "density", "particle_youngs_modulus", "particle_poisson_ratio"):
        if key in material:
            lines.append("%s = %r" % (key, material[key]))
    lines += ["", "[test]", 'kind = "%s"' % kind, "strain_limit = %r" % strain_limit, "threads = 1"]
    if sample_interval:
        lines.append("sample_interval = %d" % sample_interval)
    lines += ["", "[output]", 'name = "%s"' % name, "pictures = false", "snapshots = false", ""]
    return "\n".join(lines)


def run_test(build, scene_text, directory, name):
    path = os.path.join(directory, name + ".toml")
    with open(path, "w") as f:
        f.write(scene_text)
    return subprocess.Popen([os.path.join(build, "tools", "run-test"), path, "--output", directory, "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def summary(directory, name):
    with open(os.path.join(directory, name + "_summary.json")) as f:
        return json.load(f)["result"]


def forward(build, packings, hidden, directory):
    """E, nu (intact: the elastic run), UCS and sigma_t at the hidden parameters."""
    os.makedirs(directory, exist_ok=True)
    kn, s, rn, x = hidden["kn"], hidden["kt_over_kn"], hidden["rn"], hidden["rt_over_rn"]
    elastic = {"normal_stiffness": kn, "tangential_stiffness": s * kn, "friction_coefficient": 0.8,
               "density": hidden["density"]}
    if hidden.get("kn_over_ep_l", 0.0) > 0.0:
        length = 1.0 if hidden["dimension"] == 2 else hidden["mean_radius"]
        elastic["particle_youngs_modulus"] = kn / (hidden["kn_over_ep_l"] * length)
        elastic["particle_poisson_ratio"] = hidden["particle_poisson_ratio"]
    strong = dict(elastic, bond_tensile_strength=rn, bond_shear_strength=x * rn)
    e = run_test(build, scene(packings[0], "ucs", elastic, "elastic", 1.5e-3, 50), directory, "elastic")
    # An elastic run has no peak by design: run-test says so with status 4 and writes its files.
    if e.wait() not in (0, 4) or not os.path.exists(os.path.join(directory, "elastic_summary.json")):
        raise RuntimeError("elastic run failed: " + e.stderr.read())
    u = run_test(build, scene(packings[0], "ucs", strong, "ucs", 0.05), directory, "ucs")
    b = run_test(build, scene(packings[1], "brazilian", strong, "bts", 0.05), directory, "bts")
    for p, what in ((u, "UCS"), (b, "Brazilian")):
        if p.wait() != 0:
            raise RuntimeError("%s test failed: %s" % (what, p.stderr.read()))
    linear = summary(directory, "elastic")["linear_elastic"]
    return {"youngs_modulus": linear["youngs_modulus_pa"], "poisson_ratio": linear["poisson_ratio"],
            "ucs": summary(directory, "ucs")["peak_stress_pa"],
            "tensile_strength": summary(directory, "bts")["tensile_strength_pa"]}


def write_target(path, name, target, density):
    with open(path, "w") as f:
        f.write("# A twin target: made by forward runs at hidden micro parameters (calibration_bench.py).\n")
        f.write('[material]\nname = "%s"\nyoungs_modulus = %r\npoisson_ratio = %r\nucs = %r\n'
                'tensile_strength = %r\ndensity = %r\n' % (name, target["youngs_modulus"], target["poisson_ratio"],
                                                        target["ucs"], target["tensile_strength"], density))


MEAN_RADIUS_2D = 3.77e-4  # of the calibrator's default 2D specimen [m]


def draw_hidden(rng, deformable, bound, dimension, mean_radius=None):
    """kn and Rn of the 2D draw are per metre of thickness on discs of MEAN_RADIUS_2D; in 3D
    they keep the stress scales on spheres of mean_radius: kn ~ E r, Rn ~ sigma r^2 (bonds in
    3D carry about 2.5 times the 2D bond stress for the same rock, as the 3D Labra rock
    calibrates: Rn 547 N on r 1.8 mm)."""
    h = {"dimension": dimension, "density": 2650.0, "kn": math.exp(rng.uniform(math.log(1e10), math.log(6e10))),
         "rn": math.exp(rng.uniform(math.log(4e3), math.log(2.5e4))), "rt_over_rn": rng.uniform(2.5, 9.5)}
    if dimension == 3:
        h["kn"] *= mean_radius
        h["rn"] *= 2.5 * mean_radius ** 2 / MEAN_RADIUS_2D
    if deformable:
        h["kt_over_kn"] = rng.uniform(0.2, 0.55)
        h["kn_over_ep_l"] = rng.uniform(0.15, 0.85) * bound[0]
        h["particle_poisson_ratio"] = bound[1]
    else:
        h["kt_over_kn"] = rng.uniform(0.2, 0.85)
    return h


# --- Reading a report ---------------------------------------------------------------------

def parameter(report, name):
    """A calibrated parameter of the report; in 2D its name ends with _per_m (per metre of thickness)."""
    return report["parameters"][name + ("_per_m" if report["dimension"] == 2 else "")]


def best_errors(report):
    """Of the best round; NaN when every round failed (no result)."""
    best = [r for r in report["verification"] if r["best"]]
    if not best:
        return {k: float("nan") for k in TOLERANCES}
    return best[0]["relative_errors"]


def met(errors):
    return all(abs(errors[k]) <= TOLERANCES[k] for k in TOLERANCES)


def row_of(label, report):
    e = best_errors(report)
    reach = report["reach"]["used"]
    # Declared before the first round: the reach as assessed then (a report without it: the
    # final reach, and no ratio given up on measurement in the notes).
    before = report["reach"].get("before_rounds")
    declared = before["declared_out_of_reach"] if before else reach["declared_out_of_reach"] and not any(
        "is out of reach on this specimen: round" in n for n in report.get("notes", []))
    return {
        "case": label, "model": report["model"]["used"], "rounds": len(report["verification"]),
        "best_round": report.get("best_round", 0),
        "failed_rounds": sum(1 for r in report["verification"] if r.get("failed")),
        "elastic_runs": len(report["elastic_runs"]), "error_youngs": e["youngs_modulus"],
        "error_poisson": e["poisson_ratio"], "error_ucs": e["ucs"], "error_tensile": e["tensile_strength"],
        "converged": report["converged"], "given_up": " ".join(report["given_up"]),
        "declared_before_first_round": declared,
        "nu_reach": "%.3f-%.3f" % (reach["poisson_min"], reach["poisson_max"]),
        "ratio_reach": "%.1f-%.1f" % (reach["strength_ratio_min"], reach["strength_ratio_max"]),
        "target_ratio": report["target"]["ucs_pa"] / report["target"]["tensile_strength_pa"],
        "transfer_ucs": report["transfer_error"]["ucs"], "transfer_tensile": report["transfer_error"]["tensile_strength"],
        "first_corrected_ucs": report["transfer_error"]["first_prediction_corrected"]["ucs"],
        "first_corrected_tensile": report["transfer_error"]["first_prediction_corrected"]["tensile_strength"],
        "seconds": report["wall_seconds"], "exit_status": report["exit_status"],
    }


MARKDOWN = []  # every table printed, for the page next to this script


def emit(line=""):
    print(line)
    MARKDOWN.append(line)


def print_table(title, rows, twin):
    emit()
    emit("## " + title)
    emit()
    emit("| case | model | rounds (best) | elastic runs | E | nu | UCS | sigma_t | %s | wall |" %
          ("met in <= 3 rounds" if twin else "outcome"))
    emit("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if twin:
            outcome = "yes" if r["converged"] and r["best_round"] <= MAX_ROUNDS and met_row(r) else "**no**"
        elif r["converged"] and not r["given_up"]:
            outcome = "converged"
        elif r["declared_before_first_round"]:
            outcome = "out of reach, declared before round 1 (given up: %s; nu %s, ratio %s vs %.1f)" % (
                r["given_up"], r["nu_reach"], r["ratio_reach"], r["target_ratio"])
        else:
            outcome = "**not converged** (given up: %s)" % (r["given_up"] or "-")
        if r.get("failed_rounds"):
            outcome += "; %d round(s) failed (a test diverged: see the report)" % r["failed_rounds"]
        emit("| %s | %s | %d (%d) | %d | %+.2f %% | %+.2f %% | %+.2f %% | %+.2f %% | %s | %.0f s |" % (
            r["case"], r["model"], r["rounds"], r["best_round"], r["elastic_runs"], 100 * r["error_youngs"],
            100 * r["error_poisson"], 100 * r["error_ucs"], 100 * r["error_tensile"], outcome, r["seconds"]))


def met_row(r):
    return (abs(r["error_youngs"]) <= TOLERANCES["youngs_modulus"] and abs(r["error_poisson"]) <=
            TOLERANCES["poisson_ratio"] and abs(r["error_ucs"]) <= TOLERANCES["ucs"] and
            abs(r["error_tensile"]) <= TOLERANCES["tensile_strength"])


def write_rounds(path, reports):
    """Every target's errors against the strength round, one gnuplot block per target."""
    with open(path, "w") as f:
        f.write("# case,round,error_youngs,error_poisson,error_ucs,error_tensile\n")
        for label, report in reports:
            f.write("# %s\n" % label)
            for v in report["verification"]:
                if v.get("failed"):
                    continue  # measured nothing
                e = v["relative_errors"]
                f.write("%d,%g,%g,%g,%g,%s\n" % (v["round"], e["youngs_modulus"], e["poisson_ratio"], e["ucs"],
                                                  e["tensile_strength"], label))
            f.write("\n\n")


def plot_rounds(path_csv, path_png, count):
    if not shutil.which("gnuplot") or count == 0:
        return False
    panels = [(2, "E", TOLERANCES["youngs_modulus"]), (3, "nu", TOLERANCES["poisson_ratio"]),
              (4, "UCS", TOLERANCES["ucs"]), (5, "sigma_t", TOLERANCES["tensile_strength"])]
    script = ["set terminal pngcairo size 1400,1000", "set output '%s'" % path_png, "set datafile separator ','",
              "set multiplot layout 2,2 title 'calibrate-to-material: error against the strength round, every target'",
              "set grid", "set xtics 1", "set xlabel 'strength round'", "unset key"]
    for column, name, tol in panels:
        script += ["set ylabel '%s error [%%]'" % name, "set yrange [-40:40]",
                   "plot for [i=0:%d] '%s' index i using 1:(100*$%d) with linespoints lw 1.5 pt 7 ps 0.6, "
                   "%g with lines dt 2 lc rgb 'black', %g with lines dt 2 lc rgb 'black'" % (
                       count - 1, path_csv, column, 100 * tol, -100 * tol)]
    script.append("unset multiplot")
    return run(["gnuplot", "-e", "; ".join(script)]).returncode == 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/calibration")
    parser.add_argument("--twins", type=int, default=16, help="2D twin targets, rigid and DDEM")
    parser.add_argument("--ddem-twins", type=int, default=6, help="of the 2D twins, DDEM ones")
    parser.add_argument("--first-twin", type=int, default=1,
                        help="run the 2D twins from this one on (the earlier ones are drawn, not run)")
    parser.add_argument("--pick", default="",
                        help="comma-separated 2D twin numbers to run (the others are drawn, not run)")
    parser.add_argument("--twins-3d", type=int, default=0)
    parser.add_argument("--count-3d", type=int, default=20000)
    parser.add_argument("--seed", type=int, default=1, help="of the hidden parameters")
    parser.add_argument("--only", default="maps,twins,published",
                        help="comma-separated: maps, twins, published, 3d, 3d_low")
    parser.add_argument("--markdown", help="the page of tables to write (default OUT/calibration_bench.md)")
    parser.add_argument("--reuse-shipped-maps", action="store_true",
                        help="the master maps are data/maps (no maps-built case)")
    parser.add_argument("--anchor-levels", type=int, choices=(2, 3), default=2,
                        help="transfer anchors of the master maps (calibrate-to-material --anchor-levels): the "
                             "maps built with them, or the shipped ones completed to them")
    args = parser.parse_args()
    cases = set(c.strip() for c in args.only.split(","))
    unknown = cases - {"maps", "twins", "published", "3d", "3d_low"}
    if unknown:
        parser.error("--only: unknown %s" % ", ".join(sorted(unknown)))
    if args.twins_3d > 0:
        cases.add("3d")
    if not 0 <= args.ddem_twins <= args.twins:
        parser.error("--ddem-twins must be in [0, --twins]")
    if not 1 <= args.first_twin <= max(1, args.twins):
        parser.error("--first-twin must be in [1, --twins]")
    try:
        picked = set(int(v) for v in args.pick.split(",") if v.strip())
    except ValueError:
        parser.error("--pick: comma-separated twin numbers, e.g. 4,9")
    if any(not 1 <= v <= args.twins for v in picked):
        parser.error("--pick: twin numbers must be in [1, --twins]")
    build = os.path.abspath(args.build)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    master = os.path.join(out, "maps_master")
    materials = os.path.join(ROOT, "data", "materials")
    rows, reports = [], []

    # 1. Maps built (timed), or the shipped ones.
    if "maps" in cases and not args.reuse_shipped_maps:
        shutil.rmtree(master, ignore_errors=True)
        os.makedirs(master)
        built = []
        for label, material in (("2D Labra rock, maps built (rigid)", "labra2012_rock.toml"),
                                ("2D nu 0.27 rock, maps built (DDEM)", "high_poisson_2d.toml")):
            r = calibrate(build, os.path.join(materials, material), os.path.join(out, "maps_built"),
                          material.split(".")[0], master, ["--anchor-levels", str(args.anchor_levels)])
            built.append(row_of(label, r))
            reports.append((label, r))
            print("%s: %.0f s in all, of which maps %.0f s" % (label, r["wall_seconds"], r["maps"]["sweep_wall_time_s"]))
        strip_to_anchors(master)
        print_table("Calibrations that build their maps (sweep and transfer anchors)", built, False)
        rows += built
    elif not os.path.isdir(master) or args.reuse_shipped_maps:
        shutil.rmtree(master, ignore_errors=True)
        shutil.copytree(os.path.join(ROOT, "data", "maps"), master)
        strip_to_anchors(master)
        if args.anchor_levels > 2:
            # Completed by one round of each bundled rock (the anchors they lack measured first),
            # whose own runs are then stripped again.
            for model, material in (("rigid", "labra2012_rock.toml"), ("ddem", "high_poisson_2d.toml")):
                r = calibrate(build, os.path.join(materials, material), os.path.join(out, "maps_completed"), model,
                              master, ["--model", model, "--rounds", "1", "--anchor-levels", str(args.anchor_levels)])
                print("master maps (%s) completed to anchor levels %d: %.0f s of anchors" % (
                    model, args.anchor_levels, r["maps"]["sweep_wall_time_s"]), flush=True)
            strip_to_anchors(master)

    # The calibrator's own specimens, as written by a calibration (deterministic generation).
    reference = os.path.join(out, "reference")
    packings = [os.path.join(reference, "reference_ucs.packing"), os.path.join(reference, "reference_bts.packing")]
    if ("twins" in cases or "published" in cases) and not all(os.path.exists(p) for p in packings):
        r = calibrate(build, os.path.join(materials, "labra2012_rock.toml"), reference, "reference",
                      fresh_maps(master, os.path.join(out, "maps_reference")))
        rows.append(row_of("2D Labra rock (Labra 2012, Table 4.7), stored maps", r))
        reports.append(("2D Labra rock, stored maps", r))

    twin_rows = []
    if "twins" in cases:
        rng = random.Random(args.seed)
        bound = deformable_bound(master, 2)
        if args.ddem_twins > 0 and bound is None:
            raise RuntimeError("no 2D DDEM maps in %s: run with the 'maps' case first" % master)
        for i in range(args.twins):
            deformable = i >= args.twins - args.ddem_twins
            hidden = draw_hidden(rng, deformable, bound, 2)
            if i + 1 < args.first_twin or (picked and i + 1 not in picked):
                continue  # drawn, so that every twin keeps its hidden parameters
            d = os.path.join(out, "twin_%02d" % (i + 1))
            target = forward(build, packings, hidden, os.path.join(d, "forward"))
            label = "twin %d (%s kt/kn %.2f%s, Rt/Rn %.1f)" % (
                i + 1, "DDEM" if deformable else "rigid", hidden["kt_over_kn"],
                ", kn/(Ep l) %.3f" % hidden["kn_over_ep_l"] if deformable else "", hidden["rt_over_rn"])
            material = os.path.join(d, "target.toml")
            write_target(material, label, target, hidden["density"])
            r = calibrate(build, material, d, "twin", fresh_maps(master, os.path.join(d, "maps")))
            if sha(os.path.join(d, "twin_ucs.packing")) != sha(packings[0]):
                raise RuntimeError("twin %d: the calibrator's specimen differs from the forward runs'" % (i + 1))
            row = row_of(label, r)
            row.update({"hidden": hidden, "target": target,
                        "found_kt_over_kn": parameter(r, "tangential_stiffness_n_per_m") /
                                            parameter(r, "normal_stiffness_n_per_m")})
            twin_rows.append(row)
            reports.append((label, r))
            print("  %s: %d rounds, best %d, E %+.2f%% nu %+.2f%% UCS %+.2f%% st %+.2f%%, %.0f s" % (
                label, row["rounds"], row["best_round"], 100 * row["error_youngs"], 100 * row["error_poisson"],
                100 * row["error_ucs"], 100 * row["error_tensile"], row["seconds"]), flush=True)
        print_table("Twin experiments (2D, default 5,064-disc specimen)", twin_rows, True)
        ok = sum(1 for r in twin_rows if r["converged"] and r["best_round"] <= MAX_ROUNDS and met_row(r))
        emit()
        emit("Twins met within %d rounds: %d of %d; strength rounds in all: %d; median wall time %.0f s." % (
            MAX_ROUNDS, ok, len(twin_rows), sum(r["rounds"] for r in twin_rows),
            statistics.median(r["seconds"] for r in twin_rows)))
        rows += twin_rows

    published_rows = []
    if "published" in cases:
        files = sorted(glob.glob(os.path.join(materials, "published", "*.toml"))) + \
            [os.path.join(materials, "granitic_gneiss_1.toml")]
        for path in files:
            name = os.path.basename(path).split(".")[0]
            d = os.path.join(out, "published", name)
            r = calibrate(build, path, d, name, fresh_maps(master, os.path.join(d, "maps")))
            row = row_of(r["target"]["name"], r)
            published_rows.append(row)
            reports.append((name, r))
            print("  %s: %s, %d rounds, given up '%s', %.0f s" % (name, "converged" if r["converged"] else "not converged",
                                                                  row["rounds"], row["given_up"], row["seconds"]),
                  flush=True)
        print_table("Published rocks (2D)", published_rows, False)
        decided = sum(1 for r in published_rows if (r["converged"] and not r["given_up"]) or
                      r["declared_before_first_round"])
        emit()
        emit("Published rocks converged or declared out of reach before round 1: %d of %d; median wall time %.0f s." % (
            decided, len(published_rows), statistics.median(r["seconds"] for r in published_rows)))
        rows += published_rows

    if "3d" in cases and args.twins_3d > 0:
        master3 = os.path.join(out, "maps_master_3d")
        if not os.path.isdir(master3):
            os.makedirs(master3)
            r = calibrate(build, os.path.join(materials, "labra2012_rock.toml"), os.path.join(out, "maps_built_3d"),
                          "labra_3d", master3, ["--dimension", "3", "--count", str(args.count_3d)])
            reports.append(("3D Labra rock, maps built", r))
            strip_to_anchors(master3)
        ref3 = os.path.join(out, "maps_built_3d")
        rows3 = []
        with open(os.path.join(ref3, "labra_3d_report.json")) as f:  # built now or by an earlier run
            labra3 = json.load(f)
        labra3.setdefault("wall_seconds", labra3["wall_time_s"])
        labra3.setdefault("exit_status", 0 if labra3["converged"] and not labra3["given_up"] else 4)
        rows3.append(row_of("3D Labra rock, maps built", labra3))
        packings3 = [os.path.join(ref3, "labra_3d_ucs.packing"), os.path.join(ref3, "labra_3d_bts.packing")]
        with open(os.path.join(ref3, "labra_3d_report.json")) as f:
            mean_radius = json.load(f)["specimens"]["ucs"]["mean_radius_m"]
        rng = random.Random(args.seed + 1000)
        for i in range(args.twins_3d):
            hidden = draw_hidden(rng, False, None, 3, mean_radius)
            hidden["mean_radius"] = mean_radius
            d = os.path.join(out, "twin3d_%02d" % (i + 1))
            target = forward(build, packings3, hidden, os.path.join(d, "forward"))
            label = "3D twin %d (rigid kt/kn %.2f, Rt/Rn %.1f)" % (i + 1, hidden["kt_over_kn"], hidden["rt_over_rn"])
            material = os.path.join(d, "target.toml")
            write_target(material, label, target, hidden["density"])
            r = calibrate(build, material, d, "twin", fresh_maps(master3, os.path.join(d, "maps")),
                          ["--dimension", "3", "--count", str(args.count_3d)])
            row = row_of(label, r)
            rows3.append(row)
            reports.append((label, r))
        print_table("Twin experiments (3D, %d spheres)" % args.count_3d, rows3, True)
        rows += rows3

    if "3d_low" in cases:
        ref3 = os.path.join(out, "maps_built_3d")
        report3 = os.path.join(ref3, "labra_3d_report.json")
        if not os.path.exists(report3):
            parser.error("3d_low: no 3D specimens in %s; run --only 3d --twins-3d 1 --count-3d %d into this --out first"
                         % (ref3, args.count_3d))
        with open(report3) as f:
            mean_radius = json.load(f)["specimens"]["ucs"]["mean_radius_m"]
        packings3 = [os.path.join(ref3, "labra_3d_ucs.packing"), os.path.join(ref3, "labra_3d_bts.packing")]
        box = ["--sweep-stiffness-ratio", "0.04", "0.9"]
        master_low = os.path.join(out, "maps_master_3d_low")
        shutil.rmtree(master_low, ignore_errors=True)
        rows_low = []
        # kn and Rn as the 2D draws' scales on the spheres' mean radius (draw_hidden).
        for i, (kn_2d, rn_2d, s, x) in enumerate(((2e10, 8e3, 0.06, 4.0), (4e10, 1.5e4, 0.1, 1.0))):
            hidden = {"dimension": 3, "density": 2650.0, "kn": kn_2d * mean_radius,
                      "rn": rn_2d * 2.5 * mean_radius ** 2 / MEAN_RADIUS_2D, "kt_over_kn": s, "rt_over_rn": x,
                      "mean_radius": mean_radius}
            d = os.path.join(out, "twin3d_low_%02d" % (i + 1))
            target = forward(build, packings3, hidden, os.path.join(d, "forward"))
            label = "3D twin below the box %d (rigid kt/kn %.2f, Rt/Rn %.1f)" % (i + 1, s, x)
            material = os.path.join(d, "target.toml")
            write_target(material, label, target, hidden["density"])
            maps = os.path.join(d, "maps")
            if i == 0:
                shutil.rmtree(maps, ignore_errors=True)
                os.makedirs(maps)
            else:
                fresh_maps(master_low, maps)
            r = calibrate(build, material, d, "twin", maps, ["--dimension", "3", "--count", str(args.count_3d)] + box)
            if i == 0:
                shutil.copytree(maps, master_low)
                strip_to_anchors(master_low)
            rows_low.append(row_of(label + (", maps built" if i == 0 else ""), r))
            reports.append((label, r))
        print_table("Twin experiments below the maps' default box of kt/kn (3D, %d spheres, --sweep-stiffness-ratio "
                    "0.04 0.9)" % args.count_3d, rows_low, True)
        rows += rows_low

    fields = ["case", "model", "rounds", "best_round", "failed_rounds", "elastic_runs", "error_youngs", "error_poisson", "error_ucs",
              "error_tensile", "converged", "given_up", "declared_before_first_round", "nu_reach", "ratio_reach",
              "target_ratio", "transfer_ucs", "transfer_tensile", "first_corrected_ucs", "first_corrected_tensile",
              "seconds", "exit_status"]
    with open(os.path.join(out, "calibrations.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    rounds_csv = os.path.join(out, "error_vs_round.csv")
    write_rounds(rounds_csv, reports)
    png = os.path.join(out, "error_vs_round.png")
    if plot_rounds(rounds_csv, png, len(reports)):
        print("plot:", png)
    print("tables:", os.path.join(out, "calibrations.csv"), rounds_csv)
    page = args.markdown or os.path.join(out, "calibration_bench.md")
    with open(page + ".tmp", "w") as f:
        f.write("# calibrate-to-material benchmark\n\nReproduce: `python3 tools/bench/calibration_bench.py %s`"
                " (2 cores; `OMP_WAIT_POLICY=passive`). Tolerances: E, nu 1.5 %%, UCS 2 %%, sigma_t 5 %%; wall"
                " time of the calibration alone (the twins' forward runs excluded). Every round of every target:"
                " `error_vs_round.csv` and `.png` in the output folder.\n" % " ".join(sys.argv[1:]))
        f.write("\n".join(MARKDOWN) + "\n")
    os.replace(page + ".tmp", page)
    print("page:", page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
