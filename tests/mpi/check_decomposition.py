#!/usr/bin/python3
"""Decomposed runs against one-rank runs (docs/mpi.md, "What is checked").

Runs `oobleck run` under mpirun on 1, 2 and 3 ranks (and 2 ranks x 2 threads) and checks that the
decomposition changes nothing but round-off: the same points, every point's mass bit for bit,
total mass and momentum, the scene's measurement, and every point's position, velocity and stress
after 200 steps (points matched by position; differences relative to the field's largest
magnitude). Also restarts on a different rank count, and bad input on several ranks.

usage: check_decomposition.py --oobleck BIN --case CASE --work DIR
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SETTLING_3D = os.path.join(ROOT, "scenes/verification/settling_3d.toml")
SETTLING_2D = os.path.join(ROOT, "scenes/verification/settling.toml")
# 200 steps (dt = 2.79e-5 s), frames at steps 0, 100 and 200, the average from step ~36 on.
SHORT = ["--set", "time.duration=0.0056", "--set", "analysis.average_from=0.001",
         "--set", "output.frame_interval=0.0028"]

failures = []
# Open MPI's shared-memory transport copies large messages with process_vm_readv (CMA), which
# containers without ptrace permission refuse; plain copies work everywhere.
MPI_ENV = dict(os.environ, OMPI_MCA_btl_vader_single_copy_mechanism="none")


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def oobleck(args, ranks, threads=1, timeout=300):
    """Run BIN run ARGS on `ranks` MPI ranks (0: without mpirun). Returns (status, stderr)."""
    cmd = [BIN, "run"] + args + ["--threads", str(threads), "--quiet"]
    if ranks > 0:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)] + cmd
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=MPI_ENV)
    return p.returncode, p.stderr


def run_ok(out, scene, ranks, threads=1, extra=()):
    shutil.rmtree(out, ignore_errors=True)
    rc, err = oobleck([scene, "--out", out] + SHORT + list(extra), ranks, threads)
    check(rc == 0, f"{os.path.basename(out)}: exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
    return out


def summary(d):
    with open(os.path.join(d, "summary.json")) as f:
        return json.load(f)


def last_series_row(d):
    with open(os.path.join(d, "series.csv")) as f:
        lines = [l for l in f.read().splitlines() if l and not l.startswith("#")]
    head = lines[0].split(",")
    return dict(zip(head, map(float, lines[-1].split(","))))


def final_frame(d):
    files = sorted(glob.glob(os.path.join(d, "frames", "frame_*.h5")))
    out = {}
    with h5py.File(files[-1], "r") as f:
        for body in f["bodies"]:
            g = f["bodies"][body]
            out[body] = {k: np.array(g[k]) for k in ("position", "velocity", "stress", "mass", "volume")}
    return out


def match(ref_x, x):
    """Index into ref_x of each point of x (nearest position; the caller checks that the match is
    one to one). Both sets sorted by their positions rounded to 1e-9 of the domain pair up all but
    the points whose coordinates straddle a rounding step; those few are matched by distance."""
    origin, size = ref_x.min(axis=0), max(np.ptp(ref_x, axis=0).max(), 1e-300)

    def order(p):
        q = np.round((p - origin) / size * 1e9)
        return np.lexsort(q.T[::-1])

    ia, ib = order(ref_x), order(x)
    idx = np.empty(len(x), dtype=np.int64)
    idx[ib] = ia
    far = np.nonzero(np.abs(ref_x[idx] - x).max(axis=1) > 1e-8 * size)[0]
    for s in range(0, len(far), 256):
        part = far[s:s + 256]
        idx[part] = ((x[part, None, :] - ref_x[None, :, :]) ** 2).sum(axis=2).argmin(axis=1)
    return idx


def compare(ref, run, label, settling_tol=1e-9, field_tol=1e-10, snapshots=0):
    a, b = summary(ref), summary(run)
    check(a["points"] == b["points"] and a["points_per_body"] == b["points_per_body"],
          f"{label}: points {b['points_per_body']} = {a['points_per_body']}")
    check(a["steps"] == b["steps"], f"{label}: steps {b['steps']} = {a['steps']}")
    if "settling_velocity" in a:
        va, vb = a["settling_velocity"], b["settling_velocity"]
        rel = abs(vb - va) / abs(va)
        check(rel <= settling_tol, f"{label}: settling_velocity {vb!r} vs {va!r}: relative {rel:.2e} <= {settling_tol:g}")
    for key in ("torque_inner", "torque_outer", "velocity_profile_rms_error"):
        if key in a:
            rel = abs(b[key] - a[key]) / abs(a[key])
            check(rel <= 1e-10, f"{label}: {key} {b[key]!r} vs {a[key]!r}: relative {rel:.2e} <= 1e-10")
    for key in ("final_depth", "final_velocity", "hub_height_final", "distance"):
        if key in a:
            # lengths relative to at least 1 mm, as the centres below (a wheel that has barely
            # moved travels 0.4 um in 200 steps)
            floor = 1e-3 if key in ("final_depth", "distance") else 1e-300
            rel = abs(b[key] - a[key]) / max(abs(a[key]), floor)
            check(rel <= field_tol, f"{label}: {key} {b[key]!r} vs {a[key]!r}: relative {rel:.2e} <= {field_tol:g}")
    ra, rb = last_series_row(ref), last_series_row(run)
    # Third bodies: centre (relative to the domain), contact force (relative to its largest
    # component), motor ω and torque, at the last row.
    groups = {}
    for key in ra:
        for prefix in ("centre_", "contact_force_", "omega_", "motor_torque_"):
            if key.startswith(prefix):
                groups.setdefault(key.rsplit("_", 1)[0] if prefix in ("centre_", "contact_force_") else key, []).append(key)
    for group, keys in groups.items():
        A, B = np.array([ra[k] for k in keys]), np.array([rb[k] for k in keys])
        scale = max(np.abs(A).max(), 1e-300)
        tol = field_tol
        if group.startswith("centre_"):
            scale = max(scale, 1e-3)
        if group.startswith("motor_torque_") and "omega_" + group[len("motor_torque_"):] in ra and "omega" in a:
            # I (omega* - omega)/dt: the round-off of the measured omega grows by omega*/|omega* - omega|
            w = ra["omega_" + group[len("motor_torque_"):]]
            tol = field_tol * max(1.0, abs(a["omega"]) / max(abs(a["omega"] - w), 1e-300))
        rel = np.abs(B - A).max() / scale
        check(rel <= tol, f"{label}: {group} {B.tolist()} vs {A.tolist()}: {rel:.1e} of its largest magnitude "
                          f"(<= {tol:.1e})")
    for key in ra:
        if key.startswith("mass_"):  # the same point masses (checked below) summed in another order
            n = a["points_per_body"][key[len("mass_"):]]
            rel, bound = abs(rb[key] - ra[key]) / ra[key], n * 2.2e-16
            check(rel <= bound, f"{label}: {key} {rb[key]!r} vs {ra[key]!r}: relative {rel:.1e} (<= {bound:.1e}, "
                                f"the round-off bound of a sum of {n} terms)")
    for body in [k[len("mass_"):] for k in ra if k.startswith("mass_")]:
        pa = np.array([ra[k] for k in ra if k.startswith(f"momentum_{body}_")])
        pb = np.array([rb[k] for k in rb if k.startswith(f"momentum_{body}_")])
        scale = ra[f"mass_{body}"] * max(ra[f"max_speed_{body}"], 1e-300)  # |P| <= M max|v|
        rel = np.abs(pb - pa).max() / scale
        check(rel <= 1e-12, f"{label}: momentum of {body} within {rel:.1e} of M max|v| (<= 1e-12)")
    compare_snapshots(ref, run, label, field_tol, snapshots)
    compare_frame_files(ref, run, label, field_tol)
    fa, fb = final_frame(ref), final_frame(run)
    for body in fa:
        xa, xb = fa[body]["position"], fb[body]["position"]
        idx = match(xa, xb)
        check(len(np.unique(idx)) == len(xa), f"{label}: {body}: every point matched once")
        check(np.array_equal(fb[body]["mass"], fa[body]["mass"][idx]), f"{label}: {body}: point masses bit for bit")
        for k in ("position", "velocity", "stress", "volume"):
            A, B = fa[body][k][idx], fb[body][k]
            if k == "position":  # relative to the domain's size
                scale = np.abs(xa).max()
            else:
                scale = max(np.abs(A).max(), 1e-300)
            rel = np.abs(B - A).max() / scale
            check(rel <= field_tol, f"{label}: {body} {k} after {a['steps']} steps: {rel:.1e} of its largest magnitude "
                                    f"(<= {field_tol:g})")


def frame_layout(path):
    """Every group and dataset of a frame file: name -> (shape, dtype, attributes but `xdmf`)."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            attrs = {k: (v.tolist() if hasattr(v, "tolist") else v) for k, v in obj.attrs.items() if k != "xdmf"}
            out[name] = (getattr(obj, "shape", None), str(getattr(obj, "dtype", "")), attrs)
        out["/"] = (None, "", {k: v for k, v in f.attrs.items()})
        f.visititems(visit)
    return out


def compare_frame_files(ref, run, label, field_tol):
    """The frames that the ranks wrote together (parallel HDF5) read as the one-rank run's: the
    same XDMF index, text for text; in every frame file the same groups, datasets (shape, type)
    and attributes; each body's vertex list 0..N-1; the final frame's nodal fields within
    field_tol of their largest magnitude."""
    with open(os.path.join(ref, "frames.xmf")) as fa, open(os.path.join(run, "frames.xmf")) as fb:
        check(fa.read() == fb.read(), f"{label}: frames.xmf is the one-rank run's, text for text")
    files = sorted(os.path.basename(f) for f in glob.glob(os.path.join(ref, "frames", "frame_*.h5")))
    other = sorted(os.path.basename(f) for f in glob.glob(os.path.join(run, "frames", "frame_*.h5")))
    check(files == other and len(files) > 0, f"{label}: frame files {len(other)} = {len(files)}")
    same = all(frame_layout(os.path.join(ref, "frames", n)) == frame_layout(os.path.join(run, "frames", n))
               for n in files if n in other)
    check(same, f"{label}: every frame file holds the one-rank run's groups, datasets and attributes")
    if not files or files != other:
        return
    with h5py.File(os.path.join(ref, "frames", files[-1]), "r") as fa, \
            h5py.File(os.path.join(run, "frames", files[-1]), "r") as fb:
        for body in fb["bodies"]:
            conn = np.array(fb["bodies"][body]["connectivity"])
            check(np.array_equal(conn, np.arange(len(conn))), f"{label}: {body}: vertex list 0..{len(conn) - 1}")
        if "grid" in fa:
            for k in fa["grid"]:
                A, B = np.array(fa["grid"][k]), np.array(fb["grid"][k])
                rel = np.abs(B - A).max() / max(np.abs(A).max(), 1e-300)
                check(rel <= field_tol, f"{label}: grid {k} {A.shape}: {rel:.1e} of its largest magnitude "
                                        f"(<= {field_tol:g})")


def compare_snapshots(ref, run, label, field_tol, expected):
    """The nodal snapshots (snapshot_<k>.csv): `expected` files in both runs, every column within
    field_tol of its largest magnitude plus the rounding of the file's 9 significant digits."""
    files = sorted(os.path.basename(f) for f in glob.glob(os.path.join(ref, "snapshot_*.csv")))
    other = sorted(os.path.basename(f) for f in glob.glob(os.path.join(run, "snapshot_*.csv")))
    check(len(files) == expected and files == other, f"{label}: snapshots {other} = {files} ({expected} expected)")
    for name in files:
        if name not in other:
            continue
        A = np.loadtxt(os.path.join(ref, name), delimiter=",", skiprows=2, ndmin=2)
        B = np.loadtxt(os.path.join(run, name), delimiter=",", skiprows=2, ndmin=2)
        if A.shape != B.shape:
            check(False, f"{label}: {name}: shape {B.shape} = {A.shape}")
            continue
        scale = np.maximum(np.abs(A).max(axis=0), 1e-300)
        excess = (np.abs(B - A) - 1.01e-8 * np.abs(A)) / scale
        check(excess.max() <= field_tol, f"{label}: {name} ({A.shape[0]} nodes): largest difference "
                                         f"{(np.abs(B - A) / scale).max():.1e} of its column's largest magnitude "
                                         f"(<= {field_tol:g} beyond the 9 digits' rounding)")


def compare_analysis(ref, run, label, keys, tol=1e-10):
    """Numbers of summary.json's analysis entries `keys` (nested lists and objects): each within
    tol of the largest magnitude of the list or object that holds it."""
    a, b = summary(ref), summary(run)
    worst = [0.0, ""]

    def walk(x, y, path, scale):
        if isinstance(x, dict):
            nums = [abs(v) for v in x.values() if isinstance(v, (int, float)) and not isinstance(v, bool)]
            inner = max(nums, default=0.0)
            for k in x:
                if k not in y:
                    check(False, f"{label}: {path}/{k} missing")
                    continue
                walk(x[k], y[k], f"{path}/{k}", inner)
        elif isinstance(x, list):
            if len(x) != len(y):
                check(False, f"{label}: {path}: {len(y)} entries, expected {len(x)}")
                return
            nums = [abs(v) for v in x if isinstance(v, (int, float)) and not isinstance(v, bool)]
            inner = max(nums, default=scale)
            for i, (u, v) in enumerate(zip(x, y)):
                walk(u, v, f"{path}[{i}]", inner)
        elif isinstance(x, (int, float)) and not isinstance(x, bool) and isinstance(y, (int, float)):
            rel = abs(y - x) / max(abs(x), scale, 1e-300)
            if rel > worst[0]:
                worst[:] = [rel, path]
        else:
            check(x == y, f"{label}: {path} = {y!r}, expected {x!r}")

    for key in keys:
        if key not in a:
            check(False, f"{label}: the one-rank summary has no '{key}'")
            continue
        walk(a[key], b.get(key), key, 0.0)
    check(worst[0] <= tol, f"{label}: {', '.join(keys)}: largest difference {worst[0]:.1e} (at {worst[1] or '-'}) "
                           f"of its entry or list (<= {tol:g})")


def case_settling_3d(work):
    ref = run_ok(os.path.join(work, "s3d_np0"), SETTLING_3D, 0)
    for ranks, threads, extra, name in [(1, 1, [], "np1"), (2, 1, [], "np2"), (3, 1, [], "np3"),
                                        (2, 2, [], "np2_t2"), (2, 1, ["--ranks-grid", "1x1x2"], "np2_grid112")]:
        run = run_ok(os.path.join(work, f"s3d_{name}"), SETTLING_3D, ranks, threads, extra)
        if ranks > 1 and not failures:
            s = summary(run)
            check(s["ranks"] == ranks and "ranks_grid" in s and s["points_per_rank"]["max"] < s["points"],
                  f"settling_3d {name}: summary has ranks {s['ranks']}, ranks_grid {s.get('ranks_grid')}, "
                  f"points_per_rank {s.get('points_per_rank')}")
        if not failures:
            compare(ref, run, f"settling_3d {name}")


def case_settling_2d(work):
    ref = run_ok(os.path.join(work, "s2d_np0"), SETTLING_2D, 0)
    for ranks, extra, name in [(2, [], "np2"), (3, [], "np3"), (3, ["--ranks-grid", "1x3"], "np3_grid13")]:
        run = run_ok(os.path.join(work, f"s2d_{name}"), SETTLING_2D, ranks, 1, extra)
        if not failures:
            compare(ref, run, f"settling 2D {name}")


def against_one_rank(work, scene, runs, snapshots=0):
    name = os.path.splitext(os.path.basename(scene))[0]
    ref = oobleck_plain(work, scene, name)
    for ranks, threads, grid, crossing_expected in runs:
        extra = ["--ranks-grid", grid] if grid else []
        tag = f"np{ranks}_t{threads}" + (f"_{grid}" if grid else "")
        out = os.path.join(work, f"{name}_{tag}")
        shutil.rmtree(out, ignore_errors=True)
        rc, err = oobleck([scene, "--out", out] + extra, ranks, threads)
        check(rc == 0, f"{name} {tag}: exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
        if rc != 0:
            continue
        s = summary(out)
        if crossing_expected:
            check(s["points_migrated"] > s["points"] // 10,
                  f"{name} {tag} ({s['ranks_grid']}): {s['points_migrated']} points crossed between ranks "
                  f"(> a tenth of {s['points']})")
        compare(ref, out, f"{name} {tag}", snapshots=snapshots)


def oobleck_plain(work, scene, name):
    out = os.path.join(work, f"{name}_np0")
    shutil.rmtree(out, ignore_errors=True)
    rc, err = oobleck([scene, "--out", out], 0)
    check(rc == 0, f"{name}: one-rank run, exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
    return out


def case_crossing_2d(work):
    against_one_rank(work, os.path.join(ROOT, "tests/mpi/crossing_2d.toml"),
             [(2, 1, None, True), (3, 1, "3x1", True), (3, 1, "1x3", False), (2, 2, None, True)], snapshots=2)


def case_crossing_3d(work):
    against_one_rank(work, os.path.join(ROOT, "tests/mpi/crossing_3d.toml"),
             [(2, 1, None, True), (3, 1, "3x1x1", True), (4, 1, "2x2x1", True), (2, 2, "1x2x1", True)])


def case_couette_axisym(work):
    """V3, axisymmetric with swirl (a driven inner wall, the axis-free gap split radially and
    axially), to its steady state (0.6 s, 30 000 steps)."""
    against_one_rank(work, os.path.join(ROOT, "scenes/verification/couette_axisym.toml"),
             [(2, 1, None, False), (3, 1, "3x1", False), (2, 1, "1x2", False)])


# The paper's scenes with third bodies, coarse and short (a few hundred steps), with their nodal
# snapshots (2D: intrusion, rod, wheel) at two times.
THIRD_BODY_SCENES = {
    # S3: the prescribed intruder (axisymmetric), 1 mm, 200 steps; its fronts' fields sampled twice.
    "intrusion": ("scenes/paper/intrusion.toml", ["--set", "duration=0.0002",
                                                  "--set", "analysis.snapshot_times=[0.0001, 0.0002]",
                                                  "--set", "output.frame_interval=0.0001"]),
    # S2: the free rod (axisymmetric), 4 mm cells, 300 steps.
    "rod": ("scenes/paper/rod_impact.toml", ["--set", "cell_size=0.004", "--set", "duration=0.0012",
                                             "--set", "analysis.snapshot_times=[0.0006, 0.0012]",
                                             "--set", "output.frame_interval=0.0006"]),
    # S2 in 3D: the rod tilted by 30 deg (an oblique launch at 2 m/s), 10 mm cells, the container
    # narrowed to 10 cm, 168 steps; the rod straddles the cuts at x = 0 and y = 0. (Two points per
    # cell: with one, the points sit on the quadratic stencil's tie at the cell centres, and the
    # free surface's stress depends on how the tie is broken even on one rank, e.g. when the grid's
    # origin moves by whole cells.)
    "rod_3d": ("scenes/paper/rod_impact_3d.toml", ["--set", "cell_size=0.01", "--set", "tilt_deg=30",
                                                   "--set", "v0=2", "--set", "duration=0.002",
                                                   "--set", "grid.origin=[-0.05, -0.05, 0.0]",
                                                   "--set", "grid.size=[0.1, 0.1, 0.14]",
                                                   "--set", "region.0.min=[-0.05, -0.05, 0.0]",
                                                   "--set", "region.0.max=[0.05, 0.05, 0.1]",
                                                   "--set", "output.frame_interval=0.001"]),
    # S4: the elastic wheel with its motor (plane strain, periodic track), 60 x 30 cells, 400 steps.
    "wheel": ("scenes/paper/wheel.toml", ["--set", "cells=[60, 30]", "--set", "duration=0.008",
                                          "--set", "analysis.snapshot_times=[0.004, 0.008]",
                                          "--set", "output.frame_interval=0.004",
                                          "--set", "analysis.sample_interval=0.002"]),
    # S4 in 3D, width-periodic (the plane-strain wheel in the 3D solver), 33 mm cells, 200 steps.
    "wheel_3d": ("scenes/paper/wheel_3d.toml", ["--set", "width_periodic=true", "--set", "cells=[60, 4, 30]",
                                                "--set", "duration=0.004", "--set", "output.frame_interval=0.002",
                                                "--set", "analysis.sample_interval=0.001"]),
}


def case_third_bodies(work, name, runs):
    scene, extra = THIRD_BODY_SCENES[name]
    scene = os.path.join(ROOT, scene)
    ref = os.path.join(work, f"{name}_np0")
    shutil.rmtree(ref, ignore_errors=True)
    rc, err = oobleck([scene, "--out", ref] + extra, 0)
    check(rc == 0, f"{name}: one-rank run, exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
    for ranks, threads, grid in runs:
        tag = f"np{ranks}_t{threads}" + (f"_{grid}" if grid else "")
        out = os.path.join(work, f"{name}_{tag}")
        shutil.rmtree(out, ignore_errors=True)
        rc, err = oobleck([scene, "--out", out] + extra + (["--ranks-grid", grid] if grid else []), ranks, threads)
        check(rc == 0, f"{name} {tag}: exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
        if rc == 0 and not failures:
            compare(ref, out, f"{name} {tag}", snapshots=2 if name in ("intrusion", "rod", "wheel") else 0)
            if name == "rod":  # the displacement profile below the rod, from the first snapshot
                compare_analysis(ref, out, f"{name} {tag}", ["displacement_below_rod"])
            a, b = summary(ref), summary(out)
            for body, pa in a.get("bodies", {}).items():
                pb = b["bodies"][body]
                check(pa["points"] == pb["points"] and
                      abs(pb["mass"] - pa["mass"]) <= pa["points"] * 2.2e-16 * pa["mass"],
                      f"{name} {tag}: body {body}: points {pb['points']}, mass {pb['mass']!r} vs {pa['mass']!r}")


def case_intrusion(work):
    case_third_bodies(work, "intrusion", [(2, 1, "2x1"), (3, 1, "1x3"), (2, 2, "1x2")])


def case_rod(work):
    case_third_bodies(work, "rod", [(2, 1, "1x2"), (3, 1, "3x1"), (2, 2, "2x1")])


def case_rod_3d(work):
    case_third_bodies(work, "rod_3d", [(2, 1, "2x1x1"), (3, 1, "1x1x3"), (2, 2, "1x2x1")])


def case_wheel_3d(work):
    case_third_bodies(work, "wheel_3d", [(2, 1, "2x1x1"), (3, 1, "3x1x1"), (2, 2, "1x1x2")])


def case_wheel(work):
    case_third_bodies(work, "wheel", [(2, 1, "2x1"), (3, 1, "3x1"), (2, 2, "1x2")])


def case_annular(work):
    """S1, the annular cell (axisymmetric with swirl, its bob turning the bed), 2 000 steps: the
    run against one rank, and the annular measurement (profiles, fronts) from every rank's nodes
    and points; split radially, axially and both, and with 2 threads per rank."""
    scene = os.path.join(ROOT, "scenes/paper/annular_shear.toml")
    extra = ["--set", "duration=0.02", "--set", "output.frame_interval=0.01"]
    ref = os.path.join(work, "annular_np0")
    shutil.rmtree(ref, ignore_errors=True)
    rc, err = oobleck([scene, "--out", ref] + extra, 0)
    check(rc == 0, f"annular: one-rank run, exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
    for ranks, threads, grid in [(2, 1, "1x2"), (3, 1, "3x1"), (2, 2, "2x1")]:
        tag = f"np{ranks}_t{threads}_{grid}"
        out = os.path.join(work, f"annular_{tag}")
        shutil.rmtree(out, ignore_errors=True)
        rc, err = oobleck([scene, "--out", out, "--ranks-grid", grid] + extra, ranks, threads)
        check(rc == 0, f"annular {tag}: exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
        if rc == 0 and not failures:
            compare(ref, out, f"annular {tag}")
            compare_analysis(ref, out, f"annular {tag}", ["profiles", "front", "structure_front", "outer_rotation"])


def case_restart(work):
    """Write a checkpoint on 2 ranks, continue on 1 and on 3: the uninterrupted run's results."""
    ref = run_ok(os.path.join(work, "r_full"), SETTLING_3D, 0)
    half = run_ok(os.path.join(work, "r_half"), SETTLING_3D, 2, 1, ["--stop-after", "100"])
    check(summary(half)["complete"] is False and os.path.exists(os.path.join(half, "checkpoint.h5")),
          "restart: the 2-rank run stopped after 100 steps with a checkpoint")
    # Written by both ranks together: each point array with a checksum per rank's block.
    with h5py.File(os.path.join(half, "checkpoint.h5"), "r") as f:
        x = f["arrays/body0/x"]
        blocks = x.attrs.get("block_values")
        check(blocks is not None and len(blocks) == 2 and int(sum(blocks)) == x.shape[0] and min(blocks) > 0,
              f"restart: body0/x written by 2 ranks (blocks {None if blocks is None else blocks.tolist()} "
              f"of {x.shape[0]} values)")
    # A changed value in rank 1's block fails that block's checksum.
    bad = os.path.join(work, "r_damaged")
    shutil.rmtree(bad, ignore_errors=True)
    shutil.copytree(half, bad)
    with h5py.File(os.path.join(bad, "checkpoint.h5"), "r+") as f:
        x = f["arrays/body0/x"]
        x[x.shape[0] - 1] = x[x.shape[0] - 1] + 1e-9
    rc, err = oobleck(["--restart", bad], 1)
    said = [l for l in err.splitlines() if "checksum" in l]
    check(rc != 0 and any("body0/x' fails its checksum" in l for l in said),
          f"restart: a damaged block is refused (status {rc}: {said[0].strip() if said else err[-300:]})")
    for ranks in (1, 3):
        d = os.path.join(work, f"r_on{ranks}")
        shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(half, d)
        rc, err = oobleck(["--restart", d], ranks)
        check(rc == 0, f"restart on {ranks} rank(s): exit status {rc}" + ("" if rc == 0 else f"\n{err[-2000:]}"))
        if rc == 0:
            check(summary(d)["steps"] == summary(ref)["steps"], f"restart on {ranks}: ran to step {summary(ref)['steps']}")
            compare(ref, d, f"restart 2 -> {ranks} ranks", settling_tol=1e-10)


def case_killed_rank(work):
    """Kill rank 1 of 2 with SIGKILL mid-run (after a few checkpoints): every rank stops, and the
    checkpoint on disk is a complete one that continues to the uninterrupted run's results."""
    import signal
    import time
    scene = os.path.join(ROOT, "tests/mpi/crossing_3d.toml")
    longer = ["--set", "time.duration=0.05", "--checkpoint-every", "100"]
    ref = os.path.join(work, "k_full")
    shutil.rmtree(ref, ignore_errors=True)
    rc, err = oobleck([scene, "--out", ref] + longer, 0)
    check(rc == 0, f"killed_rank: uninterrupted run, exit status {rc}")
    d = os.path.join(work, "k_killed")
    shutil.rmtree(d, ignore_errors=True)
    cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", "2", BIN, "run", scene, "--out", d,
           "--threads", "1", "--quiet"] + longer
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=MPI_ENV)
    victim = None
    deadline = time.time() + 120
    while time.time() < deadline and p.poll() is None:
        if victim is None:
            for pid in os.listdir("/proc"):
                if not pid.isdigit():
                    continue
                try:
                    with open(f"/proc/{pid}/environ", "rb") as f:
                        env = f.read().split(b"\0")
                except OSError:
                    continue
                if b"OMPI_COMM_WORLD_RANK=1" in env and any(e.startswith(b"OMPI_") for e in env):
                    try:
                        with open(f"/proc/{pid}/cmdline", "rb") as f:
                            if b"crossing_3d" in f.read():
                                victim = int(pid)
                    except OSError:
                        pass
        # after the second checkpoint (step 200): kill rank 1 between checkpoints
        if victim and os.path.exists(os.path.join(d, "checkpoint.h5")) and os.path.getmtime(
                os.path.join(d, "checkpoint.h5")) > os.path.getmtime(os.path.join(d, "scene.toml")) + 0.2:
            os.kill(victim, signal.SIGKILL)
            break
        time.sleep(0.05)
    _, err = p.communicate(timeout=120)
    check(victim is not None, "killed_rank: found rank 1's process")
    check(p.returncode != 0, f"killed_rank: mpirun exit status {p.returncode} (non-zero)")
    check(not os.path.exists(os.path.join(d, "summary.json")), "killed_rank: no summary.json (the run did not finish)")
    rc, err = oobleck(["--restart", d], 2)
    check(rc == 0, f"killed_rank: the checkpoint left behind continues on 2 ranks (status {rc})" +
          ("" if rc == 0 else f"\n{err[-1500:]}"))
    if rc == 0:
        compare(ref, d, "killed_rank: continued run", settling_tol=1e-10)


def expect_refused(work, name, args, ranks, message):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    rc, err = oobleck([SETTLING_3D, "--out", out] + args, ranks)
    check(rc != 0 and message in err, f"{name}: refused (status {rc}) with '{message}'" +
          ("" if message in err else f"\n{err[-1500:]}"))
    check(not os.path.exists(out), f"{name}: no run folder written")


def case_bad_input(work):
    expect_refused(work, "bad_grid_count", ["--ranks-grid", "3x1x1"], 2, "3 ranks in the grid, but the run has 2")
    expect_refused(work, "bad_thin_block", ["--ranks-grid", "2x1x1"], 2, "a block needs at least 3 cells")
    expect_refused(work, "bad_too_many_ranks", [], 7, "the grid (4x4x20 cells) is too small")
    expect_refused(work, "bad_grid_one_rank", ["--ranks-grid", "1x1x2"], 0, "this run has 1 (start it with mpirun -np 2)")
    expect_refused(work, "bad_grid_syntax", ["--ranks-grid", "2x"], 2, "expected 3 positive factors")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--oobleck", required=True)
    ap.add_argument("--case", required=True, choices=["settling_3d", "settling_2d", "crossing_2d", "crossing_3d", "couette_axisym", "restart",
                                                      "bad_input", "killed_rank", "intrusion", "rod", "rod_3d", "wheel", "wheel_3d",
                                                      "annular"])
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    BIN = os.path.abspath(args.oobleck)
    os.makedirs(args.work, exist_ok=True)
    globals()["case_" + args.case](args.work)
    print(f"{len(failures)} failure(s)")
    sys.exit(1 if failures else 0)
