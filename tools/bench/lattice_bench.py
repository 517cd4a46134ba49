#!/usr/bin/env python3
"""Benchmark of the six-spring lattice model (run-test, model = "lattice"): E and nu of the
linear portion of a UCS against the input, for nu from 0 to 0.45 (plane strain), of a biaxial
test at sigma_3 10 MPa, the moduli
of an orthotropic material along both axes and at 45 degrees, and the speed against the
bonded rigid-particle law on the same packing. Prints the tables and writes them to
OUT/lattice_bench.md, with lattice_bench.csv.

  tools/bench/lattice_bench.py [--build build] [--out bench-out/lattice] [--count 5000]
        [--speed-count 50000] [--repeats 3] [--ortho-rate 1e-5]

The specimen: a 50 x 50 mm square of --count discs (generate-packing defaults, seed 1), the
default specimen of the calibrator and of the example scenes. The elastic runs load to a
strain of 1e-3 with unbreakable triangles. Speed: node-steps per second of the lattice UCS
against particle-steps per second of the bonded UCS (Labra's parameters, rigid particles) on
a --speed-count packing, each to a platen strain of 2e-4 (the set-up, with its stability
analysis, included), the median of --repeats runs of each, run alternately.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
E = 40e9
MARKDOWN = []


def emit(line=""):
    print(line)
    MARKDOWN.append(line)


def generate(build, out, name, count, domain):
    path = os.path.join(out, name + ".packing")
    if os.path.exists(path):
        return path
    result = subprocess.run([os.path.join(build, "tools", "generate-packing"), "--domain", domain, "--count", str(count),
                             "--output", out, "--name", name, "--no-pictures", "--quiet"], capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit("generate-packing failed:\n" + result.stdout + result.stderr)
    return path


def run_test(build, out, name, packing, material_lines, test_lines):
    scene = os.path.join(out, name + ".toml")
    with open(scene, "w") as f:
        f.write('[specimen]\npacking = "%s"\n\n[material]\n%s\n[test]\n%s\n[output]\nname = "%s"\npictures = false\n'
                'snapshots = false\n' % (packing, "\n".join(material_lines), "\n".join(test_lines), name))
    result = subprocess.run([os.path.join(build, "tools", "run-test"), scene, "--output", out, "--quiet"],
                            capture_output=True, text=True)
    if result.returncode not in (0, 4):
        sys.exit("run-test %s failed (%d):\n%s%s" % (name, result.returncode, result.stdout[-2000:], result.stderr))
    with open(os.path.join(out, name + "_summary.json")) as f:
        return json.load(f)["result"]


def off_axis_modulus(e1, e2, nu12, g12, angle_deg):
    """1/E along a direction at angle_deg from material axis 1 (plane stress)."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return 1.0 / (c ** 4 / e1 + s ** 4 / e2 + (1.0 / g12 - 2.0 * nu12 / e1) * s * s * c * c)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/lattice")
    parser.add_argument("--count", type=int, default=5000)
    parser.add_argument("--speed-count", type=int, default=50000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--ortho-rate", type=float, default=1e-5,
                        help="loading-rate group of the orthotropic runs (off-axis, the specimen shears as it shortens)")
    parser.add_argument("--markdown", help="the page to write (default OUT/lattice_bench.md)")
    args = parser.parse_args()
    build, out = os.path.abspath(args.build), os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    packing = generate(build, out, "square", args.count, "rectangle 0 0 0.05 0.05")
    strong = ["tensile_strength = 1e15", "cohesion = 1e15", "density = 2650"]
    elastic_test = ['kind = "ucs"', "strain_limit = 1e-3"]
    rows = []

    emit("# Six-spring lattice benchmark")
    emit()
    emit("Reproduce: `python3 tools/bench/lattice_bench.py` (`--count`, `--speed-count`, `--repeats`).")
    emit("Specimen: a 50 x 50 mm square of %d discs (generate-packing, seed 1); the UCS of `run-test` with" % args.count)
    emit("`model = \"lattice\"`, unbreakable triangles, to a strain of 1e-3; E, nu of the linear portion (ISRM).")
    emit()
    emit("## Isotropic, plane strain (E %.0f GPa)" % (E / 1e9))
    emit()
    emit("| nu input | E measured | E error | nu measured | nu error |")
    emit("|---|---|---|---|---|")
    for nu in (0.0, 0.1, 0.2, 0.25, 0.3, 0.4, 0.45):
        r = run_test(build, out, "iso_%g" % nu, packing,
                     ['model = "lattice"', "youngs_modulus = %r" % E, "poisson_ratio = %r" % nu] + strong, elastic_test)
        lin = r["linear_elastic"]
        e_err = lin["youngs_modulus_pa"] / E - 1.0
        nu_err = lin["poisson_ratio"] - nu
        rows.append({"case": "isotropic nu %g" % nu, "expected_youngs_pa": E, "youngs_pa": lin["youngs_modulus_pa"],
                     "expected_poisson": nu, "poisson": lin["poisson_ratio"]})
        emit("| %.2f | %.3f GPa | %+.2f %% | %.4f | %+.4f (%s) |" % (
            nu, lin["youngs_modulus_pa"] / 1e9, 100 * e_err, lin["poisson_ratio"], nu_err,
            "%+.2f %%" % (100 * nu_err / nu) if nu > 0 else "absolute"))

    emit()
    emit("## Biaxial, plane strain (E %.0f GPa, sigma_3 10 MPa)" % (E / 1e9))
    emit()
    emit("sigma_3 on the side surface nodes, then the platens; E, nu of the linear portion of sigma_1 against the")
    emit("axial strain (the deviator rising at constant sigma_3).")
    emit()
    emit("| nu input | E measured | E error | nu measured | nu error |")
    emit("|---|---|---|---|---|")
    for nu in (0.1, 0.25, 0.4):
        r = run_test(build, out, "biax_%g" % nu, packing,
                     ['model = "lattice"', "youngs_modulus = %r" % E, "poisson_ratio = %r" % nu] + strong,
                     ['kind = "biaxial"', "confining_stress = 10e6", "strain_limit = 1e-3"])
        lin = r["linear_elastic"]
        rows.append({"case": "biaxial nu %g" % nu, "expected_youngs_pa": E, "youngs_pa": lin["youngs_modulus_pa"],
                     "expected_poisson": nu, "poisson": lin["poisson_ratio"]})
        emit("| %.2f | %.3f GPa | %+.2f %% | %.4f | %+.4f (%+.2f %%) |" % (
            nu, lin["youngs_modulus_pa"] / 1e9, 100 * (lin["youngs_modulus_pa"] / E - 1.0), lin["poisson_ratio"],
            lin["poisson_ratio"] - nu, 100 * (lin["poisson_ratio"] - nu) / nu))

    e1, e2, nu12, g12 = 60e9, 20e9, 0.25, 12e9
    emit()
    emit("## Orthotropic, plane stress (E1 60 GPa, E2 20 GPa, nu12 0.25, G12 12 GPa)")
    emit()
    emit("Loaded along y; axis 1 at the given angle from x, so the load is at 90 degrees minus it from axis 1.")
    emit("Rate group %g: off its axes the specimen shears as it shortens, a slower mode than the lateral" % args.ortho_rate)
    emit("expansion (at the default 5e-5 the 45-degree modulus came out 1.45 % low).")
    emit("Expected: 1/E = cos^4/E1 + sin^4/E2 + (1/G12 - 2 nu12/E1) sin^2 cos^2 (in-plane E of the linear portion).")
    emit()
    emit("| axis 1 angle | expected E | measured E | error |")
    emit("|---|---|---|---|")
    for angle in (90.0, 0.0, 45.0):
        r = run_test(build, out, "ortho_%g" % angle, packing,
                     ['model = "lattice"', 'plane_model = "plane_stress"', "youngs_modulus_1 = %r" % e1,
                      "youngs_modulus_2 = %r" % e2, "poisson_ratio_12 = %r" % nu12, "shear_modulus_12 = %r" % g12,
                      "axis_angle = %r" % angle] + strong, elastic_test + ["loading_rate_group = %r" % args.ortho_rate])
        expected = off_axis_modulus(e1, e2, nu12, g12, 90.0 - angle)
        measured = r["linear_elastic"]["youngs_modulus_in_plane_pa"]
        rows.append({"case": "orthotropic axis %g" % angle, "expected_youngs_pa": expected, "youngs_pa": measured,
                     "expected_poisson": "", "poisson": ""})
        emit("| %.0f deg | %.3f GPa | %.3f GPa | %+.2f %% |" % (angle, expected / 1e9, measured / 1e9,
                                                             100 * (measured / expected - 1.0)))

    # Speed, side by side on one packing.
    big = generate(build, out, "square_speed", args.speed_count, "rectangle 0 0 0.15 0.15")
    speed_test = ['kind = "ucs"', "strain_limit = 2e-4"]
    lattice_rates, bonded_rates = [], []
    for k in range(args.repeats):
        lat = run_test(build, out, "speed_lattice", big,
                       ['model = "lattice"', "youngs_modulus = 18.7e9", "poisson_ratio = 0.2"] + strong, speed_test)
        bond = run_test(build, out, "speed_bonded", big,
                        ["normal_stiffness = 14.392e9", "tangential_stiffness = 2.868e9", "bond_tensile_strength = 1e30",
                         "bond_shear_strength = 1e30", "friction_coefficient = 0.8", "density = 2580"], speed_test)
        for r, rates in ((lat, lattice_rates), (bond, bonded_rates)):
            rates.append(r["loading"]["steps"] * r["specimen"]["particles"] / r["wall_time_s"])
    lm, bm = statistics.median(lattice_rates), statistics.median(bonded_rates)
    emit()
    emit("## Speed (%d discs, UCS to a strain of 2e-4, set-up included, median of %d, one thread)" % (
        args.speed_count, args.repeats))
    emit()
    emit("| model | node- or particle-steps per second | ratio to bonded |")
    emit("|---|---|---|")
    emit("| bonded, rigid particles | %.3g | 1 |" % bm)
    emit("| six-spring lattice | %.3g | %.2f |" % (lm, lm / bm))

    with open(os.path.join(out, "lattice_bench.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["case", "expected_youngs_pa", "youngs_pa", "expected_poisson", "poisson"])
        w.writeheader()
        w.writerows(rows)
    with open(args.markdown or os.path.join(out, "lattice_bench.md"), "w") as f:
        f.write("\n".join(MARKDOWN) + "\n")


if __name__ == "__main__":
    main()
