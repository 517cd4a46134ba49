#!/usr/bin/env python3
"""Speed benchmark of the solver core ("Speed"): prints a table, writes JSON and CSV.

  tools/bench/solver_bench.py [--build build] [--out bench-out/solver] [--runs 3]
                              [--threads 1 2] [--steps-2d 400] [--steps-3d 600]
                              [--yade auto|skip] [--yade-steps 200] [--install-yade] [--quick]
                              [--markdown PATH]

1. Specimens (generate-packing, kept in OUT/specimens and reused): a bonded 2D specimen of
   50,000 discs (square of side 100 m, r_max/r_min <= 10) and a 3D specimen of 30,000
   spheres (unit cube, r_max/r_min <= 10); the packing's contact pairs are the bonds.
2. For each specimen and thread count, --runs runs of solver-throughput --model both: the
   rigid and the deformable (DDEM) scene of the same specimen, time step and platens, run
   in alternating chunks of steps inside one process, so that both see the same machine.
   Reported per run: particle-steps per second of each model, bytes of solver arrays per
   particle, and the DDEM overhead (median over the chunk pairs of DDEM time / rigid time,
   minus 1). The same with --model moment: rigid particles with moment-carrying bonds
   (bond radius ratio 1) against the plain bonds, the cost of the bond moments. The table
   gives the medians over the runs.
3. Side by side in the same run (3D, each thread count), when yade is installed (or
   --install-yade, which runs apt-get install yade first): Yade's CohFrictMat on the same
   spheres with the packing's pairs as cohesive bonds, compressed between two walls
   (tools/bench/solver_yade.py). Yade and solver-throughput runs alternate; the ratio of
   our rigid rate to Yade's is taken per run (adjacent in time) and its median reported.
4. The table, as Markdown with the command and the machine (write_markdown): OUT/solver_bench.md,
   or --markdown PATH (tools/bench/solver_bench.md is the committed one).
Targets: DDEM overhead <= 25 %; moment-bond overhead <= 15 %; 3D rigid bonded throughput
>= 10x Yade's.

Threads: OpenMP's default wait policy spins at every barrier. When other processes keep the
cores busy (a shared machine), a spinning thread burns the time slice its partner needs, and
2 threads ran 2.5x slower than 1 on the 3D specimen (load average 5 on 2 cores). The runs
therefore set OMP_WAIT_POLICY=passive (--wait-policy; Yade's runs get the same), under which
2 threads cost nothing on a busy machine and gain on an idle one.
The machine is shared and noisy: medians of runs, ratios from paired measurements.
"""
import argparse
import csv
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))

SPECIMENS = {
    "2D": {"name": "disc2d_50k", "domain": "rectangle 0 0 100 100", "count": 50000},
    "3D": {"name": "sphere3d_30k", "domain": "box 0 0 0 1 1 1", "count": 30000},
}


def generate(build, directory, spec, count):
    name = spec["name"] if count == spec["count"] else "%s_%d" % (spec["name"], count)
    path = os.path.join(directory, name + ".packing")
    if os.path.exists(path):
        return path
    os.makedirs(directory, exist_ok=True)
    command = [os.path.join(build, "tools", "generate-packing"), "--domain", spec["domain"],
               "--count", str(count), "--radius-ratio", "10", "--seed", "1", "--output",
               directory, "--name", name, "--quiet", "--no-pictures"]
    print("generating %s (%d particles) ..." % (name, count), flush=True)
    start = time.time()
    subprocess.run(command, check=True, capture_output=True)
    print("  %.0f s" % (time.time() - start), flush=True)
    return path


def run_solver(build, packing, threads, steps, chunk, model="both"):
    command = [os.path.join(build, "tools", "bench", "solver-throughput"), "--packing", packing,
               "--model", model, "--threads", str(threads), "--steps", str(steps), "--chunk",
               str(chunk), "--quiet"]
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    results = {}
    for line in out.splitlines():
        if line.startswith("RESULT "):
            r = json.loads(line[len("RESULT "):])
            results[r["model"]] = r
    if set(results) != ({"rigid", "ddem"} if model == "both" else {"rigid", "moment"}):
        raise RuntimeError("solver-throughput printed no RESULT lines:\n" + out)
    return results


def run_yade(packing, threads, steps):
    env = dict(os.environ, SOLVER_YADE_PACKING=packing, SOLVER_YADE_STEPS=str(steps),
               SOLVER_YADE_WARMUP=str(max(10, steps // 10)), OMP_NUM_THREADS=str(threads))
    command = ["yade", "-n", "-x", "-j", str(threads), os.path.join(HERE, "solver_yade.py")]
    result = subprocess.run(command, capture_output=True, text=True, env=env)
    for line in result.stdout.splitlines():
        if line.startswith("YADE_RESULT "):
            return json.loads(line[len("YADE_RESULT "):])
    raise RuntimeError("yade printed no result (exit %d):\n%s%s" %
                       (result.returncode, result.stdout[-2000:], result.stderr[-2000:]))


def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def _rate(value):
    """A rate with two significant digits, as in the tables: 8.1e6."""
    if value is None:
        return "-"
    exponent = int(math.floor(math.log10(value)))
    mantissa = round(value / 10 ** exponent, 1)
    if mantissa >= 10.0:
        mantissa, exponent = mantissa / 10.0, exponent + 1
    return "%.1fe%d" % (mantissa, exponent)


def _runs(values, fmt):
    return ", ".join(fmt % v for v in values)


def write_markdown(path, rows, runs, machine_note, wait_policy):
    """Writes the benchmark's one table (tools/bench/solver_bench.md) from the rows main()
    prints: this toolkit's rigid and DDEM rates and Yade's side by side, the paired DDEM
    overhead and Yade ratio with their runs, and the memory per particle."""
    lines = [
        "# Solver throughput: this toolkit against Yade",
        "",
        "Reproduce: `python3 tools/bench/solver_bench.py` (about 10 minutes; `--quick` for a smoke",
        "test; `--install-yade` installs Debian's `yade` for the side-by-side rows; "
        "`--markdown PATH`",
        "writes this file). Machine: %s. Medians of %d run(s), wall clock of the stepping loop, "
        "`OMP_WAIT_POLICY=%s`." % (machine_note, runs, wait_policy),
        "",
        "| specimen | threads | rigid [particle-steps/s] | DDEM [particle-steps/s] "
        "| DDEM overhead, median (runs) | moment bonds [particle-steps/s] "
        "| moment-bond overhead, median (runs) | Yade CohFrictMat [particle-steps/s] "
        "| ours rigid / Yade, median (runs) | bytes/particle: rigid / DDEM / Yade |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        has_yade = r.get("yade_rate") is not None
        specimen = "%s, %s %s, %.1f contacts/particle" % (
            r["dimension"], format(r["particles"], ","),
            "discs" if r["dimension"] == "2D" else "spheres", r["contacts_per_particle"])
        if has_yade:  # the bonds both codes are given
            specimen += ", %s bonds" % format(round(r["bonds_per_particle"] * r["particles"]), ",")
        lines.append("| %s | %d | %s | %s | %.1f %% (%s) | %s | %.1f %% (%s) | %s | %s | %s / %s / %s |" % (
            specimen, r["threads"], _rate(r["rigid_rate"]), _rate(r["ddem_rate"]),
            r["ddem_overhead_percent"], _runs(r["ddem_overhead_runs"], "%.1f"),
            _rate(r["moment_rate"]), r["moment_overhead_percent"],
            _runs(r["moment_overhead_runs"], "%.1f"),
            _rate(r["yade_rate"]) if has_yade else "-",
            ("%.1fx (%s)" % (r["yade_ratio"], _runs(r["yade_ratio_runs"], "%.1f")))
            if has_yade else "-",
            format(round(r["rigid_bytes_per_particle"]), ","),
            format(round(r["ddem_bytes_per_particle"]), ","),
            format(round(r["yade_bytes_per_particle_rss"]), ",") if has_yade else "-"))
    worst_overhead = max(r["ddem_overhead_percent"] for r in rows)
    worst_moment = max(r["moment_overhead_percent"] for r in rows)
    lines += ["", "Targets: DDEM overhead <= 25 %%: worst median %.1f %%, %s. Moment-bond overhead "
              "<= 15 %%: worst median %.1f %%, %s." % (
                  worst_overhead, "met" if worst_overhead <= 25.0 else "missed", worst_moment,
                  "met" if worst_moment <= 15.0 else "missed")]
    yade_rows = [r for r in rows if r.get("yade_rate") is not None]
    if yade_rows:
        worst_ratio = min(r["yade_ratio"] for r in yade_rows)
        version = yade_rows[0].get("yade_version") or "the installed version"
        lines[-1] += " 3D rigid bonded >= 10x Yade (%s): worst median %.1fx, %s." % (
            version, worst_ratio, "met" if worst_ratio >= 10.0 else "missed")
    lines += [
        "",
        "- Scene (`tools/bench/solver_throughput.cpp`): the packing's pairs are the bonds, with",
        "  strengths out of reach (the failure check runs, nothing breaks); kt = 0.5 kn, friction",
        "  0.5 on unbonded contacts, rotation, local damping 0.1, the neighbour search, two",
        "  frictionless platens (the upper one moving 0.02 mean radii per 1000 steps). DDEM adds",
        "  Ep with nu_p = 0.2 and kn = 0.2 Ep R_min (2D: 0.2 Ep l); the rigid scene takes the same",
        "  kn and time step, so the two differ by the DDEM stages only. The moment-bond scene",
        "  is the rigid one with bond radius ratio 1 (bending, and in 3D twisting, springs on",
        "  every bond and the peripheral-stress failure check), paired with the rigid one at the",
        "  same time step.",
        "- DDEM overhead: the rigid and DDEM scenes run in alternating chunks of steps in one",
        "  process; the overhead is the median over chunk pairs of DDEM time / rigid time - 1.",
        "- Yade (`tools/bench/solver_yade.py`): CohFrictMat on the same spheres with exactly the",
        "  same bonds, the same friction, shear stiffness, damping and walls, no moment law.",
        "  Its time step (0.5 of Yade's p-wave estimate) sets how often its collider runs, not",
        "  the cost of a step. Yade's and our runs alternate; the ratio is taken per pair of",
        "  adjacent runs.",
        "- Memory: ours is the capacity of the solver's arrays (`RunSummary::memory_bytes`),",
        "  Yade's the growth of its resident memory while it builds and runs the scene.",
        "- The absolute rates move with the machine's load between runs of the script; the",
        "  paired figures (overhead, ratio) hardly do.",
        "",
    ]
    with open(path, "w") as f:
        f.write("\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="bench-out/solver")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--steps-2d", type=int, default=400)
    parser.add_argument("--steps-3d", type=int, default=600)
    parser.add_argument("--chunk", type=int, default=20, help="steps per rigid/DDEM alternation")
    parser.add_argument("--yade", choices=["auto", "skip"], default="auto",
                        help="auto: run Yade side by side when installed")
    parser.add_argument("--yade-steps", type=int, default=200)
    parser.add_argument("--install-yade", action="store_true",
                        help="apt-get install yade first (Debian package) if it is missing")
    parser.add_argument("--wait-policy", choices=["passive", "active", "default"], default="passive",
                        help="OMP_WAIT_POLICY of the solver and Yade runs (default: passive; "
                             "see the module docstring)")
    parser.add_argument("--markdown", default=None,
                        help="where to write the table as Markdown (default OUT/solver_bench.md; "
                             "tools/bench/solver_bench.md is the committed one)")
    parser.add_argument("--quick", action="store_true",
                        help="small specimens (5,000 discs, 3,000 spheres), 1 run: a smoke test")
    args = parser.parse_args()

    if args.install_yade and not shutil.which("yade"):
        print("installing yade (apt-get) ...", flush=True)
        subprocess.run(["apt-get", "install", "-y", "yade"], check=True)
    use_yade = args.yade == "auto" and shutil.which("yade") is not None
    if args.wait_policy != "default":
        os.environ["OMP_WAIT_POLICY"] = args.wait_policy
    if args.quick:
        args.runs = 1
        args.steps_2d = args.steps_3d = 100
        args.yade_steps = 50

    load_before = " ".join("%.1f" % v for v in os.getloadavg())
    os.makedirs(args.out, exist_ok=True)
    specimen_dir = os.path.join(args.out, "specimens")
    rows = []
    yade_rows = []
    for dim in ("2D", "3D"):
        spec = SPECIMENS[dim]
        count = spec["count"] // 10 if args.quick else spec["count"]
        packing = generate(args.build, specimen_dir, spec, count)
        steps = args.steps_2d if dim == "2D" else args.steps_3d
        for threads in args.threads:
            runs = []
            for run in range(args.runs):
                r = run_solver(args.build, packing, threads, steps, args.chunk)
                m = run_solver(args.build, packing, threads, steps, args.chunk, "moment")
                entry = {"run": run, "solver": r, "moment": m}
                if dim == "3D" and use_yade:
                    entry["yade"] = run_yade(os.path.abspath(packing), threads, args.yade_steps)
                    entry["ratio"] = (r["rigid"]["particle_steps_per_second"] /
                                      entry["yade"]["particle_steps_per_second"])
                runs.append(entry)
                print("  %s %d thread(s) run %d: rigid %.3e, DDEM %.3e particle-steps/s, "
                      "overhead %.1f %%, moment bonds %.1f %%%s" % (
                          dim, threads, run + 1, r["rigid"]["particle_steps_per_second"],
                          r["ddem"]["particle_steps_per_second"],
                          r["ddem"]["paired_overhead_median_chunk_percent"],
                          m["moment"]["paired_overhead_median_chunk_percent"],
                          (", Yade %.3e (ratio %.1f)" % (entry["yade"]["particle_steps_per_second"],
                                                         entry["ratio"])) if "yade" in entry else ""),
                      flush=True)
            first = runs[0]["solver"]
            row = {
                "dimension": dim,
                "particles": first["rigid"]["particles"],
                "contacts_per_particle": first["rigid"]["contacts_per_particle"],
                "bonds_per_particle": first["rigid"]["bonds_per_particle"],
                "threads": threads,
                "steps": steps,
                "runs": len(runs),
                "rigid_rate": median(e["solver"]["rigid"]["particle_steps_per_second"] for e in runs),
                "ddem_rate": median(e["solver"]["ddem"]["particle_steps_per_second"] for e in runs),
                "rigid_bytes_per_particle": first["rigid"]["bytes_per_particle"],
                "ddem_bytes_per_particle": first["ddem"]["bytes_per_particle"],
                "ddem_overhead_percent": median(
                    e["solver"]["ddem"]["paired_overhead_median_chunk_percent"] for e in runs),
                "ddem_overhead_runs": [e["solver"]["ddem"]["paired_overhead_median_chunk_percent"]
                                       for e in runs],
                "moment_rate": median(e["moment"]["moment"]["particle_steps_per_second"] for e in runs),
                "moment_overhead_percent": median(
                    e["moment"]["moment"]["paired_overhead_median_chunk_percent"] for e in runs),
                "moment_overhead_runs": [e["moment"]["moment"]["paired_overhead_median_chunk_percent"]
                                         for e in runs],
                "rigid_cpu_rate": median(
                    e["solver"]["rigid"]["particles"] * e["solver"]["rigid"]["steps"] /
                    e["solver"]["rigid"]["cpu_seconds"] for e in runs),
            }
            if any("yade" in e for e in runs):
                y = [e["yade"] for e in runs]
                row["yade_rate"] = median(v["particle_steps_per_second"] for v in y)
                row["yade_ratio"] = median(e["ratio"] for e in runs)
                row["yade_ratio_runs"] = [e["ratio"] for e in runs]
                row["yade_bytes_per_particle_rss"] = median(v["bytes_per_particle_rss"] for v in y)
                row["yade_bonds_per_particle"] = y[0]["bonds_per_particle"]
                row["yade_contacts_per_particle"] = y[0]["contacts_per_particle"]
                row["yade_version"] = y[0].get("yade_version", "")
                yade_rows.append(row)
            rows.append(row)
            with open(os.path.join(args.out, "solver_bench_runs_%s_%dt.json" % (dim, threads)), "w") as f:
                json.dump(runs, f, indent=1)

    # The table.
    print()
    print("Solver core speed, medians of %d run(s); particle-steps per second (wall clock); "
          "OMP_WAIT_POLICY=%s; load average before the runs %s" % (
              args.runs, os.environ.get("OMP_WAIT_POLICY", "unset"), load_before))
    header = ("case", "threads", "rigid p-steps/s", "DDEM p-steps/s", "DDEM overhead",
              "bytes/particle rigid", "bytes/particle DDEM")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        case = "%s %d %s, %.1f contacts/particle" % (
            r["dimension"], r["particles"], "discs" if r["dimension"] == "2D" else "spheres",
            r["contacts_per_particle"])
        print("| %s | %d | %.3e | %.3e | %.1f %% (runs %s) | %.0f | %.0f |" % (
            case, r["threads"], r["rigid_rate"], r["ddem_rate"], r["ddem_overhead_percent"],
            ", ".join("%.1f" % v for v in r["ddem_overhead_runs"]), r["rigid_bytes_per_particle"],
            r["ddem_bytes_per_particle"]))
    worst = max(r["ddem_overhead_percent"] for r in rows)
    print("DDEM overhead target <= 25 %%: worst median %.1f %% -> %s" %
          (worst, "met" if worst <= 25.0 else "MISSED"))
    for r in rows:
        print("moment bonds, %s %d thread(s): %.3e particle-steps/s, overhead %.1f %% (runs %s)" % (
            r["dimension"], r["threads"], r["moment_rate"], r["moment_overhead_percent"],
            ", ".join("%.1f" % v for v in r["moment_overhead_runs"])))
    worst = max(r["moment_overhead_percent"] for r in rows)
    print("Moment-bond overhead target <= 15 %%: worst median %.1f %% -> %s" %
          (worst, "met" if worst <= 15.0 else "MISSED"))
    if yade_rows:
        print()
        print("3D rigid bonded, side by side with Yade (CohFrictMat, same spheres and bonds, "
              "two walls)")
        header = ("threads", "ours p-steps/s", "Yade p-steps/s", "ratio (median of paired runs)",
                  "Yade RSS bytes/particle", "bonds/particle ours / Yade")
        print("| " + " | ".join(header) + " |")
        print("|" + "---|" * len(header))
        for r in yade_rows:
            print("| %d | %.3e | %.3e | %.1fx (runs %s) | %.0f | %.2f / %.2f |" % (
                r["threads"], r["rigid_rate"], r["yade_rate"], r["yade_ratio"],
                ", ".join("%.1f" % v for v in r["yade_ratio_runs"]),
                r["yade_bytes_per_particle_rss"], r["bonds_per_particle"],
                r["yade_bonds_per_particle"]))
        worst = min(r["yade_ratio"] for r in yade_rows)
        print("Target >= 10x Yade: worst median ratio %.1fx -> %s" %
              (worst, "met" if worst >= 10.0 else "MISSED"))
    elif args.yade == "auto":
        print("\nYade is not installed: no side-by-side comparison (--install-yade installs the "
              "Debian package).")

    with open(os.path.join(args.out, "solver_bench.json"), "w") as f:
        json.dump(rows, f, indent=1)
    with open(os.path.join(args.out, "solver_bench.csv"), "w", newline="") as f:
        fields = [k for k in rows[0] if not isinstance(rows[0][k], list)]
        fields += [k for k in ("yade_rate", "yade_ratio", "yade_bytes_per_particle_rss",
                               "yade_bonds_per_particle", "yade_contacts_per_particle")
                   if k not in fields]
        writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        for r in rows:
            writer.writerow(r)
    markdown = args.markdown or os.path.join(args.out, "solver_bench.md")
    load_after = " ".join("%.1f" % v for v in os.getloadavg())
    write_markdown(markdown, rows, args.runs,
                   "%d cores, load average %s before and %s after the runs" % (
                       os.cpu_count() or 0, load_before, load_after),
                   os.environ.get("OMP_WAIT_POLICY", "unset"))
    print("\nwritten: %s/solver_bench.json, solver_bench.csv, solver_bench_runs_*.json, %s" % (
        args.out, markdown))
    return 0


if __name__ == "__main__":
    sys.exit(main())
