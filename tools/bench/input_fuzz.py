#!/usr/bin/env python3
"""Fuzzing of the input readers and of the commands: prints a table of outcomes.

  tools/bench/input_fuzz.py [--build build] [--out bench-out/fuzz] [--seconds 3600]
        [--command-share 0.2] [--seed 1]

1. Corpus: two small packings made by generate-packing (2D, 3D), the example scenes, the
   bundled and published materials, a stability-parameter file.
2. In process (input-fuzz, most of the time): mutated copies of the corpus through the
   readers and the checks the commands make before any work. Every input must end in a
   result or a typed error (statuses 2, 3, 4); another exception or an input slower than
   5 s is a finding.
3. Commands (--command-share of the time): mutated packings through stability-limit,
   mutated scenes (on a 200-disc packing) through run-test. Every exit status must be one of
   0, 2, 3, 4; a run still going after 300 s is a hang. Findings go to <out>/findings.
"""
import argparse
import glob
import os
import random
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOKENS = ["0", "-0", "1e308", "1e309", "-1", "1e-320", "nan", "inf", "0x10", "1e", ".", "\"\"", "[", "]",
          "=", "#", "\n", "99999999999999999999", "dimension 3", "contacts", "particles"]


def mutate(text, rng):
    for _ in range(rng.randint(1, 4)):
        n = len(text)
        a = rng.randint(0, n)
        kind = rng.randrange(5)
        if kind == 0 and n:
            text = text[:a] + chr(rng.randrange(32, 127)) + text[a + 1:]
        elif kind == 1:
            text = text[:a] + text[a + rng.randint(1, 40):]
        elif kind == 2:
            b = rng.randint(0, n)
            text = text[:b] + text[a:a + rng.randint(1, 200)] + text[b:]
        elif kind == 3:
            text = text[:a] + rng.choice(TOKENS) + text[a:]
        else:
            lines = text.split("\n")
            if lines:
                del lines[rng.randrange(len(lines))]
            text = "\n".join(lines)
    return text


def run(command, timeout):
    start = time.time()
    try:
        p = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=timeout)
        return p.returncode, time.time() - start, p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        return "hang", time.time() - start, ""


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--out", default=os.path.join(ROOT, "bench-out", "fuzz"))
    parser.add_argument("--seconds", type=float, default=3600.0)
    parser.add_argument("--command-share", type=float, default=0.2)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    build, out = os.path.abspath(args.build), os.path.abspath(args.out)
    tools = os.path.join(build, "tools")
    shutil.rmtree(out, ignore_errors=True)
    corpus, findings = os.path.join(out, "corpus"), os.path.join(out, "findings")
    os.makedirs(corpus)
    os.makedirs(findings)

    # 1. The corpus.
    for name, domain in (("p2", "rectangle 0 0 0.01 0.01"), ("p3", "box 0 0 0 0.01 0.01 0.01")):
        subprocess.run([os.path.join(tools, "generate-packing"), "--domain", domain, "--count", "200",
                        "--output", corpus, "--name", name, "--quiet", "--no-pictures"], check=True,
                       stdout=subprocess.DEVNULL)
    packings = [os.path.join(corpus, "p2.packing"), os.path.join(corpus, "p3.packing")]
    parameters = os.path.join(corpus, "parameters.toml")
    with open(parameters, "w") as f:
        f.write("[material]\nnormal_stiffness = 1e9\ntangential_stiffness = 3e8\ndensity = 2650\n"
                "particle_youngs_modulus = 5e10\nparticle_poisson_ratio = 0.2\nplane_model = \"strain\"\n"
                "[time_step]\ntime_step = 1e-8\nsafety_factor = 0.9\n[stability]\nmax_spectral_radius = 0.95\n"
                "time_step_margin = 0.05\n[walls]\nsides = [\"bottom\", \"top\"]\nnormal_stiffness = 1e9\n"
                "tangential_stiffness = 1e8\nfriction = 0.5\n")
    scenes = sorted(glob.glob(os.path.join(ROOT, "data", "scenes", "*.toml")))
    materials = sorted(glob.glob(os.path.join(ROOT, "data", "materials", "*.toml")) +
                       glob.glob(os.path.join(ROOT, "data", "materials", "published", "*.toml")))

    # 2. In process.
    in_process = args.seconds * (1.0 - args.command_share)
    command = [os.path.join(tools, "bench", "input-fuzz"), "--seconds", str(in_process), "--seed", str(args.seed),
               "--findings", os.path.join(findings, "in_process")]
    for s in scenes:
        command += ["--scene", s]
    for m in materials:
        command += ["--material", m]
    command += ["--parameters", parameters]
    for p in packings:
        command += ["--packing", p]
    p = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    table = p.stdout.decode()
    print("In process (%.0f s): input-fuzz exit %s" % (in_process, p.returncode))
    print(table)
    if p.returncode < 0:
        print("input-fuzz CRASHED (signal %d); the input is in %s" % (-p.returncode, findings))
    in_process_ok = p.returncode == 0

    # 3. Commands.
    rng = random.Random(args.seed)
    texts = {path: open(path).read() for path in packings + scenes}
    # The scenes on the small 2D packing: the run-test cases stay short.
    scene_texts = []
    for s in scenes:
        t = texts[s]
        lines, skip = [], False
        for line in t.split("\n"):
            if line.strip().startswith("["):
                skip = line.strip() == "[specimen]"
                if skip:
                    lines.append("[specimen]\npacking = \"%s\"" % packings[0])
                    continue
            if not skip:
                lines.append(line)
        if "3d" not in os.path.basename(s):
            scene_texts.append("\n".join(lines))
    statuses, hangs, slowest, count, bad = {}, 0, 0.0, 0, 0
    work = os.path.join(out, "work")
    deadline = time.time() + args.seconds * args.command_share
    while time.time() < deadline:
        count += 1
        if rng.random() < 0.5:
            text = mutate(texts[rng.choice(packings)], rng)
            path = os.path.join(work, "in.packing")
            os.makedirs(work, exist_ok=True)
            with open(path, "w") as f:
                f.write(text)
            cmd = [os.path.join(tools, "stability-limit"), "--packing", path, "--kn", "1e9", "--density", "2650",
                   "--output", os.path.join(work, "o"), "--quiet", "--no-pictures"]
            which = "stability-limit"
        else:
            text = mutate(rng.choice(scene_texts), rng)
            path = os.path.join(work, "in.toml")
            os.makedirs(work, exist_ok=True)
            with open(path, "w") as f:
                f.write(text)
            cmd = [os.path.join(tools, "run-test"), path, "--output", os.path.join(work, "o"), "--quiet",
                   "--no-pictures", "--no-snapshots", "--no-quasi-static-check"]
            which = "run-test"
        status, seconds, stderr = run(cmd, 300)
        slowest = max(slowest, seconds)
        key = (which, status)
        statuses[key] = statuses.get(key, 0) + 1
        if status == "hang" or status not in (0, 2, 3, 4):
            bad += 1
            hangs += status == "hang"
            keep = os.path.join(findings, "%s_%d" % (which, count))
            shutil.copy(path, keep + os.path.splitext(path)[1])
            with open(keep + ".why", "w") as f:
                f.write("status %s after %.1f s\n%s" % (status, seconds, stderr))
    print("Commands (%.0f s, %d runs, slowest %.1f s):" % (args.seconds * args.command_share, count, slowest))
    print("| command | exit status | runs |")
    print("|---|---|---|")
    for (which, status), n in sorted(statuses.items(), key=lambda kv: (kv[0][0], str(kv[0][1]))):
        print("| %s | %s | %d |" % (which, status, n))
    print("findings: %d in the commands (%d hangs); in process: %s" % (bad, hangs, "none" if in_process_ok else "see above"))
    return 0 if bad == 0 and in_process_ok else 1


if __name__ == "__main__":
    sys.exit(main())
