#!/usr/bin/env python3
"""The ESyS-Particle export checked in ESyS-Particle: prints a table and writes it to esys_export_bench.md.

  OMP_WAIT_POLICY=passive python3 tools/bench/esys_export_bench.py [--build build] [--out bench-out/esys_export]

For the specimens and parameter sets of yade_export_bench.py (2D square, 500 discs; 3D
cylinder, 1,500 spheres), as a user would: generate-packing, export-specimen --to esys
--parameters, then
  1. mpirun -np 2 esysparticle <script> --run at-rest --steps 1000: the largest bond force at step 1
     and at the end, against kn x r_mean, and the bonds broken (each bond is a short normal bond
     at rest at its initial distance plus a shear-only rotational bond);
  2. the same with --bond-law rotbond: ESyS's own rotational bond with the same kn, kt, Rn, Rt,
     whose normal rest length is ri + rj, for the residual force it starts with;
and the bond groups, the tension-limit error and the shear-stiffness deviation the script's header
states. The table goes to tools/bench/esys_export_bench.md with the ESyS version and the machine.
"""
import argparse
import json
import os
import platform
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from yade_export_bench import CASES, PARAMETERS, exported_specimen, run  # noqa: E402  the same specimens and sets

MPI = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", "2", "esysparticle"]


def esys_json(script, arguments, path):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    _, seconds = run(MPI + [script] + arguments + ["--json", path], env=env)
    with open(path) as f:
        return json.load(f), seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(os.path.dirname(os.path.dirname(HERE)), "build"))
    parser.add_argument("--out", default=os.path.join(os.path.dirname(os.path.dirname(HERE)), "bench-out",
                                                      "esys_export"))
    args = parser.parse_args()
    tools = os.path.join(os.path.abspath(args.build), "tools")
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    package = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "esys-particle"], capture_output=True,
                             text=True).stdout.strip() or "unknown"
    rows = []
    for dimension, domain, count in CASES:
        name = "p%dd" % dimension
        script = exported_specimen(tools, out, dimension, domain, count, "esys")
        with open(script) as f:
            header = f.read(4000)
        tension = re.search(r"tension limit RN\n#\s+within ([0-9.e+-]+) %", header).group(1)
        shear = re.search(r"within ([0-9.e+-]+) % of KT", header).group(1)
        rest, seconds = esys_json(script, ["--run", "at-rest", "--steps", "1000"],
                                  os.path.join(out, name + "_esys_at_rest.json"))
        rotbond, _ = esys_json(script, ["--run", "at-rest", "--steps", "1000", "--bond-law", "rotbond",
                                        "--output-dir", os.path.join(out, name + "_rotbond_out")],
                               os.path.join(out, name + "_esys_rotbond.json"))
        scale = PARAMETERS[dimension]["normal_stiffness"] * rest["mean_radius_m"]
        rows.append(dict(
            case="%dD, %d %s" % (dimension, rest["particles"], "discs" if dimension == 2 else "spheres"),
            bonds=rest["bonds"], groups=rest["bond_groups"], tension=tension, shear=shear,
            first=rest["largest_bond_force_step_1_n"] / scale, end=rest["largest_bond_force_end_n"] / scale,
            broken=rest["broken_bonds"], seconds=seconds, rot_first=rotbond["largest_bond_force_step_1_n"] / scale,
            rot_broken=rotbond["broken_bonds"], version=rest["esys_version"]))
    header = ("| specimen | bonds | groups | tension limit within | shear stiffness within | max bond force, step 1 / "
              "(kn r_mean) | at step 1,000 | broken in 1,000 steps | 1,000 steps | ESyS RotBond: step 1 / (kn r_mean) "
              "| RotBond: broken in 1,000 steps |\n|---|---|---|---|---|---|---|---|---|---|---|\n")
    lines = "".join("| %s | %d | %d | %s %% | %s %% | %.3g | %.3g | %d | %.0f s | %.3g | %d |\n" % (
        r["case"], r["bonds"], r["groups"], r["tension"], r["shear"], r["first"], r["end"], r["broken"],
        r["seconds"], r["rot_first"], r["rot_broken"]) for r in rows)
    table = header + lines
    print(table)
    page = """# The ESyS-Particle export, run in ESyS-Particle

Written by `tools/bench/esys_export_bench.py` (Debian package esys-particle %s, library version %s, %s,
%d cores; figures of one run). For each specimen of [yade_export_bench.md](yade_export_bench.md) (same
packings and parameter sets): generate-packing, `export-specimen --to esys --parameters`, then the
script's at-rest check (`mpirun -np 2 esysparticle <script> --run at-rest --steps 1000`, 1 master and 1
worker), and the same with `--bond-law rotbond`.

%s
- **At rest**: each bond is an `NRotShortBondPrms` normal spring, whose rest length ESyS sets to the
  initial distance, and a `RotBondPrms` with normalK 0 for the shear spring (zero at creation), so no
  force arises (the test `lab_esys_export_test` requires below 1e-9 kn r_mean and no broken bond).
- **ESyS RotBond** is ESyS-Particle 2.3.5's rotational bond with the same kn, kt, Rn, Rt and
  `scaling=False`: its normal spring is at rest at ri + rj, so every bond across a gap starts with
  kn x gap; the column gives the largest at step 1 and the bonds that this breaks.
- **Groups**: the short bond breaks at a stretch of breakDistance x d0, one value per tag, so the bonds
  are grouped by initial length d0 (at most 1 %% wide) and the tension limit is Rn within the stated
  error. ESyS's shear spring acts on (ri + rj) x the rotation of the branch, so its stiffness is
  kt (ri + rj)/d0, within the stated deviation of kt.
- No UCS is run in ESyS: the script has no platens (docs/exports.md says what is not carried).
""" % (package, rows[0]["version"], platform.machine(), os.cpu_count(), table)
    with open(os.path.join(HERE, "esys_export_bench.md"), "w") as f:
        f.write(page)


if __name__ == "__main__":
    main()
