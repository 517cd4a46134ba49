#!/usr/bin/env python3
"""calibrate-to-material under mpirun (common/ranks.h, calibrate/map_sweep.h).

  mpi_sweep_test.py identical --bin BUILD_DIR --mpirun MPIRUN
      A tiny 2D calibration (200 discs, a rigid sweep of 3 x 3 points, one strength round)
      run without mpirun and with mpirun -n 2 and -n 3 (--oversubscribe: CI has 2 cores): the map files are
      equal to the last bit but for the wall times and the creation date; the same exit
      status. Then one run on generated specimens (rank 0 generates, the others receive).
  mpi_sweep_test.py resume --bin BUILD_DIR --mpirun MPIRUN
      mpirun -n 3 with rank 1 ending as a killed process after its first point (test hook
      SPECIMEN_TEST_SWEEP_EXIT), then a resume on 2 ranks: every point is in the maps once,
      the journals of both runs hold each point once (none finished twice), and the maps
      equal those of a run without mpirun.

Open MPI refuses to run as root without two environment variables: set here (CI runs as
root), not asked of the user.
"""
import argparse
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

SWEEP = ["--model", "rigid", "--sweep-levels", "3", "--rounds", "1", "--threads", "1", "--quiet", "--no-pictures"]
VOLATILE = {"created_utc", "sweep_seconds", "seconds"}  # wall times and the date


def environment():
    env = dict(os.environ)
    if os.geteuid() == 0:
        env["OMPI_ALLOW_RUN_AS_ROOT"] = "1"
        env["OMPI_ALLOW_RUN_AS_ROOT_CONFIRM"] = "1"
    # Containers often forbid the cross-memory attach of Open MPI's shared-memory transport.
    env.setdefault("OMPI_MCA_btl_vader_single_copy_mechanism", "none")
    env.setdefault("OMP_WAIT_POLICY", "passive")
    for hook in ("SPECIMEN_TEST_SWEEP_EXIT", "SPECIMEN_TEST_KEEP_JOURNALS"):
        env.pop(hook, None)
    return env


def run(command, env, expect=(0, 4)):
    result = subprocess.run(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            timeout=900)
    if expect is not None and result.returncode not in expect:
        sys.exit(f"FAIL: {' '.join(command)} -> {result.returncode}\n{result.stdout}")
    return result


def mpirun(args, ranks):
    return [args.mpirun, "--oversubscribe", "--bind-to", "none", "-n", str(ranks)]


def make_packings(args, work, env):
    gen = str(pathlib.Path(args.bin) / "tools" / "generate-packing")
    run([gen, "--domain", "rectangle 0 0 0.01 0.01", "--count", "200", "--no-pictures", "--quiet", "--output",
         str(work / "ucs"), "--name", "ucs"], env, expect=(0,))
    run([gen, "--domain", "disc 0.005 0.005 0.005", "--count", "160", "--no-pictures", "--quiet", "--output",
         str(work / "bts"), "--name", "bts"], env, expect=(0,))
    return ["--packing", str(work / "ucs" / "ucs.packing"), "--bts-packing", str(work / "bts" / "bts.packing")]


def calibrate(args, work, label, packings, env, ranks=None, extra=()):
    command = [] if ranks is None else mpirun(args, ranks)
    command += [str(pathlib.Path(args.bin) / "tools" / "calibrate-to-material"), args.material] + packings + SWEEP
    command += ["--maps-dir", str(work / label / "maps"), "--output", str(work / label / "out")] + list(extra)
    return run(command, env)


def map_file(work, label):
    files = sorted((work / label / "maps").glob("maps_*.json"))
    if len(files) != 1:
        sys.exit(f"FAIL: {label}: expected one map file, found {[str(f) for f in files]}")
    return files[0]


def stable(value):
    if isinstance(value, dict):
        return {k: stable(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [stable(v) for v in value]
    return value


def maps_of(work, label):
    # json floats are doubles parsed correctly rounded: equal here means the same bits.
    return stable(json.loads(map_file(work, label).read_text()))


def journal_points(directory):
    """(index, line) of every whole line of every journal and rank journal."""
    points = []
    for path in sorted(directory.glob("*.journal*")):
        for line in path.read_text().splitlines():
            try:
                points.append(json.loads(line)["point"]["index"])
            except (ValueError, KeyError):
                pass  # a torn line (killed mid-write)
    return points


def identical(args, work, env):
    packings = make_packings(args, work, env)
    serial = calibrate(args, work, "serial", packings, env)
    reference = maps_of(work, "serial")
    if len(reference["points"]) != 9:
        sys.exit(f"FAIL: expected 9 sweep points, found {len(reference['points'])}")
    for ranks in (2, 3):
        result = calibrate(args, work, f"ranks{ranks}", packings, env, ranks)
        if result.returncode != serial.returncode:
            sys.exit(f"FAIL: {ranks} ranks: status {result.returncode}, serial {serial.returncode}\n{result.stdout}")
        maps = maps_of(work, f"ranks{ranks}")
        if maps != reference:
            for key in reference:
                if maps.get(key) != reference[key]:
                    print(f"differs: {key}\n  serial: {reference[key]}\n  {ranks} ranks: {maps.get(key)}")
            sys.exit(f"FAIL: the maps of {ranks} ranks differ from the serial ones")
        # The final Brazilian test's outputs come from rank 1, the rest from rank 0.
        out = work / f"ranks{ranks}" / "out"
        for name in ("calibration_report.json", "calibration_verify_ucs_summary.json",
                     "calibration_verify_bts_summary.json"):
            if not (out / name).exists() or name not in result.stdout:
                sys.exit(f"FAIL: {ranks} ranks: {name} missing or not listed\n{result.stdout}")
        print(f"{ranks} ranks: maps identical to the serial run ({len(maps['points'])} points)")
    # Generated specimens: rank 0 generates them and sends them to the other ranks.
    generated = calibrate(args, work, "generated", ["--ucs-domain", "rectangle 0 0 0.01 0.01", "--count", "200",
                                                    "--sweep-fraction", "1"], env, 2)
    if len(maps_of(work, "generated")["points"]) != 9:
        sys.exit(f"FAIL: generated specimens on 2 ranks\n{generated.stdout}")
    print("generated specimens on 2 ranks: 9 points")


def resume(args, work, env):
    packings = make_packings(args, work, env)
    calibrate(args, work, "serial", packings, env)
    reference = maps_of(work, "serial")
    killed_env = dict(env, SPECIMEN_TEST_SWEEP_EXIT="1:1", SPECIMEN_TEST_KEEP_JOURNALS="1")
    body = [str(pathlib.Path(args.bin) / "tools" / "calibrate-to-material"), args.material] + packings + SWEEP
    body += ["--maps-dir", str(work / "run" / "maps"), "--output", str(work / "run" / "out")]
    killed = run(mpirun(args, 3) + body, killed_env, expect=None)
    if killed.returncode == 0:
        sys.exit(f"FAIL: the run whose rank 1 was killed ended with status 0\n{killed.stdout}")
    before = journal_points(work / "run" / "maps")
    if not (1 <= len(before) < 9) or len(set(before)) != len(before):
        sys.exit(f"FAIL: after the kill the journals hold {before}, expected 1 to 8 distinct points")
    if list((work / "run" / "maps").glob("maps_*.json")):
        sys.exit("FAIL: a map file was written by the killed run")
    print(f"killed run: {len(before)} of 9 points journaled: {sorted(before)}")
    resumed = run(mpirun(args, 2) + body, dict(env, SPECIMEN_TEST_KEEP_JOURNALS="1"))
    after = journal_points(work / "run" / "maps")
    if sorted(after) != list(range(9)):
        sys.exit(f"FAIL: the journals of both runs hold {sorted(after)}, expected each of 0..8 once\n{resumed.stdout}")
    maps = maps_of(work, "run")
    indices = sorted(p["index"] for p in maps["points"])
    if indices != list(range(9)):
        sys.exit(f"FAIL: the resumed maps hold points {indices}")
    if maps["points"] != reference["points"] or maps["surfaces"] != reference["surfaces"]:
        sys.exit("FAIL: the resumed sweep differs from the serial run")
    print(f"resumed on 2 ranks: every point once ({len(after) - len(before)} run after the kill), "
          "sweep and fit identical to the serial run")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("case", choices=["identical", "resume"])
    parser.add_argument("--bin", required=True, help="the build directory")
    parser.add_argument("--mpirun", required=True)
    parser.add_argument("--material", required=True)
    args = parser.parse_args()
    work = pathlib.Path(tempfile.mkdtemp(prefix=f"specimen_mpi_{args.case}_"))
    try:
        (identical if args.case == "identical" else resume)(args, work, environment())
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("PASS")


if __name__ == "__main__":
    main()
