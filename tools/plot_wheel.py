#!/usr/bin/python3
"""Paper Figs. 11-12 and the SI pressure-field figure from two wheel runs (scenes/paper/wheel.toml,
spec S4), e.g. omega = 10 (fast) and omega = 1 (slow).

usage: plot_wheel.py OUT_PREFIX RUN_FAST RUN_SLOW
       plot_wheel.py --stiffness OUT_PNG RUN [RUN ...]
writes OUT_PREFIX_track.png     hub height and distance travelled vs time for both runs, with the bed
                                surface and surface -/+ wheel radius;
       OUT_PREFIX_fast.png      f at each snapshot of RUN_FAST with the phi = 0.1 free-surface contour
       OUT_PREFIX_slow.png      and velocity arrows (length 1.215 v sqrt(R/g), as in the paper);
       OUT_PREFIX_pressure.png  granular pressure p_grains under the wheel at the snapshot nearest
                                t = 1 s, both runs.
The grid is periodic in x; each field panel is shifted periodically to centre the hub (x labels are
unwrapped positions). The wheel outline is drawn rigid, at the hub position of series.csv, rotated by
the integral of the measured mean angular velocity (an estimate: the wheel is elastic).
A run without summary.json (still running) is read from series.csv and scene.toml instead.

--stiffness: the SI's ringing figure. The granular pressure p~ of every grain point under the wheel
(two radii either side of it, from three radii below to one above: the window of the run's
`pressure_scatter`) in the HDF5 frame nearest t = 1 s of each run, e.g. runs of the fast wheel with
the granular moduli G, K multiplied by 1, 10 and 100; each panel gives E = 9KG/(3K + G), the time
step, and the within-cell scatter of p~ (docs/analysis.md, "Wheel") at that frame and pooled over the
run, from its summary.json; one colour scale for all panels. Needs h5py (Debian: python3-h5py).
"""
import csv
import glob
import math
import os
import re
import sys

import numpy as np
from oobleck_plot import load_scene, load_summary, need_file, plt, read_snapshot, run_title, save

PHI_SURFACE = 0.1
G = 9.81


def read_series(path):
    """series.csv -> dict of column name -> list of floats ('#' lines, the units line, skipped)."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    if not rows:
        raise SystemExit(f"{path}: no data rows")
    return {k: [float(r[k]) for r in rows] for k in rows[0].keys()}


class Run:
    """What the figures need from one wheel run folder, from summary.json or, failing that, from
    series.csv + scene.toml."""

    def __init__(self, path):
        self.path = path
        self.name = os.path.basename(path.rstrip("/"))
        self.s = load_summary(path, required=False)
        self.scene = load_scene(path)
        series_path = need_file(os.path.join(path, "series.csv"), "the run's time series")
        cols = read_series(series_path)
        for c in ("time", "centre_wheel_0", "centre_wheel_1", "omega_wheel"):
            if c not in cols:
                raise SystemExit(f"{series_path}: no column {c!r} (is this a wheel run?)")
        self.series = {k: np.asarray(v) for k, v in cols.items()}
        body = next((b for b in self.scene.get("body", []) or [] if b.get("shape") == "wheel"), {})
        self.body = body
        grid = self.scene.get("grid", {})
        if self.s is not None:
            p = self.s.get("parameters", {})
            self.width = p["cells"][0] * p["cell_size"] if p.get("cells") and p.get("cell_size") else None
        else:
            self.width = grid.get("size", [None])[0]
        if self.s is None:
            regions = self.scene.get("region", []) or [{}]
            self.s = {
                "scene": self.scene.get("scene", {}).get("name", "wheel") + " (running: series.csv)",
                "parameters": {
                    "phi": regions[0].get("phi", "?"),
                    "eta_0": self.scene.get("fluid", {}).get("eta_0", float("nan")),
                    "K_0": self.scene.get("material", {}).get("granular", {}).get("K_0", "?"),
                    "cells": grid.get("cells"),
                    "cell_size": grid.get("cell_size") or (grid["size"][0] / grid["cells"][0]
                                                           if grid.get("cells") and grid.get("size") else None),
                },
                "bed_surface": regions[0].get("max", [None, None])[1],
                "omega": body.get("motor_omega"),
                "wheel_radius": (body["hub_radius"] + body["paddle_length"]) if "hub_radius" in body
                and "paddle_length" in body else None,
            }
            self.from_series = True
        else:
            self.from_series = False
        if self.width is None:
            self.width = 2.0
        self.omega = self.s.get("omega")
        self.radius = self.s.get("wheel_radius")
        self.surface = self.s.get("bed_surface")
        # unwrapped hub x and its rotation angle (trapezoid integral of the measured omega)
        t = self.series["time"]
        xw = self.series["centre_wheel_0"]
        self.x_unwrapped = np.unwrap(xw * 2 * math.pi / self.width) * self.width / (2 * math.pi)
        om = self.series["omega_wheel"]
        self.angle = np.concatenate([[0.0], np.cumsum(0.5 * (om[1:] + om[:-1]) * np.diff(t))])

    def label(self):
        return f"ω = {self.omega:g} rad/s ({self.name})" if self.omega is not None else self.name

    def track(self):
        """(t, hub height, distance travelled)."""
        if not self.from_series and "hub_height" in self.s and "distance_travelled" in self.s:
            hh, dt = self.s["hub_height"], self.s["distance_travelled"]
            return np.asarray(hh["time"]), np.asarray(hh["value"]), np.asarray(dt["time"]), np.asarray(dt["value"])
        t = self.series["time"]
        # distance travelled counts motion in -x (the direction a wheel with omega > 0 rolls) as positive
        return t, self.series["centre_wheel_1"], t, self.x_unwrapped[0] - self.x_unwrapped

    def snapshots(self):
        names = self.s.get("snapshots")
        if not names:
            found = glob.glob(os.path.join(self.path, "snapshot_*.csv"))
            names = sorted((os.path.basename(f) for f in found), key=lambda n: int(re.findall(r"\d+", n)[-1]))
        if not names:
            raise SystemExit(f"{self.path}: no snapshot_<k>.csv files (scene needs [analysis] snapshot_times)")
        return names

    def hub_at(self, t):
        """(x, y, rotation angle) of the hub at time t, interpolated from series.csv."""
        ts = self.series["time"]
        return (float(np.interp(t, ts, self.x_unwrapped)), float(np.interp(t, ts, self.series["centre_wheel_1"])),
                float(np.interp(t, ts, self.angle)))


def centred(run, x, y, F, xc):
    """Roll the periodic node columns so that xc sits mid-panel; returns unwrapped x and rolled fields."""
    nx = len(x)
    h = x[1] - x[0]
    width = nx * h
    shift = int(round((xc - width / 2 - x[0]) / h))
    idx = (np.arange(nx) + shift) % nx
    xs = x[0] + (np.arange(nx) + shift) * h
    return xs, {k: v[:, idx] for k, v in F.items()}


def draw_wheel(ax, run, xc, yc, ang, color="k"):
    b = run.body
    hub = b.get("hub_radius")
    plen = b.get("paddle_length")
    if hub is None or plen is None:
        if run.radius:
            ax.add_patch(plt.Circle((xc, yc), run.radius, fill=False, ec=color, lw=1.0, ls="--"))
        return
    pw = b.get("paddle_width", 0.04)
    n = int(b.get("paddles", 4))
    a0 = math.radians(b.get("angle", 0.0)) + ang
    ax.add_patch(plt.Circle((xc, yc), hub, fc="0.75", ec=color, lw=1.0, zorder=6))
    for k in range(n):
        a = a0 + 2 * math.pi * k / n
        c, s = math.cos(a), math.sin(a)
        # paddle rectangle from the hub rim outwards, width pw
        pts = []
        for along, across in ((hub * 0.9, -pw / 2), (hub + plen, -pw / 2), (hub + plen, pw / 2), (hub * 0.9, pw / 2)):
            pts.append((xc + along * c - across * s, yc + along * s + across * c))
        ax.add_patch(plt.Polygon(pts, closed=True, fc="0.75", ec=color, lw=1.0, zorder=6))


def field_panel(ax, run, name, field, cmap, vmin, vmax, quiver=True, window=None):
    t, x, y, F = read_snapshot(os.path.join(run.path, name))
    xc, yc, ang = run.hub_at(t)
    xs, F = centred(run, x, y, F, xc)
    mask = F["phi"] <= PHI_SURFACE
    im = ax.pcolormesh(xs, y, np.ma.array(F[field] * (1e-3 if field == "p_grains" else 1.0), mask=mask),
                       shading="nearest", cmap=cmap, vmin=vmin, vmax=vmax)
    ax.contour(xs, y, F["phi"], levels=[PHI_SURFACE], colors="k", linewidths=1.2)
    if quiver:
        R = run.radius or 0.15
        scale = 1.0 / (1.215 * math.sqrt(R / G))
        step = 3 if window is None else 1
        sl = (slice(0, None, step), slice(0, None, step))
        ux = np.where(mask, np.nan, F["u_x"])[sl]
        uy = np.where(mask, np.nan, F["u_y"])[sl]
        X, Y = np.meshgrid(xs[sl[1]], y[sl[0]])
        ax.quiver(X, Y, ux, uy, angles="xy", scale_units="xy", scale=scale, width=0.0015, headwidth=3.5,
                  color="k", zorder=4)
    draw_wheel(ax, run, xc, yc, ang)
    ax.set_aspect("equal")
    if window is None:
        ax.set_xlim(xs[0], xs[-1])
        top = min(y[-1], (run.surface or 0.5) + 2.6 * (run.radius or 0.15))
        ax.set_ylim(y[0], top)
    else:
        ax.set_xlim(xc - window[0], xc + window[0])
        ax.set_ylim(window[1], window[2])
    return t, im


def fig_fields(run, out, which):
    names = run.snapshots()
    fmax = 0.0
    for name in names:
        fmax = max(fmax, float(np.max(read_snapshot(os.path.join(run.path, name))[3]["f"])))
    n = len(names)
    ncol = 2 if n > 1 else 1
    nrow = (n + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(7.2 * ncol, 3.3 * nrow + 0.9), layout="constrained", squeeze=False)
    im = None
    for k, name in enumerate(names):
        ax = axes[k // ncol][k % ncol]
        t, im = field_panel(ax, run, name, "f", "plasma", 0.0, max(fmax, 1e-3))
        ax.set_title(f"({'abcdefgh'[k] if k < 8 else k}) t = {t:.2f} s", fontsize=9)
        ax.set_xlabel("x [m] (periodic, centred on the hub)")
        ax.set_ylabel("y [m]")
    for k in range(n, nrow * ncol):
        axes[k // ncol][k % ncol].axis("off")
    cb = fig.colorbar(im, ax=axes.ravel().tolist(), shrink=0.8, aspect=30)
    cb.set_label("f (nodal, mass-weighted)")
    R = run.radius or 0.15
    fig.suptitle(f"Fig. {11 if which == 'fast' else 12} ({which} wheel): {run_title(run.s, f'ω = {run.omega} rad/s')}\n"
                 f"black line: φ = {PHI_SURFACE} free surface; arrows: velocity, length 1.215 v √(R/g) "
                 f"(1 m/s → {1.215 * math.sqrt(R / G) * 100:.1f} cm); wheel outline rigid-rotation estimate",
                 fontsize=9)
    fig.savefig(out, dpi=130, format="png")
    plt.close(fig)


def snapshot_nearest(run, target):
    best = None
    for name in run.snapshots():
        path = os.path.join(run.path, name)
        need_file(path, "nodal snapshot CSV")
        with open(path) as fh:
            m = re.search(r"t\s*=\s*([-+0-9.eE]+)", fh.readline())
        if m and (best is None or abs(float(m.group(1)) - target) < best[0]):
            best = (abs(float(m.group(1)) - target), name, float(m.group(1)))
    if best is None:
        raise SystemExit(f"{run.path}: no readable snapshot times")
    return best[1], best[2]


def fig_pressure(runs, out):
    picks = [snapshot_nearest(r, 1.0) for r in runs]
    vmax = 0.0
    for r, (name, _) in zip(runs, picks):
        p = read_snapshot(os.path.join(r.path, name))[3]
        vals = p["p_grains"][p["phi"] > PHI_SURFACE]
        vmax = max(vmax, float(np.percentile(vals, 99.5)) * 1e-3 if vals.size else 0.0)
    fig, axes = plt.subplots(1, len(runs), figsize=(6.0 * len(runs), 4.6), layout="constrained", squeeze=False)
    im = None
    for ax, r, (name, ts) in zip(axes[0], runs, picks):
        R = r.radius or 0.15
        surf = r.surface or 0.5
        t, im = field_panel(ax, r, name, "p_grains", "viridis", 0.0, max(vmax, 1e-6), quiver=False,
                            window=(3.0 * R, max(0.0, surf - 3.0 * R), surf + 2.0 * R))
        ax.set_title(f"{r.label()}, t = {t:.2f} s", fontsize=9)
        ax.set_xlabel("x [m] (periodic, centred on the hub)")
        ax.set_ylabel("y [m]")
        p = r.s.get("parameters", {})
        ax.text(0.02, 0.03, f"G = {p.get('G', '?'):.3g} Pa, K = {p.get('K', '?'):.3g} Pa" if isinstance(p.get("G"), float)
                else "", transform=ax.transAxes, fontsize=7, bbox=dict(fc="w", ec="0.7"))
    cb = fig.colorbar(im, ax=axes.ravel().tolist(), shrink=0.9)
    cb.set_label("p̃ = p_grains [kPa] (colour range to the 99.5th percentile)")
    fig.suptitle("SI: granular pressure under the wheel at t ≈ 1 s; " + run_title(runs[0].s).split(", ", 1)[1]
                 + f"; black line φ = {PHI_SURFACE}", fontsize=9)
    fig.savefig(out, dpi=130, format="png")
    plt.close(fig)


def frame_nearest(run, target):
    """(time, path) of the HDF5 frame of `run` nearest `target` seconds."""
    try:
        import h5py
    except ImportError:
        raise SystemExit("plot_wheel.py --stiffness reads HDF5 frames: install h5py (Debian: python3-h5py)")
    best = None
    for path in glob.glob(os.path.join(run.path, "frames", "*.h5")):
        with h5py.File(path, "r") as h5:
            t = float(h5.attrs["time"])
        if best is None or abs(t - target) < abs(best[0] - target):
            best = (t, path)
    if best is None:
        raise SystemExit(f"{run.path}: no frames/*.h5 (the scene writes frames at [output] frame_interval)")
    return best


def fig_stiffness(runs, out, target=1.0):
    import h5py

    panels = []
    for r in runs:
        t, path = frame_nearest(r, target)
        with h5py.File(path, "r") as h5:
            xg = h5["bodies/grains/position"][:]
            pg = h5["bodies/grains/pressure"][:]
            wheel = next((k for k in h5["bodies"] if k not in ("grains", "fluid")), None)
            xw = h5[f"bodies/{wheel}/position"][:] if wheel else None
            mw = h5[f"bodies/{wheel}/mass"][:] if wheel else None
        R = r.radius or 0.15
        L = r.width
        if xw is not None:  # the wheel's centre of mass on the periodic track (as the run's window)
            a = 2 * math.pi * xw[:, 0] / L
            xc = (math.atan2(np.average(np.sin(a), weights=mw), np.average(np.cos(a), weights=mw)) * L
                  / (2 * math.pi)) % L
            yc = float(np.average(xw[:, 1], weights=mw))
        else:
            xc, yc, _ = r.hub_at(t)
            xc %= L
        dx = (xg[:, 0] - xc + L / 2) % L - L / 2
        m = (np.abs(dx) <= 2 * R) & (xg[:, 1] >= yc - 3 * R) & (xg[:, 1] <= yc + R)
        panels.append((r, t, dx[m], xg[m, 1], pg[m], None if xw is None else ((xw[:, 0] - xc + L / 2) % L - L / 2,
                                                                              xw[:, 1])))
    # one colour scale for all panels (the 99th percentile over all of them), so that the panels'
    # pressure levels compare directly
    allp = np.concatenate([pn[4] for pn in panels]) if panels else np.zeros(1)
    vmax = max(float(np.percentile(allp, 99)) * 1e-3 if allp.size else 0.0, 1e-9)
    fig, axes = plt.subplots(1, len(runs), figsize=(5.0 * len(runs) + 1.0, 4.4), layout="constrained", squeeze=False)
    sc = None
    for ax, (r, t, x, y, p, w) in zip(axes[0], panels):
        sc = ax.scatter(x, y, c=p * 1e-3, s=3, cmap="viridis", vmin=0.0, vmax=vmax, linewidths=0)
        if w is not None:
            ax.scatter(w[0], w[1], s=2, c="0.5", linewidths=0)
        prm = r.s.get("parameters", {})
        Gm, Km = prm.get("G"), prm.get("K")
        num = isinstance(Gm, (int, float)) and isinstance(Km, (int, float))
        E = 9 * Km * Gm / (3 * Km + Gm) if num else float("nan")
        moduli = f"G = {Gm:.3g}, K = {Km:.3g} Pa" if num else "G, K: see scene.toml"
        pooled = (r.s.get("pressure_scatter") or {}).get("pooled")
        near = None
        for rec in (r.s.get("pressure_scatter") or {}).get("series", []):
            if near is None or abs(rec["time"] - t) < abs(near["time"] - t):
                near = rec
        note = f"scatter {near['relative']:.2f} of rms {near['rms']:.3g} Pa here" if near else "no pressure_scatter"
        if pooled and pooled.get("points"):
            note += f"; pooled {pooled['relative']:.2f} (rms {pooled['rms']:.3g} Pa)"
        dt = r.s.get("dt")
        ax.set_title(f"E = {E:.3g} Pa ({moduli}), Δt = {dt if dt is not None else float('nan'):.2g} s\n"
                     f"t = {t:.2f} s; {note}", fontsize=8)
        ax.set_aspect("equal")
        ax.set_xlabel("x − x_wheel [m] (periodic)")
        ax.set_ylabel("y [m]")
        print(f"{r.path}: t = {t:.3f} s, E = {E:.3g} Pa, {note}")
    fig.colorbar(sc, ax=axes.ravel().tolist(), shrink=0.85).set_label("p̃ [kPa] (one scale: 99th percentile of all panels)")
    fig.suptitle("SI: granular pressure of the grain points under the wheel for three granular stiffnesses; "
                 + run_title(runs[0].s).split(", ", 1)[1], fontsize=9)
    fig.savefig(out, dpi=130, format="png")
    plt.close(fig)


def fig_track(runs, out):
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.6))
    for i, r in enumerate(runs):
        th, hh, td, dd = r.track()
        lab = r.label() + (" [series.csv: run not finished]" if r.from_series else "")
        ax1.plot(th, hh, "-", color=f"C{i}", lw=1.6, label=lab)
        ax2.plot(td, dd, "-", color=f"C{i}", lw=1.6, label=lab)
    r0 = runs[0]
    if r0.surface is not None:
        ax1.axhline(r0.surface, color="k", lw=0.9, label=f"bed surface {r0.surface:g} m")
        if r0.radius:
            ax1.axhline(r0.surface + r0.radius, color="0.4", lw=0.8, ls="--",
                        label=f"surface + R (resting on the surface), R = {r0.radius:g} m")
            ax1.axhline(r0.surface - r0.radius, color="0.4", lw=0.8, ls=":", label="surface − R (fully submerged)")
    ax1.set_xlabel("t [s]")
    ax1.set_ylabel("hub height [m]")
    ax1.legend(fontsize=7, loc="best")
    ax1.set_title("hub height", fontsize=9)
    ax2.set_xlabel("t [s]")
    ax2.set_ylabel("distance travelled [m] (−x, unwrapped)")
    for i, r in enumerate(runs):
        if r.omega is not None and r.radius:
            t = r.series["time"]
            ax2.plot(t, r.omega * r.radius * t, ":", color=f"C{i}", lw=0.9,
                     label=f"ω R t (rolling without slip), {r.label().split(' (')[0]}")
    ax2.set_ylim(bottom=min(0.0, ax2.get_ylim()[0]), top=1.2 * max(float(np.max(r.track()[3])) for r in runs) + 0.05)
    ax2.legend(fontsize=7)
    ax2.set_title("distance travelled", fontsize=9)
    fig.suptitle("Running on oobleck: " + run_title(r0.s).split(", ", 1)[1], fontsize=9)
    save(fig, out)


def main(argv):
    if argv and argv[0] == "--stiffness":
        if len(argv) < 3:
            raise SystemExit(__doc__.strip())
        fig_stiffness([Run(r) for r in argv[2:]], argv[1])
        return
    if len(argv) != 3 or argv[0].startswith("-"):
        raise SystemExit(__doc__.strip())
    prefix, fast, slow = argv
    runs = [Run(fast), Run(slow)]
    fig_track(runs, f"{prefix}_track.png")
    fig_fields(runs[0], f"{prefix}_fast.png", "fast")
    fig_fields(runs[1], f"{prefix}_slow.png", "slow")
    fig_pressure(runs, f"{prefix}_pressure.png")


if __name__ == "__main__":
    main(sys.argv[1:])
