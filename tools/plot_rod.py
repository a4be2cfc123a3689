#!/usr/bin/python3
"""Paper Figs. 7 and 8 from rod-impact runs (scenes/paper/rod_impact.toml, spec S2).

usage: plot_rod.py RUN_DIR OUT.png
           Fig. 7: (a) the z-displacement field (displacement_y) at the first snapshot with contours
           and the rod outline; (c) |dz| vs depth directly below the rod with the linear fit of
           summary.json (displacement_below_rod).
       plot_rod.py --dynamics OUT.png RUN_DIR [RUN_DIR ...]
           Fig. 8: rod acceleration, velocity and tip position (relative to the bed surface) vs time
           for several runs, one colour per run, legend v_0.
"""
import os
import sys

import numpy as np
from oobleck_plot import finite, load_scene, load_summary, need, plt, read_snapshot, run_title, save, scene_body

PHI_MASK = 0.1


def usage():
    raise SystemExit(__doc__.strip())


def rod_geometry(run, s):
    """(radius, length) of the rod from the run's scene.toml; (None, None) where not known."""
    body = scene_body(load_scene(run), "rod")
    if body.get("min") and body.get("max"):
        return body["max"][0] - max(body["min"][0], 0.0), body["max"][1] - body["min"][1]
    return None, None


def nearest(series, t):
    i = int(np.argmin(np.abs(np.asarray(series["time"]) - t)))
    return series["value"][i]


def fig7(run, out):
    s = load_summary(run)
    spath = os.path.join(run, "summary.json")
    snaps = need(s, spath, "snapshots")
    if not snaps:
        raise SystemExit(f"{spath}: 'snapshots' is empty (scene needs [analysis] snapshot_times)")
    prof = need(s, spath, "displacement_below_rod")
    t, x, y, F = read_snapshot(os.path.join(run, snaps[0]))
    mm = 1e3
    radius, length = rod_geometry(run, s)
    if "rod_position" in s:
        tip = nearest(s["rod_position"], t)
    else:
        tip = prof.get("rod_tip")
    v0 = -s["rod_velocity"]["value"][0] if s.get("rod_velocity") else float("nan")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12.5, 5.6), gridspec_kw={"width_ratios": [1.25, 1]},
                                   layout="constrained")
    mask = F["phi"] <= PHI_MASK
    dz = np.ma.array(F["displacement_y"] * mm, mask=mask)
    lim = float(np.max(np.abs(dz))) if dz.count() else 1.0
    im = ax1.pcolormesh(x * mm, y * mm, dz, shading="nearest", cmap="RdBu_r", vmin=-lim, vmax=lim)
    X, Y = np.meshgrid(x * mm, y * mm)
    levels = [lv for lv in np.linspace(-lim, lim, 17) if abs(lv) > 1e-9 * lim]
    cs = ax1.contour(X, Y, dz.filled(0.0), levels=levels, colors="k", linewidths=0.6)
    ax1.clabel(cs, fontsize=6, fmt="%.2g")
    if radius is not None and tip is not None:
        top = tip + length
        ax1.fill([0, radius * mm, radius * mm, 0], [tip * mm, tip * mm, top * mm, top * mm], facecolor="0.6",
                 edgecolor="k", lw=1.0, zorder=5, label="rod")
    elif tip is not None:
        ax1.axhline(tip * mm, color="0.4", lw=1, ls="--", label="rod tip (radius unknown: no scene.toml)")
    if "bed_surface" in s:
        ax1.axhline(s["bed_surface"] * mm, color="0.3", lw=0.8, ls=":", label="initial bed surface")
    ax1.set_aspect("equal")
    ax1.set_xlim(x[0] * mm, x[-1] * mm)
    ax1.set_ylim(y[0] * mm, y[-1] * mm)
    ax1.set_xlabel("r [mm]")
    ax1.set_ylabel("z [mm]")
    ax1.legend(fontsize=7, loc="lower right")
    cb = fig.colorbar(im, ax=ax1, shrink=0.85)
    cb.set_label(f"Δz [mm] (z-displacement since t = 0; φ ≤ {PHI_MASK} blank)")
    ax1.set_title(f"(a) z-displacement at t = {t * 1e3:.1f} ms", fontsize=9)

    depth = np.asarray(need(prof, spath, "depth"))
    disp = np.abs(np.asarray(need(prof, spath, "displacement")))
    ax2.plot(depth * mm, disp * mm, "o-", ms=3.5, label=f"|Δz| on the axis below the rod (t = {prof.get('time', t) * 1e3:.1f} ms)")
    fit = prof.get("fit")
    if fit and finite(fit.get("slope")):
        dd = np.linspace(0, depth.max(), 50)
        ax2.plot(dd * mm, (fit["intercept"] + fit["slope"] * dd) * mm, "r--",
                 label=f"linear fit: |Δz| = {fit['intercept'] * mm:.3g} mm {fit['slope']:+.3g} × depth, R² = {fit['r_squared']:.3f}")
    if "bed_surface" in s and prof.get("rod_tip") is not None:
        ax2.axvline((s["bed_surface"] - prof["rod_tip"]) * mm, color="0.5", lw=0.8, ls=":",
                    label="rod tip depth")
    ax2.set_xlabel("depth below the initial bed surface [mm]")
    ax2.set_ylabel("|Δz| [mm]")
    ax2.set_xlim(left=0)
    ax2.set_ylim(bottom=0)
    ax2.legend(fontsize=7)
    ax2.set_title("(c) displacement directly below the rod (a growing solid plug is ~linear)", fontsize=9)
    extra = f"v_0 = {v0:g} m/s"
    if s.get("rod_mass") is not None:
        extra += f", rod mass {s['rod_mass'] * 1e3:.3g} g"
    if radius is not None:
        extra += f", rod radius {radius * mm:.3g} mm"
    fig.suptitle("Fig. 7: " + run_title(s, extra), fontsize=10)
    fig.savefig(out, dpi=130, format="png")
    plt.close(fig)


def series_xy(s, spath, key, scale=1.0, shift=0.0, t0=0.0):
    d = need(s, spath, key)
    return (np.asarray(d["time"]) - t0) * 1e3, (np.asarray(d["value"]) - shift) * scale


def fig8(out, runs):
    fig, (axa, axv, axz) = plt.subplots(3, 1, figsize=(7.5, 10), sharex=True)
    heads = {run_title(load_summary(r)).split(", ", 1)[1] for r in runs}
    force_lines = False
    amax = 0.0
    for i, run in enumerate(runs):
        s = load_summary(run)
        spath = os.path.join(run, "summary.json")
        col = f"C{i % 10}"
        vel = need(s, spath, "rod_velocity")
        v0 = -vel["value"][0]
        t0 = s.get("impact_time") or 0.0
        p = s.get("parameters", {})
        lab = f"v_0 = {v0:g} m/s ({os.path.basename(run.rstrip('/'))}"
        if len(heads) > 1:
            lab += f"; φ = {p.get('phi')}, η_0 = {p.get('eta_0', 0) * 1e3:.3g} mPa·s, {p.get('cells')}"
        lab += ")"
        ta, a = series_xy(s, spath, "rod_acceleration", t0=t0)
        axa.plot(ta, a, "-", color=col, lw=1.6, label=lab)
        amax = max(amax, float(np.max(np.abs(a))) if len(a) else 0.0)
        if s.get("rod_acceleration_from_force"):
            tf, af = series_xy(s, spath, "rod_acceleration_from_force", t0=t0)
            axa.plot(tf, af, "-", color=col, lw=0.6, alpha=0.45)
            force_lines = True
        tv, v = series_xy(s, spath, "rod_velocity", t0=t0)
        axv.plot(tv, v, "-", color=col, lw=1.6, label=lab)
        if s.get("rod_velocity_from_position"):
            tp, vp = series_xy(s, spath, "rod_velocity_from_position", t0=t0)
            axv.plot(tp, vp, "--", color=col, lw=0.9)
        surface = need(s, spath, "bed_surface")
        tz, z = series_xy(s, spath, "rod_position", scale=1e3, shift=surface, t0=t0)
        axz.plot(tz, z, "-", color=col, lw=1.6, label=lab)
    if force_lines:
        axa.plot([], [], "-", color="0.4", lw=0.6, alpha=0.6, label="thin: from the contact force (rod_acceleration_from_force)")
        # the force-based curve can spike at impact; keep the finite-difference curves readable
        lo, hi = axa.get_ylim()
        axa.set_ylim(max(lo, -0.4 * amax), min(hi, 2.0 * amax))
    axa.axhline(0, color="k", lw=0.5)
    axa.set_ylabel("a_rod [m/s²] (upward +)")
    axa.set_title("acceleration: finite differences of the tip position (stencil as in summary.json)", fontsize=8)
    axa.legend(fontsize=7)
    axv.set_ylabel("v_rod [m/s]")
    axv.plot([], [], "--", color="0.4", lw=0.9, label="dashed: from position differences")
    axv.legend(fontsize=7)
    axz.axhline(0, color="k", lw=0.6, ls=":")
    axz.set_ylabel("z_rod − bed surface [mm] (tip)")
    axz.set_xlabel("t − t_impact [ms]")
    axz.legend(fontsize=7)
    title = "Fig. 8: rod dynamics, " + load_summary(runs[0]).get("scene", "?")
    title += "\n" + (heads.pop() if len(heads) == 1 else "φ/η_0/K_0/grid differ between runs")
    fig.suptitle(title, fontsize=9)
    save(fig, out)


def main(argv):
    if len(argv) >= 3 and argv[0] == "--dynamics":
        fig8(argv[1], argv[2:])
    elif len(argv) == 2 and not argv[0].startswith("-"):
        fig7(argv[0], argv[1])
    else:
        usage()


if __name__ == "__main__":
    main(sys.argv[1:])
