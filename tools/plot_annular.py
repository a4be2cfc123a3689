#!/usr/bin/python3
"""Paper Fig. 6 from an annular-shear run (scenes/paper/annular_shear.toml): surface v_theta/u_i
profiles at the bob rotation angles in summary.json beside the Newtonian A r + B/r profile, and
the fronts vs time: the co-rotating band (v_theta/(omega r) = 0.5) and the jammed structure
(f = f_m/2), with the outer half's rotation.

usage: plot_annular.py RUN_DIR OUT.png
"""
import json
import sys

from oobleck_plot import plt, save

run, out = sys.argv[1], sys.argv[2]
s = json.load(open(f"{run}/summary.json"))
p = s["parameters"]
ri, ro = p["r_inner"], p["r_outer"]
A = -ri / (ro**2 - ri**2)
B = ri * ro**2 / (ro**2 - ri**2)
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
for prof, d in zip(s["profiles"], s["newtonian_distance"]):
    r_mm = [r * 1e3 for r in prof["r"]]
    ax1.plot(r_mm, prof["v_over_ui"], "-o", ms=2, label=f"θ = {prof['angle']:.2f} rad (dist. {d:.2f})")
rr = [ri + (ro - ri) * k / 100 for k in range(101)]
ax1.plot([r * 1e3 for r in rr], [A * r + B / r for r in rr], "k--", label="Newtonian A r + B/r")
ax1.plot([r * 1e3 for r in rr], [r / ri for r in rr], "k:", lw=0.8, label="rigid rotation with the bob")
ax1.set_xlabel("r [mm]")
ax1.set_ylabel("surface v_θ / u_i")
ax1.set_ylim(-0.05, max(2.0, ax1.get_ylim()[1]))
ax1.legend(fontsize=7)
ax1.set_title(f"u_i = {p.get('u_inner', float('nan')) * 1e3:.3g} mm/s, φ = {p['phi']}, K_0 = {p['K_0']}", fontsize=9)
fr = s["front"]
ax2.plot([t * 1e3 for t in fr["time"]], [r * 1e3 for r in fr["value"]], "b-")
if s.get("front_speed") is not None:
    fit = s["front_fit"]
    t_end = s.get("front_farthest_time", float("inf"))  # fitted while the front advances
    ts = [t for t in fr["time"] if t <= t_end]
    ax2.plot([t * 1e3 for t in ts], [(fit["intercept"] + fit["slope"] * t) * 1e3 for t in ts], "r--",
             label=f"fit: {s['front_speed'] * 1e3:.0f} mm/s (R² {fit['r_squared']:.3f})")
    ax2.legend(fontsize=8)
if "structure_front" in s:
    sf = s["structure_front"]
    ax2.plot([t * 1e3 for t in sf["time"]], [r * 1e3 for r in sf["value"]], "m-",
             label=f"structure f = {s['structure_front_threshold']:.3g} (f_m/2)")
    if s.get("structure_front_wall_time") is not None:
        ax2.axvline(s["structure_front_wall_time"] * 1e3, color="m", ls=":", lw=0.8)
    ax2.legend(fontsize=8)
ax2.axhline(ro * 1e3, color="k", lw=0.8)
if "outer_rotation" in s:
    # The outer half's mean rotation relative to the bob (0 = at rest) and its first fall below
    # 10% of its peak (outer_arrest).
    o = s["outer_rotation"]
    ax3 = ax2.twinx()
    ax3.plot([t * 1e3 for t in o["time"]], o["value"], "g-", lw=1)
    ax3.set_ylabel("outer half: mean v_θ/(ω_bob r)", color="g")
    ax3.set_ylim(0.0, 1.0)
    arrest = s.get("outer_arrest", {})
    if arrest.get("time") is not None:
        ax3.axvline(arrest["time"] * 1e3, color="g", ls=":", lw=0.8)
ax2.set_xlabel("t [ms]")
ax2.set_ylabel("front radius [mm] (blue: v_θ/(ω r) = 0.5)")
ax2.set_title(f"{s['scene']}: {p['cells'][0]}×{p['cells'][1]} cells of {p['cell_size'] * 1e3:g} mm", fontsize=9)
save(fig, out)
