#!/usr/bin/python3
"""S2 in 3D (scenes/paper/rod_impact_3d.toml) from a run's frames: a slice and a 3D view.

usage: plot_rod_3d.py OUT.png RUN_DIR [RUN_DIR ...] [--time T]
  One row per run, at the frame nearest T seconds (default 0.005: the plug moving with the rod):
  (left) the grains within one point spacing of the plane y = 0, coloured by their downward
  speed -v_z, with the rod's points in that plane; (right) a 3D view of the grains moving down
  faster than a tenth of the rod's speed (the plug driven by the rod), coloured by -v_z, and the
  rod. Reads frames/frame_*.h5 (h5py), the run's summary.json and scene.toml.
"""
import os
import sys

import h5py
import numpy as np
from oobleck_plot import frame_nearest, load_scene, load_summary, plt, run_title, save, scene_body


def usage():
    raise SystemExit(__doc__.strip())


def read_body(h, name):
    g = h["bodies"][name]
    return g["position"][()], g["velocity"][()]


def main(argv):
    t = 0.005
    if "--time" in argv:
        i = argv.index("--time")
        t = float(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    if len(argv) < 2:
        usage()
    out, runs = argv[0], argv[1:]
    fig = plt.figure(figsize=(11, 4.2 * len(runs)))
    for k, run in enumerate(runs):
        s = load_summary(run)
        scene = load_scene(run)
        rod = scene_body(scene, "rod")
        h_cell = scene["grid"]["cell_size"]
        half = 0.5 * h_cell / scene["region"][0].get("points_per_cell", 2)
        path = frame_nearest(run, t, "plot_rod_3d")
        with h5py.File(path, "r") as h:
            time = float(h.attrs["time"])
            xg, vg = read_body(h, "grains")
            xr, vr = read_body(h, "rod")
        speed = float(np.linalg.norm(vr.mean(axis=0))) or 1.0
        down = -vg[:, 2]
        ax = fig.add_subplot(len(runs), 2, 2 * k + 1)
        sl = np.abs(xg[:, 1]) < 2 * half  # the layer(s) nearest y = 0
        sc = ax.scatter(xg[sl, 0] * 100, xg[sl, 2] * 100, c=down[sl], s=3, cmap="viridis", vmin=0, vmax=speed,
                        marker="s", linewidths=0)
        rs = np.abs(xr[:, 1]) < h_cell / rod.get("points_per_cell", 2)
        ax.scatter(xr[rs, 0] * 100, xr[rs, 2] * 100, c="tab:red", s=4, marker="s", linewidths=0, label="rod")
        ax.set_aspect("equal")
        ax.set_xlabel("x [cm]")
        ax.set_ylabel("z [cm]")
        tilt = rod.get("tilt", 0.0)
        ax.set_title(f"slice y = 0, t = {time * 1e3:.1f} ms, tilt {tilt:g} deg", fontsize=9)
        fig.colorbar(sc, ax=ax, label="-v_z [m/s]", shrink=0.8)
        ax.legend(loc="lower left", fontsize=8)
        ax3 = fig.add_subplot(len(runs), 2, 2 * k + 2, projection="3d")
        plug = down > 0.1 * speed
        ax3.scatter(xg[plug, 0] * 100, xg[plug, 1] * 100, xg[plug, 2] * 100, c=down[plug], s=2, cmap="viridis",
                    vmin=0, vmax=speed, linewidths=0, depthshade=False)
        ax3.scatter(xr[:, 0] * 100, xr[:, 1] * 100, xr[:, 2] * 100, c="tab:red", s=2, linewidths=0)
        ax3.set_xlabel("x [cm]")
        ax3.set_ylabel("y [cm]")
        ax3.set_zlabel("z [cm]")
        ax3.set_title(f"grains moving down faster than {0.1 * speed:.2g} m/s ({plug.sum()} points) and the rod",
                      fontsize=9)
        ax3.view_init(elev=20, azim=-60)
        fig.text(0.5, 1.0 - k / len(runs), run_title(s, os.path.basename(os.path.normpath(run))), ha="center",
                 va="top", fontsize=9)
    save(fig, out)


if __name__ == "__main__":
    main(sys.argv[1:])
