#!/usr/bin/env python3
"""The Yade export checked in Yade: prints a table and writes it to yade_export_bench.md.

  OMP_WAIT_POLICY=passive python3 tools/bench/yade_export_bench.py [--build build] [--out bench-out/yade_export]

For a 2D square (20 x 20 mm, 500 discs) and a 3D cylinder (10 x 10 mm, 1,500 spheres),
with one parameter set each (2D: the twin_01 set of the calibration benchmark; 3D: a set
written here), as a user would: generate-packing, export-specimen --to yade --parameters, then
  1. yade -x -n <script> --run at-rest --steps 1000: the largest bond force after step 1 and at
     the end, against kn x r_mean, and the bonds broken;
  2. yade -x -n <script> --run ucs --until-first-break: E by the script's linear portion
     (platen stress against platen strain, before the first broken bond, from 20 % of the
     largest stress), against run-test on the same packing and parameters (scale_density
     false, as the script): its linear_elastic.youngs_modulus_platen_pa, the same measurement,
     and its interior E (Bagi strain 4 mean radii inside), which no platen measurement gives.
The table goes to tools/bench/yade_export_bench.md with the Yade version and the machine.
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# 2D: twin_01 of the calibration benchmark (rigid, kt/kn 0.37, Rt/Rn 7.8); 3D: a set for
# r_mean ~ 0.4 mm (E ~ 2 GPa). Strengths only decide where the first bond breaks.
PARAMETERS = {
    2: dict(normal_stiffness=12721478916.752708, tangential_stiffness=4654458556.9943256,
            bond_tensile_strength=19335.218652621636, bond_shear_strength=100857.20620640897,
            friction_coefficient=0.8, density=2650),
    3: dict(normal_stiffness=2.0e6, tangential_stiffness=0.5e6, bond_tensile_strength=5.0,
            bond_shear_strength=50.0, friction_coefficient=0.5, density=2650),
}
CASES = [
    (2, "rectangle 0 0 0.02 0.02", 500),
    (3, "cylinder 0 0 0.005 0 0.01", 1500),
]


def run(command, **kwargs):
    started = time.time()
    done = subprocess.run(command, capture_output=True, text=True, **kwargs)
    if done.returncode != 0:
        sys.exit("failed: %s\n%s%s" % (" ".join(command), done.stdout, done.stderr))
    return done.stdout, time.time() - started


def material_table(p):
    return "[material]\n" + "".join("%s = %r\n" % (k, v) for k, v in p.items())


def exported_specimen(tools, out, dimension, domain, count, target):
    """Generates the packing p<D>d of the case, writes its parameter file and exports it with
    export-specimen --to target; returns the script's path."""
    name = "p%dd" % dimension
    run([os.path.join(tools, "generate-packing"), "--domain", domain, "--count", str(count), "--threads", "1",
         "--no-pictures", "--quiet", "--output", out, "--name", name])
    parameters = os.path.join(out, name + "_parameters.toml")
    with open(parameters, "w") as f:
        f.write(material_table(PARAMETERS[dimension]))
    script = os.path.join(out, "%s_%s.py" % (name, target))
    run([os.path.join(tools, "export-specimen"), os.path.join(out, name + ".packing"), "--to", target,
         "--parameters", parameters, "--output", script, "--quiet"])
    return script


def yade_json(script, arguments, out, path):
    _, seconds = run(["yade", "-x", "-n", script] + arguments + ["--json", path], cwd=out)
    with open(path) as f:
        return json.load(f), seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--out", default=os.path.join(ROOT, "bench-out", "yade_export"))
    args = parser.parse_args()
    tools = os.path.join(os.path.abspath(args.build), "tools")
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    version, _ = run(["yade", "--version"])
    version = [line for line in version.splitlines() if "Yade version" in line][0].split(":")[1].strip()
    rows = []
    for dimension, domain, count in CASES:
        name = "p%dd" % dimension
        script = exported_specimen(tools, out, dimension, domain, count, "yade")
        rest, _ = yade_json(script, ["--run", "at-rest", "--steps", "1000"], out,
                            os.path.join(out, name + "_yade_at_rest.json"))
        ucs, yade_seconds = yade_json(script, ["--run", "ucs", "--until-first-break",
                                               "--curve", os.path.join(out, name + "_yade_curve.csv")], out,
                                    os.path.join(out, name + "_yade_ucs.json"))
        scene = os.path.join(out, name + "_ucs.toml")
        with open(scene, "w") as f:
            f.write('[specimen]\npacking = "%s.packing"\nscale_density = false\n\n%s\n[test]\nkind = "ucs"\n\n'
                    '[output]\nname = "%s_run_test"\npictures = false\nsnapshots = false\n'
                    % (name, material_table(PARAMETERS[dimension]), name))
        env = dict(os.environ, OMP_WAIT_POLICY="passive")
        _, run_test_seconds = run([os.path.join(tools, "run-test"), scene, "--output", out, "--quiet"], env=env)
        with open(os.path.join(out, name + "_run_test_summary.json")) as f:
            linear = json.load(f)["result"]["linear_elastic"]
        scale = PARAMETERS[dimension]["normal_stiffness"] * rest["mean_radius_m"]
        e_yade, e_run_test = ucs["youngs_modulus_pa"], linear["youngs_modulus_platen_pa"]
        rows.append(dict(
            case="%dD, %d %s" % (dimension, rest["particles"], "discs" if dimension == 2 else "spheres"),
            bonds=rest["bonds"], first=rest["largest_bond_force_step_1_n"] / scale,
            end=rest["largest_bond_force_end_n"] / scale, broken=rest["broken_bonds"],
            e_yade=e_yade, e_run_test=e_run_test, error=100.0 * (e_yade / e_run_test - 1.0),
            e_interior=linear["youngs_modulus_in_plane_pa"], yade_steps=ucs["steps"], yade_s=yade_seconds,
            run_test_s=run_test_seconds))
    header = ("| specimen | bonds | max bond force, step 1 / (kn r_mean) | at step 1,000 | broken in 1,000 steps | "
              "E platen, Yade [GPa] | E platen, run-test [GPa] | difference | run-test interior E [GPa] | "
              "Yade UCS to first break |\n|---|---|---|---|---|---|---|---|---|---|\n")
    lines = "".join("| %s | %d | %.3g | %.3g | %d | %.4f | %.4f | %+.2f %% | %.4f | %d steps, %.0f s |\n" % (
        r["case"], r["bonds"], r["first"], r["end"], r["broken"], r["e_yade"] / 1e9, r["e_run_test"] / 1e9,
        r["error"], r["e_interior"] / 1e9, r["yade_steps"], r["yade_s"]) for r in rows)
    table = header + lines
    print(table)
    page = """# The Yade export, run in Yade

Written by `tools/bench/yade_export_bench.py` (Yade %s, %s, %d cores; figures of one run).
For each specimen: generate-packing, `export-specimen --to yade --parameters`, then the script's
at-rest check (`yade -x -n <script> --run at-rest --steps 1000`) and its UCS to the first broken
bond (`--run ucs --until-first-break`), against `run-test` on the same packing and parameters.

%s
- **At rest**: the bonds are made with their initial gap as the zero-force distance, so no
  force arises (the test `lab_yade_export_test` requires below 1e-9 kn r_mean and no broken bond).
- **E** is the same measurement on both sides: platen stress (mean platen force over the
  cross-section, 2D per metre of thickness: in-plane E') against platen strain, least squares
  over the samples before the first broken bond from 20 %% of their largest stress (run-test's
  `linear_elastic.youngs_modulus_platen_pa`). run-test's own E is measured in the interior
  (Bagi strain 4 mean radii inside the boundary), stiffer than the platen reading by the
  compliance of the boundary layers; the Yade script has no interior strain.
- Differences of the two runs: Yade has no contact dashpots (run-test: 0.1 of critical), its
  local damping acts per component, its time step is half the per-particle bound (run-test: 0.7
  of the certified step) and run-test scales the inertia of the few particles that limit its step.
  The platens move as run-test's (same speed and ramp) without its pauses on breakage, which
  start only after the first broken bond.
""" % (version, platform.machine(), os.cpu_count(), table)
    with open(os.path.join(HERE, "yade_export_bench.md"), "w") as f:
        f.write(page)


if __name__ == "__main__":
    main()
