#!/usr/bin/python3
"""S4 in 3D (scenes/paper/wheel_3d.toml) against plane strain (wheel.toml), from runs' outputs.

usage: plot_wheel_3d.py OUT.png RUN_3D PLANE_RUN [RUN_3D PLANE_RUN ...] [--time T]
  One row per pair (bench/wheel_3d_vs_plane.sh writes them): (left) the hub height against time of
  the 3D run and of the plane-strain run, with the bed's surface and the paper's criterion (one
  radius below the start); (middle) the 3D run's grains within one point spacing of the wheel's
  mid-plane, coloured by their speed, with the wheel's points in that slab; (right) a 3D view of
  the grains moving faster than a tenth of the wheel's rim speed, and the wheel. The slice and the
  view are at the frame nearest T seconds (default: the last frame). Reads the runs' summary.json,
  scene.toml and frames/frame_*.h5 (h5py).
"""
import os
import sys

import h5py
import numpy as np
from oobleck_plot import frame_nearest, load_scene, load_summary, plt, run_title, save, scene_body


def usage():
    raise SystemExit(__doc__.strip())


def hub_series(s, run):
    if "hub_height" not in s:
        raise SystemExit(f"plot_wheel_3d: {run}/summary.json has no hub_height (not a wheel run?)")
    return np.array(s["hub_height"]["time"]), np.array(s["hub_height"]["value"])


def main(argv):
    t = None
    if "--time" in argv:
        i = argv.index("--time")
        t = float(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    if len(argv) < 3 or (len(argv) - 1) % 2 != 0:
        usage()
    out, pairs = argv[0], list(zip(argv[1::2], argv[2::2]))
    fig = plt.figure(figsize=(15, 4.2 * len(pairs)))
    for k, (run3, run2) in enumerate(pairs):
        s3, s2 = load_summary(run3), load_summary(run2)
        scene = load_scene(run3)
        wheel = scene_body(scene, "wheel")
        ax = fig.add_subplot(len(pairs), 3, 3 * k + 1)
        for s, run, style, label in ((s2, run2, "--", "plane strain"), (s3, run3, "-", "3D")):
            tt, hh = hub_series(s, run)
            ax.plot(tt, hh, style, label=label)
        surface = s3.get("bed_surface")
        radius = s3.get("wheel_radius")
        h0 = s3.get("hub_height_initial")
        criterion = h0 - radius if radius is not None and h0 is not None else None
        if surface is not None:
            same = criterion is not None and abs(criterion - surface) < 1e-9
            ax.axhline(surface, color="0.6", lw=0.8, label="bed surface" + (" = start − one radius" if same else ""))
            if same:
                criterion = None
        if criterion is not None:
            ax.axhline(criterion, color="tab:red", lw=0.8, ls=":", label="start − one radius")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("hub height [m]")
        ax.set_title(f"ω = {s3.get('omega', '?')} rad/s: hub height", fontsize=9)
        ax.legend(fontsize=8)

        path = frame_nearest(run3, t, "plot_wheel_3d")
        with h5py.File(path, "r") as h:
            time = float(h.attrs["time"])
            xg, vg = h["bodies"]["grains"]["position"][()], h["bodies"]["grains"]["velocity"][()]
            xw = h["bodies"]["wheel"]["position"][()]
        cells = scene["grid"]["cells"]
        h_cell = scene["grid"]["size"][0] / cells[0]
        mid = wheel["centre"][1]
        spacing = h_cell / scene["region"][0].get("points_per_cell", 2)
        speed = np.linalg.norm(vg, axis=1)
        rim = abs(float(s3.get("omega", 1.0))) * (radius or 0.15)
        ax2 = fig.add_subplot(len(pairs), 3, 3 * k + 2)
        sl = np.abs(xg[:, 1] - mid) < spacing
        sc = ax2.scatter(xg[sl, 0], xg[sl, 2], c=speed[sl], s=2, cmap="viridis", vmin=0, vmax=rim, marker="s",
                         linewidths=0)
        ws = np.abs(xw[:, 1] - mid) < spacing
        ax2.scatter(xw[ws, 0], xw[ws, 2], c="tab:red", s=3, marker="s", linewidths=0, label="wheel")
        ax2.set_aspect("equal")
        ax2.set_xlabel("x [m]")
        ax2.set_ylabel("z [m]")
        ax2.set_title(f"slice y = {mid:.3g} m (mid-width), t = {time:.3g} s", fontsize=9)
        fig.colorbar(sc, ax=ax2, label="|v| grains [m/s]", shrink=0.8)
        ax2.legend(loc="lower left", fontsize=8)

        ax3 = fig.add_subplot(len(pairs), 3, 3 * k + 3, projection="3d")
        moving = speed > 0.1 * rim
        ax3.scatter(xg[moving, 0], xg[moving, 1], xg[moving, 2], c=speed[moving], s=1, cmap="viridis", vmin=0,
                    vmax=rim, linewidths=0, depthshade=False)
        ax3.scatter(xw[:, 0], xw[:, 1], xw[:, 2], c="tab:red", s=1, linewidths=0)
        ax3.set_xlabel("x [m]")
        ax3.set_ylabel("y [m]")
        ax3.set_zlabel("z [m]")
        ax3.set_title(f"grains faster than {0.1 * rim:.2g} m/s ({moving.sum()} points) and the wheel", fontsize=9)
        lo = np.array(scene["grid"].get("origin", [0.0, 0.0, 0.0]))
        size = np.array(scene["grid"]["size"])
        ax3.set_xlim(lo[0], lo[0] + size[0])
        ax3.set_ylim(lo[1], lo[1] + size[1])
        ax3.set_zlim(lo[2], lo[2] + size[2])
        ax3.set_box_aspect(size)
        ax3.tick_params(labelsize=7)
        ax3.view_init(elev=30, azim=-70)
        fig.text(0.5, 1.0 - k / len(pairs), run_title(s3, os.path.basename(os.path.normpath(run3))), ha="center",
                 va="top", fontsize=9)
    save(fig, out)


if __name__ == "__main__":
    main(sys.argv[1:])
