#!/usr/bin/env python3
"""Cross-code comparison of S3 intruder runs: oobleck against the authors' code (mpm_3d).

Reads the frames of each run — oobleck (RUN/frames/frame_*.h5, docs/output.md) or mpm_3d
(CASE/output/fpd.<id>.grains.<frame>.vtk, written by their DefaultVTK serializer for a case made
by bench/cross_code/mpm3d_case.py) — and bins the grain phase's point velocities, mass-weighted,
into the 1 mm grid cells (r, z from the axis and the container floor):

    u_c = sum_p m_p v_p / sum_p m_p   over the grain points p in cell c.

Relative L2 of a run a against the reference b (the authors' code) at one time, over the cells
occupied by grains in both, each cell counted once:

    L2(a, b) = sqrt(sum_c |u_a,c - u_b,c|^2) / sqrt(sum_c |u_b,c|^2)

for u = (u_r, u_z) and for u_z alone. Frames are paired by time (nearest within --time-tol).

Fronts (the same measure for both codes, from the binned field): g = -u_z / v0 (1 in material
moving down with the intruder). The intruder's flat end is at z_tip = bed - v0 t.
  longitudinal: on the axis column of cells (0 < r < h) walking down from the first cell centre
    below the tip, the first crossing of g = 0.5, linearly interpolated between cell centres;
    reported as the distance ahead of the tip, d_l = z_tip - z_front;
  transverse: on the row of cells whose centre is the first below the tip, walking outward from
    the first cell centre beyond the intruder's radius R, the first crossing of g = 0.5; r_front.
  A column or row that never crosses gives the last cell centre (the front at the wall).
  Fits: k_l = (d d_l/dt)/v0 (= v_fl/v0 - 1 in the lab frame), k_t = (d r_front/dt)/v0, least
  squares over the whole run and up to the time the first front reaches its farthest extent.

    /usr/bin/python3 tools/cross_code.py --ref mpm_3d=out/cross_code/mpm3d/phi047_v02 \\
        --run matched=out/cross_code/oobleck/phi047_v02/matched --v0 0.2 \\
        --times 0.002 0.004 0.008 [--csv-dir DIR]

Prints, per run, the relative L2 at --times and over all paired frames, and the fronts' fits of
every run and of the reference; --csv-dir writes l2_<run>.csv (every paired frame) and
fronts_<run>.csv.
"""
import argparse
import glob
import os
import re
import sys

import numpy as np

H = 0.001           # [m] cell
NR, NZ = 50, 35     # cells of the S3 grid
BED = 0.030         # [m] bed surface (initial tip height)
R_INT = 0.005       # [m] intruder radius


# ----------------------------------------------------------------------------------- readers
def read_vtk_points(path, want=("velocity", "mass", "active", "c")):
    """Legacy ASCII VTK of mpm_3d's DefaultVTK: positions and the requested point arrays."""
    with open(path) as f:
        lines = f.read().split("\n")
    m = re.search(r"Time:\s*([-+0-9.eE]+)", lines[1])
    t = float(m.group(1)) if m else float("nan")
    i = 2
    out = {}
    while i < len(lines):
        ln = lines[i].strip()
        if ln.startswith("POINTS"):
            n = int(ln.split()[1])
            out["position"] = np.loadtxt(lines[i + 1:i + 1 + n], ndmin=2)[:, :2]
            i += 1 + n
        elif ln.startswith("CELLS") or ln.startswith("CELL_TYPES"):
            i += 1 + int(ln.split()[1])
        elif ln.startswith("SCALARS"):
            name = ln.split()[1]
            if name in want:
                out[name] = np.array(lines[i + 2:i + 2 + n], dtype=float)
            i += 2 + n
        elif ln.startswith("VECTORS"):
            name = ln.split()[1]
            if name in want:
                out[name] = np.loadtxt(lines[i + 1:i + 1 + n], ndmin=2)
            i += 1 + n
        elif ln.startswith("TENSORS"):
            i += 1 + 4 * n
        else:
            i += 1
    return t, out


def load_mpm3d(case, dt):
    files = sorted(glob.glob(os.path.join(case, "output", "fpd.*.grains.*.vtk")))
    if not files:
        raise SystemExit(f"{case}: no output/fpd.*.grains.*.vtk frames")
    frames = []
    for p in files:
        t, d = read_vtk_points(p)
        act = d["active"] > 0.5
        # the header holds t before the step's increment; the state is that of t + dt
        frames.append(dict(time=t + dt, r=d["position"][act, 0], z=d["position"][act, 1],
                           ur=d["velocity"][act, 0], uz=d["velocity"][act, 1], m=d["mass"][act],
                           f=d["c"][act] if "c" in d else None))
    return frames


def load_oobleck(run):
    import h5py
    files = sorted(glob.glob(os.path.join(run, "frames", "frame_*.h5")))
    if not files:
        raise SystemExit(f"{run}: no frames/frame_*.h5")
    frames = []
    for p in files:
        with h5py.File(p, "r") as f:
            g = f["bodies/grains"]
            x, v = g["position"][:], g["velocity"][:]
            frames.append(dict(time=float(f.attrs["time"]), r=x[:, 0], z=x[:, 1], ur=v[:, 0], uz=v[:, 1],
                               m=g["mass"][:], f=g["f"][:] if "f" in g else None))
    return frames


def load(path, dt):
    if glob.glob(os.path.join(path, "frames", "frame_*.h5")):
        return load_oobleck(path)
    return load_mpm3d(path, dt)


# ----------------------------------------------------------------------------------- binning
def bin_frame(fr):
    """Mass-weighted mean grain velocity per cell: (mass, u_r, u_z), arrays [NZ, NR]."""
    ir = np.floor(fr["r"] / H).astype(int)
    iz = np.floor(fr["z"] / H).astype(int)
    ok = (ir >= 0) & (ir < NR) & (iz >= 0) & (iz < NZ)
    idx = iz[ok] * NR + ir[ok]
    w = fr["m"][ok]
    mass = np.bincount(idx, w, NR * NZ)
    mur = np.bincount(idx, w * fr["ur"][ok], NR * NZ)
    muz = np.bincount(idx, w * fr["uz"][ok], NR * NZ)
    with np.errstate(invalid="ignore", divide="ignore"):
        ur = np.where(mass > 0, mur / mass, np.nan)
        uz = np.where(mass > 0, muz / mass, np.nan)
    return mass.reshape(NZ, NR), ur.reshape(NZ, NR), uz.reshape(NZ, NR)


def window_mean(frames, binned, t, w):
    """Binned fields averaged over the frames with |time - t| <= w/2 (cells occupied in all)."""
    k = [j for j, f in enumerate(frames) if abs(f["time"] - t) <= w / 2 + 2e-5]
    if not k:
        return None
    mass = np.min([binned[j][0] for j in k], axis=0)
    ur = np.mean([binned[j][1] for j in k], axis=0)
    uz = np.mean([binned[j][2] for j in k], axis=0)
    return mass, ur, uz


def rel_l2(a, b):
    """(L2 of u, L2 of u_z, cells) of binned frame a against reference b over common cells."""
    ma, ura, uza = a
    mb, urb, uzb = b
    c = (ma > 0) & (mb > 0)
    du2 = (ura[c] - urb[c]) ** 2 + (uza[c] - uzb[c]) ** 2
    nb = urb[c] ** 2 + uzb[c] ** 2
    if not c.any() or nb.sum() == 0 or (uzb[c] ** 2).sum() == 0:
        return float("nan"), float("nan"), int(c.sum())
    l2u = np.sqrt(du2.sum() / nb.sum())
    l2z = np.sqrt(((uza[c] - uzb[c]) ** 2).sum() / (uzb[c] ** 2).sum())
    return l2u, l2z, int(c.sum())


# ----------------------------------------------------------------------------------- fronts
def crossing(xs, g, thr=0.5):
    """First x where g drops below thr walking along xs (linear between samples); NaN if g starts
    below it; the last x if it never does. Empty cells (NaN) end the walk there."""
    if len(g) == 0 or not np.isfinite(g[0]) or g[0] < thr:
        return float("nan")
    for k in range(1, len(g)):
        if not np.isfinite(g[k]):
            return xs[k - 1]
        if g[k] < thr:
            return xs[k - 1] + (g[k - 1] - thr) / (g[k - 1] - g[k]) * (xs[k] - xs[k - 1])
    return xs[-1]


def fronts(binned, t, v0):
    _, _, uz = binned
    g = -uz / v0
    tip = BED - v0 * t
    centres = (np.arange(NZ) + 0.5) * H
    below = np.nonzero(centres < tip)[0]
    if len(below) == 0:
        return float("nan"), float("nan")
    j0 = below[-1]
    # longitudinal: axis column, from the first centre below the tip downwards
    zs = centres[j0::-1]
    zf = crossing(zs, g[j0::-1, 0])
    d_l = tip - zf
    # transverse: row j0, from the first centre beyond R outwards
    rc = (np.arange(NR) + 0.5) * H
    i0 = int(np.searchsorted(rc, R_INT))
    r_f = crossing(rc[i0:], g[j0, i0:])
    return d_l, r_f


def fit(t, y, t_end=None):
    t, y = np.asarray(t), np.asarray(y)
    k = np.isfinite(y) & (t > 0)
    if t_end is not None:
        k &= t <= t_end + 1e-12
    if k.sum() < 3:
        return float("nan"), float("nan")
    A = np.vstack([t[k], np.ones(k.sum())]).T
    (s, c), res, *_ = np.linalg.lstsq(A, y[k], rcond=None)
    ss = ((y[k] - (s * t[k] + c)) ** 2).sum()
    st = ((y[k] - y[k].mean()) ** 2).sum()
    return s, (1 - ss / st) if st > 0 else float("nan")


def front_fits(ts, dl, rf, v0):
    """k_l, k_t and k_l/k_t over the whole run and up to the first front's farthest extent."""
    dl, rf = np.asarray(dl), np.asarray(rf)
    out = {}
    sl, r2l = fit(ts, dl)
    st, r2t = fit(ts, rf)
    out["whole"] = (sl / v0, st / v0, r2l, r2t, ts[-1])
    tl = ts[int(np.nanargmax(dl))] if np.isfinite(dl).any() else ts[-1]
    tt = ts[int(np.nanargmax(rf))] if np.isfinite(rf).any() else ts[-1]
    te = min(tl, tt)
    sl, r2l = fit(ts, dl, te)
    st, r2t = fit(ts, rf, te)
    out["to_farthest"] = (sl / v0, st / v0, r2l, r2t, te)
    return out


def plot_fronts(path, allfronts, v0):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    for name, (ts, dl, rf) in allfronts.items():
        ax[0].plot(np.asarray(ts) * 1e3, np.asarray(dl) * 1e3, ".-", label=name, lw=1)
        ax[1].plot(np.asarray(ts) * 1e3, (np.asarray(rf) - R_INT) * 1e3, ".-", label=name, lw=1)
    ax[0].set_ylabel("longitudinal front ahead of the tip [mm]")
    ax[1].set_ylabel("transverse front beyond r = R [mm]")
    for x in ax:
        x.set_xlabel("t [ms]")
        x.grid(alpha=0.3)
    ax[0].legend(fontsize=7)
    fig.suptitle(f"u_z = 0.5 v0 fronts from the grains' per-cell velocity (v0 = {v0} m/s)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_maps(path, times, ref, run, v0):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(3, len(times), figsize=(3.2 * len(times), 7.5), squeeze=False)
    ext = [0, NR * H * 1e3, 0, NZ * H * 1e3]
    for k, t in enumerate(times):
        maps = []
        for (name, frames, binned) in (ref, run):
            j = int(np.argmin([abs(f["time"] - t) for f in frames]))
            maps.append(-binned[j][2] / v0)
        for row, (m, title) in enumerate(((maps[0], ref[0]), (maps[1], run[0]), (maps[1] - maps[0], f"{run[0]} − {ref[0]}"))):
            im = ax[row, k].imshow(m, origin="lower", extent=ext, cmap="RdBu_r" if row == 2 else "viridis",
                                   vmin=-0.5 if row == 2 else 0, vmax=0.5 if row == 2 else 1.2)
            ax[row, k].set_title(f"{title}, {t * 1e3:g} ms", fontsize=8)
            ax[row, k].plot([0, R_INT * 1e3], [(BED - v0 * t) * 1e3] * 2, "w-", lw=2)
            ax[row, k].set_xlabel("r [mm]", fontsize=7)
            ax[row, k].set_ylabel("z [mm]", fontsize=7)
            ax[row, k].tick_params(labelsize=6)
            fig.colorbar(im, ax=ax[row, k], shrink=0.7)
    fig.suptitle("grains' −u_z / v0 per 1 mm cell (white: the intruder's flat end)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ----------------------------------------------------------------------------------- main
def main():
    ap = argparse.ArgumentParser(description="S3 cross-code comparison (docs/cross_code.md)")
    ap.add_argument("--ref", required=True, help="NAME=DIR of the reference run (the authors' code)")
    ap.add_argument("--run", action="append", default=[], help="NAME=DIR of a run compared with the reference")
    ap.add_argument("--v0", type=float, required=True)
    ap.add_argument("--dt", type=float, default=1e-6, help="mpm_3d's step (its frame times are t + dt)")
    ap.add_argument("--times", type=float, nargs="*", default=[0.002, 0.004, 0.008])
    ap.add_argument("--time-tol", type=float, default=2e-5, help="[s] pairing tolerance of frame times")
    ap.add_argument("--window", type=float, default=0.0,
                    help="[s] also compare fields averaged over the frames within +-window/2 of each of --times "
                         "(elastic waves ring through the bed; a snapshot catches their phase)")
    ap.add_argument("--t-max", type=float, default=float("inf"),
                    help="[s] last time of the frame mean (e.g. before a run fails)")
    ap.add_argument("--csv-dir")
    ap.add_argument("--plot-fronts", help="PNG: the fronts of the reference and every --run against time")
    ap.add_argument("--plot", help="PNG: u_z/v0 per cell of the reference, the first --run and their "
                                   "difference at --times")
    a = ap.parse_args()

    def parse(s):
        name, _, path = s.partition("=")
        return name, path

    ref_name, ref_dir = parse(a.ref)
    ref = load(ref_dir, a.dt)
    ref_b = [bin_frame(f) for f in ref]
    ref_t = np.array([f["time"] for f in ref])
    runs = [parse(s) for s in a.run]
    if a.csv_dir:
        os.makedirs(a.csv_dir, exist_ok=True)

    def front_series(name, frames, binned):
        ts = np.array([f["time"] for f in frames])
        fr = [fronts(b, t, a.v0) for b, t in zip(binned, ts)]
        dl, rf = [x[0] for x in fr], [x[1] for x in fr]
        if a.csv_dir:
            with open(os.path.join(a.csv_dir, f"fronts_{name}.csv"), "w") as f:
                f.write("time_s,tip_z_m,longitudinal_ahead_m,transverse_r_m\n")
                for t, x, y in zip(ts, dl, rf):
                    f.write(f"{t:.7g},{BED - a.v0 * t:.7g},{x:.6g},{y:.6g}\n")
        return ts, dl, rf

    allfronts = {ref_name: front_series(ref_name, ref, ref_b)}
    hdr = "  ".join(f"{t * 1e3:g} ms (u | u_z)" for t in a.times)
    print(f"relative L2 of the per-cell grain velocity against {ref_name} ({ref_dir}); cells occupied in both")
    tm = "end" if not np.isfinite(a.t_max) else f"{a.t_max * 1e3:g} ms"
    print(f"{'run':16s} {hdr}   mean over frames 0.5 ms–{tm} (u | u_z)")
    for name, path in runs:
        fr = load(path, a.dt)
        b = [bin_frame(f) for f in fr]
        allfronts[name] = front_series(name, fr, b)
        if a.plot and name == runs[0][0]:
            plot_maps(a.plot, a.times, (ref_name, ref, ref_b), (name, fr, b), a.v0)
        rows = []
        for f, bb in zip(fr, b):
            if f["time"] <= 0.0:
                continue  # the initial state (mpm_3d writes its first frame after one step)
            k = int(np.argmin(np.abs(ref_t - f["time"])))
            if abs(ref_t[k] - f["time"]) <= a.time_tol:
                l2u, l2z, n = rel_l2(bb, ref_b[k])
                rows.append((f["time"], ref_t[k], l2u, l2z, n))
        if a.csv_dir:
            with open(os.path.join(a.csv_dir, f"l2_{name}.csv"), "w") as f:
                f.write("time_s,ref_time_s,rel_l2_u,rel_l2_uz,cells\n")
                for r in rows:
                    f.write("%.7g,%.7g,%.5g,%.5g,%d\n" % r)
        cols = []
        for t in a.times:
            m = [r for r in rows if abs(r[0] - t) <= a.time_tol]
            cols.append(f"{m[0][2]:.3f} | {m[0][3]:.3f}" if m else "—")
        later = [r for r in rows if 5e-4 - 1e-9 <= r[0] <= a.t_max + 1e-9 and np.isfinite(r[2])]
        mean = (f"{np.mean([r[2] for r in later]):.3f} | {np.mean([r[3] for r in later]):.3f}"
                if later else "—")
        print(f"{name:16s} " + "  ".join(f"{c:>18s}" for c in cols) + f"   {mean}")
        if a.window > 0:
            wcols = []
            for t in a.times:
                fa = window_mean(fr, b, t, a.window)
                fb = window_mean(ref, ref_b, t, a.window)
                if fa is None or fb is None:
                    wcols.append("—")
                    continue
                l2u, l2z, _ = rel_l2(fa, fb)
                wcols.append(f"{l2u:.3f} | {l2z:.3f}")
            print(f"{'  ' + str(round(a.window * 1e3, 3)) + ' ms mean':16s} " + "  ".join(f"{c:>18s}" for c in wcols))
    if a.plot_fronts:
        plot_fronts(a.plot_fronts, allfronts, a.v0)
    print()
    print("u_z = 0.5 v0 fronts (binned per cell): k_l / k_t / ratio (R² long. / trans.; fit end)")
    print(f"{'run':16s} {'whole run':44s} to the first front's farthest extent")
    for name, (ts, dl, rf) in allfronts.items():
        ff = front_fits(ts, dl, rf, a.v0)
        cells = []
        for key in ("whole", "to_farthest"):
            kl, kt, r2l, r2t, te = ff[key]
            cells.append(f"{kl:6.2f} / {kt:5.2f} / {kl / kt:5.2f} ({r2l:4.2f} / {r2t:4.2f}; {te * 1e3:4.1f} ms)")
        print(f"{name:16s} {cells[0]:44s} {cells[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
