#!/usr/bin/python3
"""Paper Figs. 9 and 10 from intrusion runs (scenes/paper/intrusion.toml, spec S3).

usage: plot_intrusion.py RUN_DIR OUT.png
           Fig. 9: (a-c) u_z/v_0 on the (r, z) grid at the snapshots with the u_z = 0.5 v_0 front in
           bold and the intruder outline; (d) f at the last snapshot with u_z contours; (g) the
           longitudinal and transverse positions of the velocity front (u_z = 0.5 v_0) and of the
           f front vs time with the linear fits of summary.json and k_l, k_t, k_l/k_t, R^2.
       plot_intrusion.py --factors OUT.png RUN_DIR [RUN_DIR ...]
           Fig. 10: k_t vs k_l of the velocity front (filled; f front hollow) for several runs,
           labelled with phi and v_0, beside the line k_l = 2 k_t.
"""
import os
import sys

import numpy as np
from oobleck_plot import (finite, load_scene, load_summary, need, plt, read_snapshot, run_title, save,
                          scene_body)

PHI_MASK = 0.1


def usage():
    raise SystemExit(__doc__.strip())


def nearest_frame(frames, t):
    return min(frames, key=lambda fr: abs(fr["time"] - t))


def intruder_geometry(run, s, spath):
    """(radius, length or None) of the intruder."""
    vf = need(s, spath, "velocity_front")
    radius = vf.get("series", {}).get("intruder_radius")
    body = scene_body(load_scene(run), "intruder")
    length = None
    if body.get("min") and body.get("max"):
        length = body["max"][1] - body["min"][1]
        if radius is None:
            radius = body["max"][0]
    if radius is None:
        raise SystemExit(f"{spath}: no ['velocity_front']['series']['intruder_radius'] and no "
                         f"intruder body in {os.path.join(run, 'scene.toml')}")
    return radius, length


def draw_intruder(ax, radius, length, tip_z, ytop, mm=1e3):
    top = tip_z + length if length else ytop
    ax.fill([0, radius * mm, radius * mm, 0], [tip_z * mm, tip_z * mm, top * mm, top * mm],
            facecolor="0.55", edgecolor="k", lw=1.0, zorder=5)


def fig9(run, out):
    s = load_summary(run)
    spath = os.path.join(run, "summary.json")
    snaps = need(s, spath, "snapshots")
    if not snaps:
        raise SystemExit(f"{spath}: 'snapshots' is empty (scene needs [analysis] snapshot_times)")
    v0 = need(s, spath, "v0")
    vfront = need(s, spath, "velocity_front")
    frames = need(vfront, spath, "series", "frames")
    if not frames:
        raise SystemExit(f"{spath}: velocity_front.series.frames is empty")
    radius, length = intruder_geometry(run, s, spath)
    ref_z = vfront["series"].get("reference_z", frames[0]["tip_z"])
    # v0 in summary is the speed; the intruder moves in -z, so co-moving material has u_z/(-v0) = 1.
    vz0 = -abs(v0)

    n = len(snaps)
    ncol = n + 1
    fig = plt.figure(figsize=(max(3.4 * ncol, 12.0), 8.2), layout="constrained")
    gs = fig.add_gridspec(2, 2 * ncol, height_ratios=[1.0, 1.15])
    mm = 1e3
    im = None
    last = None
    for k, name in enumerate(snaps):
        t, x, y, F = read_snapshot(os.path.join(run, name))
        mask = F["phi"] <= PHI_MASK
        uz = np.ma.array(F["u_y"] / vz0, mask=mask)
        ax = fig.add_subplot(gs[0, 2 * k:2 * k + 2])
        im = ax.pcolormesh(x * mm, y * mm, uz, shading="nearest", cmap="viridis", vmin=0.0, vmax=1.0)
        X, Y = np.meshgrid(x * mm, y * mm)
        ax.contour(X, Y, uz.filled(0.0), levels=[0.5], colors="w", linewidths=2.2)
        ax.contour(X, Y, uz.filled(0.0), levels=[0.1, 0.25, 0.75], colors="w", linewidths=0.6,
                   linestyles="--")
        fr = nearest_frame(frames, t)
        draw_intruder(ax, radius, length, fr["tip_z"], y[-1], mm)
        ax.set_aspect("equal")
        ax.set_xlim(x[0] * mm, x[-1] * mm)
        ax.set_ylim(y[0] * mm, y[-1] * mm)
        ax.set_xlabel("r [mm]")
        if k == 0:
            ax.set_ylabel("z [mm]")
        ax.set_title(f"({'abc'[k] if k < 3 else k}) u_z/v_0 at t = {t * 1e3:.1f} ms", fontsize=9)
        last = (t, x, y, F, fr)
    cb = fig.colorbar(im, ax=fig.axes[:n], orientation="horizontal", shrink=0.7, aspect=40)
    cb.set_label(f"u_z / v_0 (v_0 = {vz0:g} m/s); white: 0.5 bold,\n0.1/0.25/0.75 dashed; φ ≤ {PHI_MASK} blank",
                 fontsize=8)

    # (d) f at the last snapshot with the u_z contours
    t, x, y, F, fr = last
    mask = F["phi"] <= PHI_MASK
    ax = fig.add_subplot(gs[0, 2 * n:2 * n + 2])
    fim = ax.pcolormesh(x * mm, y * mm, np.ma.array(F["f"], mask=mask), shading="nearest", cmap="magma",
                        vmin=0.0, vmax=max(0.05, float(np.max(F["f"]))))
    X, Y = np.meshgrid(x * mm, y * mm)
    uz = np.where(mask, 0.0, F["u_y"] / vz0)
    ax.contour(X, Y, uz, levels=[0.5], colors="c", linewidths=2.0)
    ax.contour(X, Y, uz, levels=[0.1, 0.25, 0.75], colors="c", linewidths=0.6, linestyles="--")
    draw_intruder(ax, radius, length, fr["tip_z"], y[-1], mm)
    ax.set_aspect("equal")
    ax.set_xlim(x[0] * mm, x[-1] * mm)
    ax.set_ylim(y[0] * mm, y[-1] * mm)
    ax.set_xlabel("r [mm]")
    ax.set_title(f"(d) f at t = {t * 1e3:.1f} ms, u_z/v_0 contours (cyan)", fontsize=9)
    cb = fig.colorbar(fim, ax=ax, orientation="horizontal", shrink=0.9, aspect=20)
    cb.set_label("f (structure)", fontsize=8)

    # (g) fronts vs time
    axl = fig.add_subplot(gs[1, :ncol])
    axt = fig.add_subplot(gs[1, ncol:])
    tip_t = [fr["time"] * 1e3 for fr in frames]
    axl.plot(tip_t, [(ref_z - fr["tip_z"]) * mm for fr in frames], "k-", lw=1, label="intruder tip")
    axt.axhline(radius * mm, color="k", lw=1, label="intruder edge")
    notes = []
    for key, col, lab in (("velocity_front", "C0", "velocity front u_z = 0.5 v_0"), ("f_front", "C3", "f front")):
        fd = s.get(key)
        if not fd or not fd.get("series", {}).get("frames"):
            continue
        frs = fd["series"]["frames"]
        rz = fd["series"].get("reference_z", ref_z)
        for ax, side, coord, conv in ((axl, "longitudinal", "z", lambda v: (rz - v) * mm),
                                      (axt, "transverse", "r", lambda v: v * mm)):
            pts = [(fr["time"] * 1e3, conv(fr[side][coord]), fr[side].get("at_boundary", False))
                   for fr in frs if fr[side].get("found")]
            inside = [(a, b) for a, b, w in pts if not w]
            wall = [(a, b) for a, b, w in pts if w]
            if inside:
                ax.plot(*zip(*inside), ".", color=col, ms=3, label=lab)
            if wall:
                ax.plot(*zip(*wall), "x", color=col, ms=4, label=f"{lab} (at a wall)")
        sp = fd.get("speeds") or {}
        far = fd.get("speeds_to_farthest") or {}
        for fits, style, what in ((sp, "--", "fit"), (far, ":", "fit to the farthest extent")):
            if what != "fit" and fits.get("longitudinal_fit") == sp.get("longitudinal_fit") and \
                    fits.get("transverse_fit") == sp.get("transverse_fit"):
                continue  # a front that kept advancing: the same fit
            for ax, fitkey, kkey in ((axl, "longitudinal_fit", "k_l"), (axt, "transverse_fit", "k_t")):
                fit = fits.get(fitkey)
                if not fit or not finite(fit.get("slope")):
                    continue
                tt = np.linspace(fit["t_begin"], fit["t_end"], 50)
                ax.plot(tt * 1e3, (fit["intercept"] + fit["slope"] * tt) * mm, style, color=col, lw=1.6,
                        label=f"{what}: {fit['slope']:.3g} m/s, {kkey} = {fits.get(kkey, float('nan')):.3g}, "
                              f"R² = {fit['r_squared']:.3f}")
        if finite(sp.get("k_l_over_k_t")):
            err = sp.get("k_l_over_k_t_stderr")
            notes.append(f"{lab.split(' u_z')[0]}: k_l = {sp['k_l']:.3g}, k_t = {sp['k_t']:.3g}, "
                         f"k_l/k_t = {sp['k_l_over_k_t']:.3g}" + (f" ± {err:.2g}" if finite(err) else ""))
    axl.set_xlabel("t [ms]")
    axl.set_ylabel("depth below the initial tip, z_tip(0) − z [mm]")
    axl.set_title("(g) longitudinal front (on the axis, below the tip)", fontsize=9)
    axl.axhline(ref_z * mm, color="0.5", lw=0.8, ls=":", label="container bottom")
    axl.legend(fontsize=7, loc="upper left")
    axt.set_xlabel("t [ms]")
    axt.set_ylabel("front radius r [mm] (at the tip depth)")
    axt.set_title("(g) transverse front (radially at the tip depth)", fontsize=9)
    rmax = max([float(np.max(ln.get_ydata())) for ln in axt.get_lines() if len(ln.get_ydata())] + [radius * mm])
    if rmax > 0.6 * x[-1] * mm:
        axt.axhline(x[-1] * mm, color="0.5", lw=0.8, ls=":", label="outer wall")
    else:
        axt.set_ylim(0, 1.6 * rmax)
    axt.legend(fontsize=7, loc="upper left")
    head = f"{run_title(s)}, v_0 = {abs(v0):g} m/s, intruder radius {radius * mm:g} mm"
    if notes:
        head += "\n" + ";   ".join(notes) + "   (k_l = v_fl/v_0 − 1, k_t = v_ft/v_0)"
    fig.suptitle(head, fontsize=9.5)
    fig.savefig(out, dpi=130, format="png")
    plt.close(fig)


def fig10(out, runs):
    fig, ax = plt.subplots(figsize=(6.2, 5.2))
    klmax = ktmax = 0.0
    plotted = 0
    heads = {run_title(load_summary(r)).split(", ", 2)[2] for r in runs}
    for i, run in enumerate(runs):
        s = load_summary(run)
        spath = os.path.join(run, "summary.json")
        kl, kt = s.get("k_l"), s.get("k_t")
        if not (finite(kl) and finite(kt)):
            print(f"{spath}: no velocity-front k_l/k_t (fit failed?); left out", file=sys.stderr)
            continue
        plotted += 1
        p = s.get("parameters", {})
        col = f"C{i % 10}"
        lab = f"φ = {p.get('phi', '?')}, v_0 = {abs(s.get('v0', float('nan'))):g} m/s ({os.path.basename(run.rstrip('/'))}"
        if len(heads) > 1:
            lab += f"; η_0 = {p.get('eta_0', 0) * 1e3:.3g} mPa·s, K_0 = {p.get('K_0')}, {p.get('cells')}"
        lab += ")"
        sp = (s.get("velocity_front") or {}).get("speeds") or {}
        ax.errorbar([kt], [kl], xerr=[sp.get("k_t_stderr") or 0], yerr=[sp.get("k_l_stderr") or 0], fmt="o",
                    color=col, ms=7, capsize=2, label=lab)
        klmax = max(klmax, kl + (sp.get("k_l_stderr") or 0))
        ktmax = max(ktmax, kt + (sp.get("k_t_stderr") or 0))
        ff = (s.get("f_front") or {}).get("speeds") or {}
        if finite(ff.get("k_l")) and finite(ff.get("k_t")):
            ax.plot([ff["k_t"]], [ff["k_l"]], "o", mfc="none", mec=col, ms=7)
            ax.plot([kt, ff["k_t"]], [kl, ff["k_l"]], ":", color=col, lw=0.8)
            klmax, ktmax = max(klmax, ff["k_l"]), max(ktmax, ff["k_t"])
    if not plotted:
        raise SystemExit("no run had summary k_l and k_t: " + " ".join(runs))
    kk = np.linspace(0, 1.15 * ktmax, 10)
    ax.plot(kk, 2 * kk, "k--", label="k_l = 2 k_t (Han et al. 2016)")
    ax.plot([], [], "o", mfc="none", mec="k", label="f front (same run, hollow)")
    ax.set_xlim(0, 1.15 * ktmax)
    ax.set_ylim(0, 1.15 * klmax)
    ax.set_xlabel("k_t = v_ft / v_0")
    ax.set_ylabel("k_l = v_fl / v_0 − 1")
    # the title carries the shared settings; φ and v_0 vary per point (legend)
    scene = load_summary(runs[0]).get("scene", "?")
    ax.set_title("Fig. 10: front propagation factors (filled: u_z = 0.5 v_0 front)\n" + scene + ", "
                 + (heads.pop() if len(heads) == 1 else "η_0/K_0/grid differ between runs"), fontsize=8)
    ax.legend(fontsize=7)
    save(fig, out)


def main(argv):
    if len(argv) >= 3 and argv[0] == "--factors":
        fig10(argv[1], argv[2:])
    elif len(argv) == 2 and not argv[0].startswith("-"):
        fig9(argv[0], argv[1])
    else:
        usage()


if __name__ == "__main__":
    main(sys.argv[1:])
