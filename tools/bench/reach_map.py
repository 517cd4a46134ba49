#!/usr/bin/env python3
"""The reach map: which (nu, UCS / sigma_t) each model reaches on the calibrator's default 2D
specimens, or on its 3D ones (--dimension 3), measured by real tests; prints the table, writes
CSV, JSON and a picture.

  tools/bench/reach_map.py [--build build] [--dimension 2] [--out bench-out/reach] [--packings UCS BTS]
        [--models rigid,moment,ddem,lattice] [--markdown PATH] [--picture PATH] [--quick] [--reuse JSON]
        [--lattice-map JSON] [--bond-strain FACTOR] [--stiffness-ratios LIST]

The specimens: the calibrator's own 5,064-disc UCS square and 3,940-disc Brazilian disc
(--packings, or bench-out/calibration/reference/ when the calibration bench made them, or
made here by a one-round calibration of the bundled Labra rock). At every point of a grid
over each model's micro parameters, run-test runs what the calibrator runs: the elastic run
(bonds unbreakable, E and nu of the intact specimen, plane strain), the UCS and the
Brazilian test; the point's (nu, UCS / sigma_t) goes into the map. The grids:

  rigid    contact bonds (Labra's law): kt/kn 0.1, 0.2, 0.4, 0.9 x Rt/Rn 0.25, 1, 3.16, 10, 30
  moment   bonds with a moment (bond_radius_ratio 1, a parallel bond): kt/kn 0.1, 0.2, 0.4,
           0.9 x Rt/Rn 0.5, 1, 3.16, 10
  ddem     deformable particles, nu_p 0.45, kn/(Ep l) at 0.85 of the admissible bound of both
           specimens (rho(B) <= 0.9): kt/kn 0.05, 0.15, 0.3, 0.6 x Rt/Rn 1, 3.16, 10
  rigid_jaws, ddem_jaws  the rigid and DDEM grids with the Brazilian test between jaws with a
           30-degree loading arc (run-test's loading_arc; calibrate-to-material --loading-arc 30);
           the UCS and nu of a point are taken from the flat-platen model's row of the same point
           when this run or --reuse has it (the arc changes only the Brazilian test)
  lattice  the six-spring lattice, nu 0.05, 0.15, 0.25, 0.35, 0.45 x friction angle 10, 30,
           50 degrees x triangle sigma_t / c 0.05, 0.2, 2 (E and nu are inputs); with
           --lattice-map, the points of the calibrator's stored strength map of these specimens
           instead (data/maps/maps_2d_lattice_*.json: its rows of nu x friction angle 5, 15,
           30, 50 x sigma_t / c 0.05-2.5, each a UCS and a Brazilian test), not measured again

In 3D (--dimension 3; out bench-out/reach3d) the specimens are a calibrator's 3D ones: --packings,
or the 5,142-sphere UCS cylinder and 1,442-sphere Brazilian disc of the first 3D twin of the
calibration bench (bench-out/calibration3d/twin3d_01/; `calibration_bench.py --only 3d --twins-3d 1
--count-3d 5000 --out bench-out/calibration3d` makes them). nu is the 3D one; the Brazilian test has flat
platens, the calibrator's bonded default. kn and Rn keep the 2D grid's kn / l and bond strain at
failure Rn / (kn l), l the UCS specimen's volume-mean radius (run-test's l in 3D); --bond-strain
FACTOR multiplies Rn, and so that strain, in either dimension (in 3D the ratio of bonded spheres
moves with it); --stiffness-ratios replaces the kt/kn levels of every bonded grid (to measure
beyond the calibration maps' box, kt/kn 0.15-0.9). The grids
(default models rigid, rigid_range, ddem_range):

  rigid        contact bonds: kt/kn 0.1, 0.3, 0.6, 0.9 x Rt/Rn 0.5, 2, 6, 20
  rigid_range  the same with bonds within range (bond_range gamma 1.4: every pair within
               1.4 (ri + rj) bonded; the ratio of bonded spheres grows with their bonded
               coordination, docs/solver.md)
  ddem, ddem_range  deformable particles, nu_p 0.45, kn/(Ep l) at 0.85 of the admissible bound
               of both specimens (with the bonds at range for ddem_range): kt/kn 0.05, 0.3, 0.6
               x Rt/Rn 1, 4, 16
  rigid_jaws   the rigid grid with the Brazilian test between 30-degree jaws (as in 2D)

A model's region is, at each of its elastic sets (one nu), the interval of the ratio over its
strength parameters. The map is measured, not taken from the calibration maps: the map
specimens (0.3 of the particles) transfer the ratio poorly (at kt/kn 0.3, Rt/Rn 0.25 they
give 6.9 where the default specimen gives 11.2). The target rectangle of a reach (nu 0.05-0.40,
ratio 4-25; 3D nu 0.05-0.35, ratio 4-20) and the published rocks of data/materials/published/
are drawn on it.
"""
import argparse
import glob
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import calibration_bench as cb  # noqa: E402  (run_test, summary, calibrate, fresh_maps)

KN, RN, DENSITY = 3e10, 1e4, 2600.0
TARGETS = {2: ((0.05, 0.40), (4.0, 25.0)), 3: ((0.05, 0.35), (4.0, 20.0))}  # (nu, ratio) of a reach
MODELS = {
    "rigid": "rigid, contact bonds",
    "rigid_range": "rigid, bonds within range (gamma 1.4)",
    "moment": "rigid, bonds with a moment (lambda 1)",
    "ddem": "DDEM (nu_p 0.45)",
    "ddem_range": "DDEM (nu_p 0.45), bonds within range (gamma 1.4)",
    "rigid_jaws": "rigid, contact bonds, Brazilian jaws 30 deg",
    "ddem_jaws": "DDEM (nu_p 0.45), Brazilian jaws 30 deg",
    "lattice": "six-spring lattice",
}
DIMENSION_MODELS = {2: ("rigid", "moment", "ddem", "rigid_jaws", "ddem_jaws", "lattice"),
                    3: ("rigid", "rigid_range", "ddem", "ddem_range", "rigid_jaws")}
DEFAULT_MODELS = {2: "rigid,moment,ddem,lattice", 3: "rigid,rigid_range,ddem_range"}
LOADING_ARC = 30.0  # the jaws of the *_jaws models [degrees]
BOND_RANGE = 1.4  # gamma of the *_range models
TWIN_3D = os.path.join("bench-out", "calibration3d", "twin3d_01")  # the default 3D specimens


def bonded_scene(packing, kind, material, name, elastic, loading_arc=0.0):
    lines = ["[specimen]", 'packing = "%s"' % packing, "scale_density = true", "", "[material]"]
    lines += ["%s = %r" % (k, v) for k, v in material.items()]
    lines += ["", "[test]", 'kind = "%s"' % kind, "threads = 1"]
    lines += ["loading_arc = %g" % loading_arc] if loading_arc > 0 else []
    lines += ["strain_limit = 1.5e-3", "sample_interval = 50"] if elastic else ["strain_limit = 0.05"]
    lines += ["", "[output]", 'name = "%s"' % name, "pictures = false", "snapshots = false", ""]
    return "\n".join(lines)


def lattice_scene(packing, kind, material, name):
    lines = ["[specimen]", 'packing = "%s"' % packing, "", "[material]", 'model = "lattice"',
             'plane_model = "plane_strain"']
    lines += ["%s = %r" % (k, v) for k, v in material.items()]
    lines += ["", "[test]", 'kind = "%s"' % kind, "threads = 1", "", "[output]", 'name = "%s"' % name,
              "pictures = false", "snapshots = false", ""]
    return "\n".join(lines)


def launch(build, text, directory, name):
    os.makedirs(directory, exist_ok=True)
    return cb.run_test(build, text, directory, name)


def finish(process, directory, name, allowed=(0,)):
    status = process.wait()
    path = os.path.join(directory, name + "_summary.json")
    if status not in allowed or not os.path.exists(path):
        return None, "exit %d: %s" % (status, process.stderr.read().strip().splitlines()[-1:] or "")
    return cb.summary(directory, name), None


def strength_pair(build, packings, material, directory, tag, scene=bonded_scene, loading_arc=0.0, ucs=None):
    """UCS and Brazilian strength at one point, the two tests at once (the UCS not run when
    given: a point measured with flat platens)."""
    u = None
    if scene is bonded_scene:
        if ucs is None:
            u = launch(build, bonded_scene(packings[0], "ucs", material, "ucs_" + tag, False), directory, "ucs_" + tag)
        b = launch(build, bonded_scene(packings[1], "brazilian", material, "bts_" + tag, False, loading_arc),
                   directory, "bts_" + tag)
    else:
        u = launch(build, lattice_scene(packings[0], "ucs", material, "ucs_" + tag), directory, "ucs_" + tag)
        b = launch(build, lattice_scene(packings[1], "brazilian", material, "bts_" + tag), directory, "bts_" + tag)
    ru, eu = finish(u, directory, "ucs_" + tag) if u else ({"peak_stress_pa": ucs}, None)
    rb, eb = finish(b, directory, "bts_" + tag)
    if eu or eb:
        return None, "UCS %s, Brazilian %s" % (eu or "ok", eb or "ok")
    return (ru["peak_stress_pa"], rb["tensile_strength_pa"]), None


def elastic_nu(build, packing, material, directory, tag):
    """nu (2D: plane strain) of the intact specimen: the elastic run, bonds unbreakable."""
    e = launch(build, bonded_scene(packing, "ucs", material, "elastic_" + tag, True), directory, "elastic_" + tag)
    # An elastic run has no peak by design: run-test says so with status 4.
    r, error = finish(e, directory, "elastic_" + tag, allowed=(0, 4))
    if error:
        raise RuntimeError("elastic run %s failed: %s" % (tag, error))
    return r["linear_elastic"]["poisson_ratio"]


def admissible_compliance(build, packings, nu_p, directory, bond_range=1.0):
    """kn/(Ep l) at rho(B) = 0.9 on both specimens (stability-limit, the bonds at range counted),
    the lower of the two. In 3D l is a packing's volume-mean radius: a bound is carried to the
    UCS specimen's l, as one Ep serves both specimens (in 2D l = 1 m on both)."""
    bounds = []
    for k, packing in enumerate(packings):
        out = os.path.join(directory, "stability_%d" % k if bond_range == 1.0 else
                           "stability_g%g_%d" % (bond_range, k))
        result = cb.run([os.path.join(build, "tools", "stability-limit"), "--packing", packing, "--kn", str(KN),
                         "--density", str(DENSITY), "--Ep", str(KN / 0.1), "--nu-p", str(nu_p), "--max-rho", "0.9",
                         "--output", out, "--quiet"]
                        + (["--bond-range", str(bond_range)] if bond_range != 1.0 else []))
        if result.returncode != 0:
            raise RuntimeError("stability-limit failed: " + result.stdout[-500:] + result.stderr[-500:])
        with open(os.path.join(out, "packing_stability.json")) as f:
            analysis = json.load(f)["analysis"]
        bounds.append((analysis["ddem_convergence"]["recommended_kn_over_ep"], analysis["scene"]["group_length_m"]))
    return min(c * length / bounds[0][1] for c, length in bounds)


def shown(path):
    """A path as the page gives it: from the repository's root when inside it."""
    path = os.path.abspath(path)
    inside = os.path.commonpath([path, ROOT]) == ROOT
    return os.path.relpath(path, ROOT) if inside else path


def read_packing(path):
    """Dimension, domain shape, particle count and volume-mean radius of a packing file."""
    info, radii, left = {"dimension": 2, "shape": "", "particles": 0}, [], 0
    with open(path) as f:
        for line in f:
            words = line.split()
            if left > 0:
                radii.append(float(words[-1]))
                left -= 1
            elif words[:1] == ["dimension"]:
                info["dimension"] = int(words[1])
            elif words[:1] == ["domain"]:
                info["shape"] = words[1]
            elif words[:1] == ["particles"]:
                info["particles"] = left = int(words[1])
    d = info["dimension"]
    info["volume_mean_radius"] = (sum(r ** d for r in radii) / max(1, len(radii))) ** (1.0 / d)
    return info


def scales(dimension, packing, bond_strain=1.0):
    """kn, Rn and l of the grids: in 2D per metre of thickness (l = 1 m); in 3D on spheres of
    the UCS specimen's volume-mean radius l, the 2D grid's kn / l and bond strain at failure
    Rn / (kn l) (of 2D discs of cb.MEAN_RADIUS_2D). `bond_strain` multiplies Rn (--bond-strain)."""
    if dimension == 2:
        return KN, RN * bond_strain, 1.0
    length = read_packing(packing)["volume_mean_radius"]
    return KN * length, bond_strain * RN * length ** 2 / cb.MEAN_RADIUS_2D, length


def ends(values, quick):
    """The grid, or in a smoke test (--quick) its two ends."""
    return (values[0], values[-1]) if quick else values


def lattice_map_rows(path):
    """The points of a stored lattice strength map (calibrate/lattice_strength_map.h) as rows."""
    with open(path) as f:
        m = json.load(f)
    rows = []
    for p in m["points"]:
        s = p["tensile_over_cohesion"]
        rows.append({"model": "lattice", "poisson_ratio": p["poisson_ratio"], "friction_angle_deg": p["friction_angle_deg"],
                     "tensile_over_cohesion": s, "ucs_over_cohesion": p["ucs_over_cohesion"],
                     "bts_over_tensile": p["bts_over_tensile"], "seconds": p.get("seconds", 0.0),
                     "strength_ratio": p["ucs_over_cohesion"] / (p["bts_over_tensile"] * s)})
    return rows


def measure(build, packings, models, out, quick=False, known=(), dimension=2, bond_strain=1.0,
            stiffness_ratios=None):
    """Every point of every model's grid: rows of (model, elastic set, strength set, nu, ratio).
    `known`: rows of an earlier run, whose flat-platen UCS and nu the *_jaws models take.
    `stiffness_ratios`: the kt/kn levels of every bonded grid instead of the grids' own."""
    rows = []
    runs = os.path.join(out, "runs")
    kn, rn, length = scales(dimension, packings[0], bond_strain)

    def flat_row(model, s, x):
        """The flat-platen model's measured row of this point (this run first), or None."""
        for r in list(rows) + list(known):
            if r["model"] == model and r.get("kt_over_kn") == s and r.get("rt_over_rn") == x and "ucs_pa" in r:
                return r
        return None

    def record(row, measured, start):
        strengths, error = measured
        row["seconds"] = time.monotonic() - start
        if strengths:
            row.update(ucs_pa=strengths[0], tensile_strength_pa=strengths[1],
                       strength_ratio=strengths[0] / strengths[1])
        else:
            row["failure"] = error
        rows.append(row)
        report(row)

    def bonded(model, stiffness_ratios, strength_ratios, extra, flat_model=None):
        arc = LOADING_ARC if flat_model else 0.0
        for s in ends(stiffness_ratios, quick):
            base = {"normal_stiffness": kn, "tangential_stiffness": s * kn, "friction_coefficient": 0.8,
                    "density": DENSITY}
            base.update(extra)
            tag = "%s_s%g" % (model, s)
            flats = {x: flat_row(flat_model, s, x) if flat_model else None for x in ends(strength_ratios, quick)}
            known_nu = [r["poisson_ratio"] for r in flats.values() if r]
            nu = known_nu[0] if known_nu else elastic_nu(build, packings[0], base, runs, tag)
            for x in ends(strength_ratios, quick):
                start = time.monotonic()
                m = dict(base, bond_tensile_strength=rn, bond_shear_strength=x * rn)
                flat = flats[x]
                record({"model": model, "kt_over_kn": s, "rt_over_rn": x, "poisson_ratio": nu},
                       strength_pair(build, packings, m, runs, "%s_x%g" % (tag, x), loading_arc=arc,
                                     ucs=flat["ucs_pa"] if flat else None), start)

    if dimension == 3:
        rigid_grid, ddem_grid = ((0.1, 0.3, 0.6, 0.9), (0.5, 2.0, 6.0, 20.0)), ((0.05, 0.3, 0.6), (1.0, 4.0, 16.0))
    else:
        rigid_grid, ddem_grid = ((0.1, 0.2, 0.4, 0.9), (0.25, 1.0, 3.16, 10.0, 30.0)), ((0.05, 0.15, 0.3, 0.6),
                                                                                        (1.0, 3.16, 10.0))
    moment_grid = ((0.1, 0.2, 0.4, 0.9), (0.5, 1.0, 3.16, 10.0))
    if stiffness_ratios:
        rigid_grid, ddem_grid, moment_grid = ((tuple(stiffness_ratios), g[1]) for g in (rigid_grid, ddem_grid,
                                                                                        moment_grid))
    if "rigid" in models:
        bonded("rigid", *rigid_grid, {})
    if "rigid_range" in models:
        bonded("rigid_range", *rigid_grid, {"bond_range": BOND_RANGE})
    if "rigid_jaws" in models:
        bonded("rigid_jaws", *rigid_grid, {}, flat_model="rigid")
    if "moment" in models:
        bonded("moment", *moment_grid, {"bond_radius_ratio": 1.0})
    for model in ("ddem", "ddem_range", "ddem_jaws"):
        if model not in models:
            continue
        gamma = BOND_RANGE if model == "ddem_range" else 1.0
        compliance = 0.85 * admissible_compliance(build, packings, 0.45, runs, gamma)
        extra = {"particle_youngs_modulus": kn / (compliance * length), "particle_poisson_ratio": 0.45}
        if gamma != 1.0:
            extra["bond_range"] = gamma
        for s in ends(ddem_grid[0], quick):
            bonded(model, (s,), ddem_grid[1], dict(extra), flat_model="ddem" if model == "ddem_jaws" else None)
        for r in rows:
            if r["model"] == model:
                r["kn_over_ep_l"] = compliance
    if "lattice" in models:
        cohesion = 30e6
        for nu in ends((0.05, 0.15, 0.25, 0.35, 0.45), quick):
            for phi in ends((10.0, 30.0, 50.0), quick):
                for share in ends((0.05, 0.2, 2.0), quick):
                    start = time.monotonic()
                    m = {"youngs_modulus": 40e9, "poisson_ratio": nu, "tensile_strength": share * cohesion,
                         "cohesion": cohesion, "friction_angle": phi, "density": DENSITY}
                    tag = "lattice_nu%g_phi%g_t%g" % (nu, phi, share)
                    record({"model": "lattice", "poisson_ratio": nu, "friction_angle_deg": phi,
                            "tensile_over_cohesion": share},
                           strength_pair(build, packings, m, runs, tag, scene=lattice_scene), start)
    return rows


def report(row):
    ratio = row.get("strength_ratio")
    print("  %-8s nu %.3f  ratio %s  (%s)  %.0f s" % (
        row["model"], row["poisson_ratio"], "%.2f" % ratio if ratio else "-",
        ", ".join("%s %g" % (k, row[k]) for k in ("kt_over_kn", "rt_over_rn", "friction_angle_deg",
                                                  "tensile_over_cohesion") if k in row),
        row["seconds"]), flush=True)


def regions(rows):
    """Per model and elastic set (one nu): the interval of the ratio over the strength axis."""
    out = {}
    for r in rows:
        if "strength_ratio" not in r:
            continue
        key = (r["model"], round(r["poisson_ratio"], 4))
        lo, hi = out.get(key, (math.inf, -math.inf))
        out[key] = (min(lo, r["strength_ratio"]), max(hi, r["strength_ratio"]))
    table = {}
    for (model, nu), (lo, hi) in sorted(out.items()):
        table.setdefault(model, []).append({"poisson_ratio": nu, "ratio_min": lo, "ratio_max": hi})
    return table


def covers(table, nu, ratio):
    """The models whose region holds (nu, ratio): between two elastic sets, the intervals
    interpolated linearly in nu (log of the ratio); outside the sets' nu, nothing."""
    inside = []
    for model, sets in table.items():
        sets = sorted(sets, key=lambda s: s["poisson_ratio"])
        for a, b in zip(sets, sets[1:] if len(sets) > 1 else sets):
            lo_nu, hi_nu = a["poisson_ratio"], b["poisson_ratio"]
            if not lo_nu <= nu <= hi_nu:
                continue
            t = 0.0 if hi_nu == lo_nu else (nu - lo_nu) / (hi_nu - lo_nu)
            low = math.exp((1 - t) * math.log(a["ratio_min"]) + t * math.log(b["ratio_min"]))
            high = math.exp((1 - t) * math.log(a["ratio_max"]) + t * math.log(b["ratio_max"]))
            if low <= ratio <= high:
                inside.append(model)
                break
    return inside


def published_rocks():
    rocks = []
    for path in sorted(glob.glob(os.path.join(ROOT, "data", "materials", "published", "*.toml"))):
        values = {}
        with open(path) as f:
            for line in f:
                line = line.split("#")[0].strip()
                if "=" in line:
                    k, v = (p.strip() for p in line.split("=", 1))
                    values[k] = v.strip('"')
        try:
            rocks.append({"name": values.get("name", os.path.basename(path)),
                          "poisson_ratio": float(values["poisson_ratio"]),
                          "strength_ratio": float(values["ucs"]) / float(values["tensile_strength"])})
        except (KeyError, ValueError):
            continue
    return rocks


def coverage(table, target):
    """Share of the target rectangle (uniform in nu and in log ratio) inside some model."""
    (nu_low, nu_high), (ratio_low, ratio_high) = target
    hits, total = 0, 0
    for i in range(36):
        nu = nu_low + (nu_high - nu_low) * i / 35.0
        for j in range(41):
            ratio = ratio_low * (ratio_high / ratio_low) ** (j / 40.0)
            total += 1
            hits += 1 if covers(table, nu, ratio) else 0
    return hits / total


def plot(table, rows, rocks, png, target, title, nu_label):
    """Regions as filled polygons (lower envelope over nu, then the upper one back), the
    measured points, the target rectangle and the published rocks."""
    base = os.path.splitext(png)[0]
    colours = {"rigid": "#4060a0", "rigid_range": "#60a040", "moment": "#40a060", "ddem": "#d08020",
               "ddem_range": "#b03060", "rigid_jaws": "#20a0c0", "ddem_jaws": "#c04020", "lattice": "#a040a0"}
    (nu_low, nu_high), (ratio_low, ratio_high) = target
    drawn = [m for m in MODELS if table.get(m)]
    with open(base + "_regions.dat", "w") as f, open(base + "_points.dat", "w") as g:
        for model in drawn:  # one block per model: gnuplot's index
            sets = sorted(table[model], key=lambda s: s["poisson_ratio"])
            polygon = [(s["poisson_ratio"], s["ratio_min"]) for s in sets]
            polygon += [(s["poisson_ratio"], s["ratio_max"]) for s in reversed(sets)]
            f.write("".join("%g %g\n" % p for p in polygon + polygon[:1]) + "\n\n")
            g.write("".join("%g %g\n" % (r["poisson_ratio"], r["strength_ratio"])
                            for r in rows if r["model"] == model and "strength_ratio" in r) + "\n\n")
    with open(base + "_rocks.dat", "w") as f:
        f.write("".join("%g %g\n" % (r["poisson_ratio"], r["strength_ratio"]) for r in rocks))
    plots = []
    for k, model in enumerate(drawn):
        plots.append("'%s_regions.dat' index %d using 1:2 with filledcurves closed lc rgb '%s' title '%s'" % (
            base, k, colours[model], MODELS[model]))
        plots.append("'%s_points.dat' index %d using 1:2 with points pt 7 ps 0.6 lc rgb '%s' notitle" % (
            base, k, colours[model]))
    plots.append("'%s_rocks.dat' using 1:2 with points pt 6 ps 1.6 lw 2 lc rgb '#d02020' "
                 "title 'published rocks'" % base)
    plots.append("1/0 with lines dt 2 lw 2 lc rgb '#202020' title 'target: nu %.2f-%.2f, ratio %g-%g'" % (
        nu_low, nu_high, ratio_low, ratio_high))
    script = "\n".join([
        "set terminal pngcairo size 1100,760 font ',11'", "set output '%s'" % png,
        "set logscale y", "set xrange [0:0.5]", "set yrange [2:60]", "set grid",
        "set xlabel '%s'" % nu_label, "set ylabel 'UCS / sigma_t (Brazilian)'",
        "set title '%s'" % title,
        "set key outside right top", "set style fill transparent solid 0.25 border",
        "set object 1 rect from %g,%g to %g,%g fs empty border lc rgb '#202020' dt 2 lw 2" % (
            nu_low, ratio_low, nu_high, ratio_high),
        "plot " + ", \\\n  ".join(plots), ""])
    result = subprocess.run(["gnuplot"], input=script, capture_output=True, text=True)
    if result.returncode != 0:
        print("gnuplot failed: " + result.stderr[-800:])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--dimension", type=int, choices=(2, 3), default=2,
                        help="2: the default 2D specimens; 3: a calibrator's 3D specimens (--packings, or those "
                             "of %s)" % TWIN_3D)
    parser.add_argument("--out", help="default bench-out/reach (2D), bench-out/reach3d (3D)")
    parser.add_argument("--packings", nargs=2, metavar=("UCS", "BTS"))
    parser.add_argument("--models", help="comma-separated; default %s (2D), %s (3D)" % (
        DEFAULT_MODELS[2], DEFAULT_MODELS[3]))
    parser.add_argument("--markdown", help="the page to write (default OUT/reach_map.md)")
    parser.add_argument("--picture", help="where to copy the picture (default: only OUT/reach_map.png)")
    parser.add_argument("--quick", action="store_true", help="the two ends of every grid axis: a smoke test")
    parser.add_argument("--lattice-map", metavar="JSON",
                        help="the lattice's points from this stored strength map instead of measuring them")
    parser.add_argument("--reuse", metavar="JSON",
                        help="an earlier run's reach_map.json: the points of the models not in --models are "
                             "taken from it (the page says which)")
    parser.add_argument("--bond-strain", type=float, default=1.0, metavar="FACTOR",
                        help="multiplies Rn, and so the bond strain at failure Rn / (kn l), of every grid "
                             "(default 1: 2D Rn %g N/m, kn %g N/m/m); in 3D the ratio of bonded spheres moves with "
                             "it" % (RN, KN))
    parser.add_argument("--stiffness-ratios", metavar="LIST",
                        help="comma-separated kt/kn levels of every bonded grid (rigid, moment, ddem and their "
                             "variants), each in (0, 1], instead of the grids' own")
    args = parser.parse_args()
    if not (args.bond_strain > 0.0):
        parser.error("--bond-strain: %g, must be > 0" % args.bond_strain)
    stiffness_ratios = None
    if args.stiffness_ratios:
        try:
            stiffness_ratios = sorted(float(v) for v in args.stiffness_ratios.split(","))
        except ValueError:
            parser.error("--stiffness-ratios: %r, must be comma-separated numbers" % args.stiffness_ratios)
        if not all(0.0 < v <= 1.0 for v in stiffness_ratios):
            parser.error("--stiffness-ratios: %s, each must lie in (0, 1]" % args.stiffness_ratios)
    dimension = args.dimension
    args.models = args.models or DEFAULT_MODELS[dimension]
    args.out = args.out or ("bench-out/reach" if dimension == 2 else "bench-out/reach3d")
    models = [m.strip() for m in args.models.split(",")]
    unknown = set(models) - set(MODELS)
    if unknown:
        parser.error("--models: unknown %s" % ", ".join(sorted(unknown)))
    elsewhere = [m for m in models if m not in DIMENSION_MODELS[dimension]]
    if elsewhere:
        parser.error("--models: %s not in %dD (there: %s)" % (", ".join(elsewhere), dimension,
                                                              ", ".join(DIMENSION_MODELS[dimension])))
    if args.lattice_map and dimension == 3:
        parser.error("--lattice-map: the lattice is 2D")
    earlier = []
    if args.reuse:
        with open(args.reuse) as f:
            before = json.load(f)
        if before.get("dimension", 2) != dimension:
            parser.error("--reuse: %s is a %dD map" % (args.reuse, before.get("dimension", 2)))
        if before.get("bond_strain", 1.0) != args.bond_strain:
            parser.error("--reuse: %s was measured with --bond-strain %g, not %g" % (
                args.reuse, before.get("bond_strain", 1.0), args.bond_strain))
        earlier = before["points"]
    build, out = os.path.abspath(args.build), os.path.abspath(args.out)

    packings = args.packings
    if not packings and dimension == 3:
        packings = [os.path.join(ROOT, TWIN_3D, "twin_%s.packing" % k) for k in ("ucs", "bts")]
        if not all(os.path.exists(p) for p in packings):
            parser.error("no --packings and no 3D specimens in %s: make them with `python3 tools/bench/"
                         "calibration_bench.py --only 3d --twins-3d 1 --count-3d 5000 --out bench-out/calibration3d`"
                         % TWIN_3D)
    os.makedirs(out, exist_ok=True)
    if not packings:
        reference = os.path.join(ROOT, "bench-out", "calibration", "reference")
        packings = [os.path.join(reference, "reference_ucs.packing"), os.path.join(reference, "reference_bts.packing")]
        if not all(os.path.exists(p) for p in packings):
            reference = os.path.join(out, "reference")
            print("making the calibrator's default specimens (one-round calibration of the Labra rock) ...", flush=True)
            cb.calibrate(build, os.path.join(ROOT, "data", "materials", "labra2012_rock.toml"), reference,
                         "reference", cb.fresh_maps(os.path.join(ROOT, "data", "maps"), os.path.join(out, "maps")),
                         ["--rounds", "1"])
            packings = [os.path.join(reference, "reference_ucs.packing"),
                        os.path.join(reference, "reference_bts.packing")]
    packings = [os.path.abspath(p) for p in packings]
    specimens = [read_packing(p) for p in packings]
    if any(s["dimension"] != dimension for s in specimens):
        parser.error("--packings: %s, not %dD" % (", ".join("%s is %dD" % (p, s["dimension"]) for p, s in zip(
            packings, specimens) if s["dimension"] != dimension), dimension))

    start = time.monotonic()
    measured = [m for m in models if not (m == "lattice" and args.lattice_map)]
    rows = measure(build, packings, measured, out, args.quick, known=earlier, dimension=dimension,
                   bond_strain=args.bond_strain, stiffness_ratios=stiffness_ratios)
    if "lattice" in models and args.lattice_map:
        rows += lattice_map_rows(args.lattice_map)
    reused = []
    if args.reuse:
        reused = sorted({r["model"] for r in earlier} - set(models), key=list(MODELS).index)
        rows = [r for r in earlier if r["model"] in reused] + rows
    table = regions(rows)
    rocks = published_rocks()
    for rock in rocks:
        rock["models"] = covers(table, rock["poisson_ratio"], rock["strength_ratio"])
    target = TARGETS[dimension]
    share = coverage(table, target)

    csv_path = os.path.join(out, "reach_map.csv")
    fields = ["model", "poisson_ratio", "kt_over_kn", "rt_over_rn", "kn_over_ep_l", "friction_angle_deg",
              "tensile_over_cohesion", "ucs_pa", "tensile_strength_pa", "strength_ratio", "seconds", "failure"]
    with open(csv_path, "w") as f:
        f.write(",".join(fields) + "\n")
        for r in rows:
            f.write(",".join(str(r.get(k, "")) for k in fields) + "\n")
    with open(os.path.join(out, "reach_map.json"), "w") as f:
        # 2D maps carry no dimension (those written before 3D had none).
        json.dump(dict({"dimension": 3} if dimension == 3 else {},
                       **({"bond_strain": args.bond_strain} if args.bond_strain != 1.0 else {}),
                       **({"stiffness_ratios": stiffness_ratios} if stiffness_ratios else {}),
                       specimens=packings, points=rows, regions=table,
                       published_rocks=rocks, target={"poisson_ratio": target[0], "strength_ratio": target[1]},
                       target_covered_share=share), f, indent=1)
    png = os.path.join(out, "reach_map.png")
    page = os.path.abspath(args.markdown or os.path.join(out, "reach_map.md"))
    if dimension == 2:
        nu_label = "nu (plane strain)"
        title = "Reach on the default 2D specimens (5,064-disc UCS, 3,940-disc Brazilian), measured"
    else:
        nu_label = "nu"
        described = "%s-sphere UCS %s and %s-sphere Brazilian disc" % (
            "{:,}".format(specimens[0]["particles"]), specimens[0]["shape"], "{:,}".format(specimens[1]["particles"]))
        title = "Reach on the 3D specimens (%s-sphere UCS, %s-sphere Brazilian), measured" % (
            "{:,}".format(specimens[0]["particles"]), "{:,}".format(specimens[1]["particles"]))
    plot(table, rows, rocks, png, target, title, nu_label)

    minutes = ("%.0f minutes for what it measured" % ((time.monotonic() - start) / 60) if measured
               else "nothing measured by it")
    if dimension == 2:
        md = ["# Reach map (2D, the calibrator's default specimens)", "",
              "Reproduce: `python3 tools/bench/reach_map.py --markdown tools/bench/reach_map.md "
              "--picture docs/images/reach_map.png%s` (%s; every model measured: about 75 minutes on 2 cores, 25 of "
              "them the lattice, 12 the jaws models). Every point is the "
              "elastic run, the UCS and the Brazilian test of run-test on the 5,064-disc UCS square and the "
              "3,940-disc Brazilian disc; the grids are in the script's header." % (
                  "".join(" --%s %s" % (k.replace("_", "-"), v) for k, v in (
                      ("models", args.models if args.models != DEFAULT_MODELS[2] else None),
                      ("bond_strain", "%g" % args.bond_strain if args.bond_strain != 1.0 else None),
                      ("stiffness_ratios", args.stiffness_ratios),
                      ("reuse", args.reuse and os.path.relpath(os.path.abspath(args.reuse), ROOT)),
                      ("lattice_map", args.lattice_map and os.path.relpath(os.path.abspath(args.lattice_map), ROOT)))
                      if v), minutes)]
        picture = "../../docs/images/reach_map.png"
    else:
        # What the page needs to be made again: the specimens, models and paths given, --quick.
        flags = " --dimension 3"
        flags += " --packings %s %s" % tuple(shown(p) for p in packings) if args.packings else ""
        flags += " --models " + args.models if args.models != DEFAULT_MODELS[3] else ""
        flags += " --bond-strain %g" % args.bond_strain if args.bond_strain != 1.0 else ""
        flags += " --stiffness-ratios %s" % args.stiffness_ratios if args.stiffness_ratios else ""
        for name, path in (("markdown", args.markdown), ("picture", args.picture), ("reuse", args.reuse)):
            flags += " --%s %s" % (name, shown(path)) if path else ""
        flags += " --quick" if args.quick else ""
        md = ["# Reach map (3D, %s)" % described, "",
              "Reproduce: `python3 tools/bench/reach_map.py%s` (%s). Every point is the elastic run, the UCS and the "
              "Brazilian test (flat platens; rigid_jaws: between 30-degree jaws) of run-test on the %s; kn / l = %g Pa and Rn / (kn l) = %.3g, %s"
              ", with l = %.3g mm the UCS specimen's volume-mean radius; the grids are in the script's header." % (
                  flags, minutes, described, KN, args.bond_strain * RN / (KN * cb.MEAN_RADIUS_2D),
                  "the 2D grid's" if args.bond_strain == 1.0 else "%g times the 2D grid's" % args.bond_strain,
                  1e3 * specimens[0]["volume_mean_radius"])]
        picture = os.path.relpath(os.path.abspath(args.picture) if args.picture else png, os.path.dirname(page))
    md[-1] += (("" if not reused else " Measured here: %s; taken from an earlier run (`--reuse`): %s." % (
        ", ".join(MODELS[m] for m in measured) or "none", ", ".join(MODELS[m] for m in reused)))
        + ("" if not args.lattice_map else " The lattice's points are those of its stored strength map, %s "
           "(`--lattice-map`)." % os.path.relpath(os.path.abspath(args.lattice_map), ROOT)))
    md += ["", "![reach map](%s)" % picture, "",
           "| model | %s | UCS / sigma_t at that nu: lowest - highest measured |" % nu_label, "|---|---|---|"]
    for model in MODELS:
        for s in table.get(model, []):
            md.append("| %s | %.3f | %.1f - %.1f |" % (MODELS[model], s["poisson_ratio"], s["ratio_min"], s["ratio_max"]))
    failures = [r for r in rows if "failure" in r]
    md += ["", "Share of the target rectangle (nu %.2f-%.2f x ratio %g-%g, uniform in nu and in the "
           "logarithm of the ratio) inside the region of at least one model: **%.0f %%**." % (
               target[0] + target[1] + (100 * share,)), "",
           "| published rock | nu | UCS / sigma_t | inside the region of |", "|---|---|---|---|"]
    for rock in rocks:
        md.append("| %s | %.2f | %.1f | %s |" % (rock["name"], rock["poisson_ratio"], rock["strength_ratio"],
                                              ", ".join(rock["models"]) or "**none**"))
    if failures:
        md += ["", "Points without a result: " + "; ".join(
            "%s %s" % (r["model"], r["failure"]) for r in failures)]
    md.append("")
    text = "\n".join(md)
    print("\n" + text)
    with open(page, "w") as f:
        f.write(text)
    if args.picture and os.path.exists(png):
        os.makedirs(os.path.dirname(os.path.abspath(args.picture)), exist_ok=True)
        with open(png, "rb") as src, open(args.picture, "wb") as dst:
            dst.write(src.read())
    print("written: %s, reach_map.json, reach_map.png" % csv_path)


if __name__ == "__main__":
    main()
