#!/usr/bin/env python3
"""Benchmark of the virtual laboratory, run-test: prints a table, writes CSV and a plot.

  tools/bench/lab_bench.py [--build build] [--out bench-out/lab] [--runs 3] [--threads 1]
                           [--quick] [--skip-timing] [--skip-error]

1. Wall time, median of --runs runs (the packing is generated once, outside the timing):
   - 2D UCS on 10,000 discs (50 x 50 mm), Labra's 2D parameters with Rn, Rt scaled to the
     packing's mean radius (2D strength ~ Rn / r_mean), through the peak to 50 %;
   - 2D Brazilian test on 5,000 discs (disc of diameter 50 mm) to 50 % post-peak;
   - 3D UCS on 20,000 spheres (cylinder 50 x 50 mm), Labra's 3D parameters (Table 4.11,
     improved column), to 50 % post-peak.
   Target: the 2D UCS on 10,000 discs in under 2 minutes (of CPU).
   The rows go to lab_timing.csv and, as the table of tools/bench/lab_bench.md, to lab_bench.md.
2. Error of E against run time: 2D UCS without breakage (elastic, to strain 1e-3) on
   1,000-10,000 discs at loading-rate groups 2e-4 .. 1.25e-5; the error of E' is taken against
   the largest specimen at the slowest rate (the best estimate this study has) and against the
   uniform-strain (Voigt) estimate of each packing's interior. CSV (lab_error.csv) and a plot
   (lab_error.png, gnuplot) next to it.
Medians of several runs because the machine is shared; every figure comes from this run.
"""
import argparse
import csv
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

# Labra, Onate & Rojek (2012) Table 4.8 (2D) and Table 4.11 improved column (3D).
LABRA_2D = dict(kn=14.392e9, kt=2.868e9, rn=4962.3, rt=49623.0, mu=0.8, rho=2580.0)
LABRA_2D_RADIUS = 0.154e-3  # r_rms of his 30,480-disc 50 x 50 mm specimen at e = 9.2 %
LABRA_3D = dict(kn=27.889e6, kt=5.3681e6, rn=91.971, rt=643.80, mu=0.8, rho=2580.0)


def run(command):
    """Runs a command; returns (status, wall seconds, CPU seconds of the child, output). The CPU
    time (user + system) is the figure to trust on a shared machine."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.time()
    result = subprocess.run(command, capture_output=True, text=True)
    seconds = time.time() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return result.returncode, seconds, cpu, result.stdout + result.stderr


def generate(build, out, domain, count, seed, name):
    path = os.path.join(out, name + ".packing")
    report = os.path.join(out, name + "_report.json")
    if not os.path.exists(path):
        code, _, _, text = run([os.path.join(build, "tools", "generate-packing"), "--domain", domain,
                             "--count", str(count), "--seed", str(seed), "--output", out, "--name",
                             name, "--quiet", "--no-pictures"])
        if code != 0:
            raise RuntimeError("generate-packing failed:\n" + text)
    with open(report) as f:
        return path, json.load(f)["metrics"]


def scene(path, packing, material, test_lines, name):
    m = material
    lines = ["[specimen]", 'packing = "%s"' % os.path.abspath(packing), "scale_density = true",
             "[material]", "normal_stiffness = %.10g" % m["kn"], "tangential_stiffness = %.10g" % m["kt"]]
    if m.get("rn") is not None:
        lines += ["bond_tensile_strength = %.10g" % m["rn"], "bond_shear_strength = %.10g" % m["rt"]]
    lines += ["friction_coefficient = %.10g" % m["mu"], "density = %.10g" % m["rho"], "[test]"]
    lines += test_lines + ["[output]", 'name = "%s"' % name, "pictures = false", "snapshots = false"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def run_test(build, scene_path, out, threads, allow_no_peak=False):
    code, seconds, cpu, text = run([os.path.join(build, "tools", "run-test"), scene_path, "--output",
                                    out, "--quiet", "--no-quasi-static-check", "--threads", str(threads)])
    if code != 0 and not (allow_no_peak and code == 4):
        raise RuntimeError("run-test failed (%d):\n%s" % (code, text))
    name = os.path.splitext(os.path.basename(scene_path))[0].replace("scene_", "")
    with open(os.path.join(out, name + "_summary.json")) as f:
        return seconds, cpu, json.load(f)["result"]


def timing(args, out):
    cases = []
    # 2D UCS, 10,000 discs.
    packing, metrics = generate(args.build, out, "rectangle 0 0 0.05 0.05", 10000, 1, "ucs2d_10k")
    scale = metrics["mean_radius_m"] / LABRA_2D_RADIUS
    m2 = dict(LABRA_2D, rn=LABRA_2D["rn"] * scale, rt=LABRA_2D["rt"] * scale)
    cases.append(("2D UCS", packing, metrics, m2, ['kind = "ucs"'], "ucs2d", 120.0))
    # 2D BTS, 5,000 discs on a 50 mm disc.
    packing, metrics = generate(args.build, out, "disc 0 0 0.025", 5000, 1, "bts2d_5k")
    scale = metrics["mean_radius_m"] / LABRA_2D_RADIUS
    mb = dict(LABRA_2D, rn=LABRA_2D["rn"] * scale, rt=LABRA_2D["rt"] * scale)
    cases.append(("2D BTS", packing, metrics, mb, ['kind = "brazilian"'], "bts2d", None))
    # 3D UCS, 20,000 spheres.
    if not args.quick:
        packing, metrics = generate(args.build, out, "cylinder 0 0 0.025 0 0.05", 20000, 1, "ucs3d_20k")
        cases.append(("3D UCS", packing, metrics, LABRA_3D, ['kind = "ucs"'], "ucs3d", None))
    rows = []
    for label, packing, metrics, material, lines, name, target in cases:
        times, cpus, results = [], [], []
        for k in range(args.runs):
            path = os.path.join(out, "scene_%s.toml" % name)
            scene(path, packing, material, lines, name)
            seconds, cpu, result = run_test(args.build, path, out, args.threads)
            times.append(seconds)
            cpus.append(cpu)
            results.append(result)
            print("  %s run %d: %.1f s wall, %.1f s CPU, %d steps" % (
                label, k + 1, seconds, cpu, result["loading"]["steps"]), flush=True)
        r = results[0]
        rows.append(dict(case=label, particles=metrics["particle_count"],
                         median_s=statistics.median(times), min_s=min(times), max_s=max(times),
                         median_cpu_s=statistics.median(cpus),
                         steps=r["loading"]["steps"], pauses=r["loading"].get("pauses", 0),
                         peak_mpa=r["peak_stress_pa"] / 1e6,
                         youngs_gpa=r["elastic"]["youngs_modulus_pa"] / 1e9 if r["elastic"]["measured"] else float("nan"),
                         poisson=r["elastic"]["poisson_ratio"] if r["elastic"]["measured"] else float("nan"),
                         target_s=target))
    print("\nWall time (median of %d, --threads %d)" % (args.runs, args.threads))
    print("%-8s %9s %9s %9s %9s %9s %8s %7s %10s %9s %7s  %s" % (
        "case", "particles", "median s", "min s", "max s", "CPU s", "steps", "pauses", "peak MPa", "E GPa",
        "nu", "target (CPU)"))
    for r in rows:
        target = "" if r["target_s"] is None else ("%.0f s: %s" % (
            r["target_s"], "met" if r["median_cpu_s"] <= r["target_s"] else "MISSED"))
        print("%-8s %9d %9.1f %9.1f %9.1f %9.1f %8d %7d %10.2f %9.3f %7.4f  %s" % (
            r["case"], r["particles"], r["median_s"], r["min_s"], r["max_s"], r["median_cpu_s"], r["steps"], r["pauses"],
            r["peak_mpa"], r["youngs_gpa"], r["poisson"], target))
    with open(os.path.join(out, "lab_timing.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    path = os.path.join(out, "lab_bench.md")
    write_markdown(rows, path, args.runs, args.threads, " ".join(["python3", "tools/bench/lab_bench.py"] + sys.argv[1:]))
    print("table: " + path + " (the format of tools/bench/lab_bench.md)")


def markdown_table(rows, runs, threads):
    """The timing rows as printed by timing(), as the Markdown table of tools/bench/lab_bench.md:
    one line per case; the peak column is the UCS (the tensile strength 2F/(pi D t) for the
    Brazilian test), E and nu the secants over the default window (plane strain in 2D)."""
    def number(value, form):
        return "-" if value is None or (isinstance(value, float) and math.isnan(value)) else form % value

    lines = ["| case | particles | threads | wall s (median of %d; min-max) | CPU s (median) | steps | pauses "
             "| peak MPa (BTS: sigma_t) | E GPa | nu | target | met |" % runs,
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["target_s"] is None:
            target, met = "-", "-"
        else:
            target = "%.0f s CPU" % r["target_s"]
            met = "yes" if r["median_cpu_s"] <= r["target_s"] else "**missed** (x%.1f)" % (r["median_cpu_s"] / r["target_s"])
        lines.append("| %s | %s | %d | %.1f (%.1f-%.1f) | %.1f | %s | %s | %s | %s | %s | %s | %s |" % (
            r["case"], "{:,}".format(r["particles"]), threads, r["median_s"], r["min_s"], r["max_s"],
            r["median_cpu_s"], "{:,}".format(r["steps"]), r["pauses"], number(r["peak_mpa"], "%.4g"),
            number(r["youngs_gpa"], "%.4g"), number(r["poisson"], "%.3f"), target, met))
    return "\n".join(lines) + "\n"


def write_markdown(rows, path, runs, threads, command):
    """Writes the rows timing() prints as a Markdown page: the command, then markdown_table."""
    with open(path, "w") as f:
        f.write("# run-test benchmark\n\nReproduce: `%s`\n\n" % command)
        f.write(markdown_table(rows, runs, threads))


def voigt_in_plane(metrics, kn, kt):
    """E', nu' of the uniform-strain (Voigt) estimate over the whole packing (Madan (4.15)-(4.16)
    with C = N_c <|l|^2>/4 / V): an upper bound; the interior of a specimen is denser than
    its boundary layer, so the interior's C is a few per cent higher (lab_test.h)."""
    c = metrics["contact_count"] * metrics["mean_branch_length_squared_m2"] / 4.0 / metrics["domain_area_m2"]
    return 4.0 * c * kn * (kn + kt) / (3.0 * kn + kt), (kn - kt) / (3.0 * kn + kt)


def error_study(args, out):
    sizes = [1000, 2500, 5000] if args.quick else [1000, 2500, 5000, 10000]
    groups = [2e-4, 1e-4, 5e-5] if args.quick else [2e-4, 1e-4, 5e-5, 2.5e-5, 1.25e-5]
    rows = []
    for n in sizes:
        packing, metrics = generate(args.build, out, "rectangle 0 0 0.05 0.05", n, 1, "err_%d" % n)
        for g in groups:
            name = "err_%d_%g" % (n, g)
            path = os.path.join(out, "scene_%s.toml" % name)
            material = dict(LABRA_2D, rn=None, rt=None)
            scene(path, packing, material, ['kind = "ucs"', "strain_limit = 1e-3",
                                            "loading_rate_group = %g" % g], name)
            seconds, cpu, r = run_test(args.build, path, out, args.threads, allow_no_peak=True)
            e = r["elastic"]
            rows.append(dict(particles=metrics["particle_count"], rate_group=g, seconds=seconds, cpu_seconds=cpu,
                             steps=r["loading"]["steps"], youngs_in_plane_pa=e["youngs_modulus_in_plane_pa"],
                             poisson_in_plane=e["poisson_ratio_in_plane"], youngs_pa=e["youngs_modulus_pa"],
                             poisson=e["poisson_ratio"], coordination=metrics["coordination_number"],
                             voigt_youngs_in_plane_pa=voigt_in_plane(metrics, LABRA_2D["kn"], LABRA_2D["kt"])[0],
                             porosity=metrics["nominal_porosity"]))
            print("  N %6d group %8.3g: %6.1f s, E' %.4f GPa, nu' %.4f" % (
                n, g, seconds, e["youngs_modulus_in_plane_pa"] / 1e9, e["poisson_ratio_in_plane"]), flush=True)
    reference = [r for r in rows if r["particles"] == max(x["particles"] for x in rows)]
    reference = min(reference, key=lambda r: r["rate_group"])
    for r in rows:
        r["error_youngs"] = abs(r["youngs_in_plane_pa"] / reference["youngs_in_plane_pa"] - 1.0)
        r["error_poisson"] = abs(r["poisson_in_plane"] - reference["poisson_in_plane"])
    path = os.path.join(out, "lab_error.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print("\nError of E' against run time (reference: N %d at group %g, E' %.4f GPa, nu' %.4f)" % (
        reference["particles"], reference["rate_group"], reference["youngs_in_plane_pa"] / 1e9,
        reference["poisson_in_plane"]))
    print("%9s %10s %9s %9s %9s %10s %9s %11s %11s" % ("particles", "rate group", "wall s", "CPU s", "steps",
                                                     "E' GPa", "nu'", "|dE'|/E'", "E'/Voigt-1"))
    for r in rows:
        print("%9d %10.3g %9.1f %9.1f %9d %10.4f %9.4f %10.2f%% %10.2f%%" % (
            r["particles"], r["rate_group"], r["seconds"], r["cpu_seconds"], r["steps"],
            r["youngs_in_plane_pa"] / 1e9, r["poisson_in_plane"], 100 * r["error_youngs"],
            100 * (r["youngs_in_plane_pa"] / r["voigt_youngs_in_plane_pa"] - 1)))
    plot(rows, path, os.path.join(out, "lab_error.png"))


def plot(rows, csv_path, png_path):
    if not shutil.which("gnuplot"):
        print("gnuplot not found: no plot")
        return
    with tempfile.TemporaryDirectory() as tmp:
        sizes = sorted(set(r["particles"] for r in rows))
        commands = ["set terminal pngcairo size 900,600", "set output '%s'" % png_path,
                    "set logscale xy", "set xlabel 'CPU time of the test [s]'",
                    "set ylabel '|E - E_{ref}| / E_{ref}'", "set key outside right",
                    "set title 'run-test 2D UCS (elastic): error of E against run time'", "set grid"]
        parts = []
        for n in sizes:
            data = os.path.join(tmp, "n%d.dat" % n)
            with open(data, "w") as f:
                for r in sorted((r for r in rows if r["particles"] == n and r["error_youngs"] > 0),
                                key=lambda r: -r["rate_group"]):
                    f.write("%g %g %g\n" % (r["cpu_seconds"], r["error_youngs"], r["rate_group"]))
            parts.append("'%s' using 1:2 with linespoints title 'N = %d', '' using 1:2:(sprintf('%%g', $3)) "
                         "with labels offset 1,0.5 font ',7' notitle" % (data, n))
        commands.append("plot " + ", ".join(parts))
        script = os.path.join(tmp, "plot.gp")
        with open(script, "w") as f:
            f.write("\n".join(commands) + "\n")
        result = subprocess.run(["gnuplot", script], capture_output=True, text=True)
        if result.returncode != 0:
            print("gnuplot failed: " + result.stderr)
        else:
            print("plot: " + png_path)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/lab")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--quick", action="store_true", help="no 3D case, fewer sizes and rates")
    parser.add_argument("--skip-timing", action="store_true")
    parser.add_argument("--skip-error", action="store_true")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if not args.skip_timing:
        timing(args, args.out)
    if not args.skip_error:
        error_study(args, args.out)


if __name__ == "__main__":
    main()
