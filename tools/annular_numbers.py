#!/usr/bin/env python3
"""Print the S1 (annular shear) numbers docs/results.md quotes that summary.json does not hold as
keys, computed from a run folder of `oobleck run scenes/paper/annular_shear.toml`:

  python3 tools/annular_numbers.py RUN [RUN ...]

From summary.json (keys named in the output): the velocity front's fit (`front_speed`,
`front_fit`), its farthest extent, the structure front's straight-line fit (a least-squares line
through `structure_front` from 5 ms to 50 ms, and from 5 ms up to `structure_front_wall_time`, or
to the last sample if the front never reaches the wall), the band's rotation v_theta/(omega_bob r) = (v/u_i) r_0/r in the
profile at 0.31 rad (`profiles`), the outer half's arrest (`outer_arrest`) and the distances from
the Newtonian profile (`newtonian_distance`).

From the frames (frames/frame_*.h5, read with h5dump; no summary key): the grains next to the bob
(points with r < r_0 + h, all depths) at every frame, their mean shear stress sigma_r_theta
(stress component xz of the Tensor6, docs/output.md), mean structure f and mean granular pressure,
and the fluid points' mean pressure there. Pure Python (no numpy), so that it runs wherever the
CLI does.
"""
import glob
import json
import os
import subprocess
import sys
import tempfile


def fit_line(t, y):
    n = len(t)
    mt, my = sum(t) / n, sum(y) / n
    stt = sum((a - mt) ** 2 for a in t)
    sty = sum((a - mt) * (b - my) for a, b in zip(t, y))
    slope = sty / stt
    icpt = my - slope * mt
    ss_res = sum((b - (icpt + slope * a)) ** 2 for a, b in zip(t, y))
    ss_tot = sum((b - my) ** 2 for b in y)
    return slope, icpt, 1.0 - ss_res / ss_tot if ss_tot > 0 else float("nan")


def h5_array(path, dset, width):
    """Dataset `dset` of `path` as a list of rows of `width` numbers."""
    with tempfile.NamedTemporaryFile("r", suffix=".txt") as tmp:
        subprocess.run(["h5dump", "-y", "-w", "0", "-m", "%.17g", "-d", dset, "-o", tmp.name, path],
                       check=True, stdout=subprocess.DEVNULL)
        vals = [float(x) for x in tmp.read().replace(",", " ").split()]
    return [vals[i:i + width] for i in range(0, len(vals), width)]


def h5_time(path):
    out = subprocess.run(["h5dump", "-m", "%.17g", "-a", "/time", path], check=True, capture_output=True,
                         text=True).stdout
    return float(out.split("(0):")[1].split()[0])


def main(run):
    s = json.load(open(os.path.join(run, "summary.json")))
    h = s["parameters"]["cell_size"]
    print(f"== {run}")
    ff = s.get("front_fit") or {}
    print(f"velocity front: front_speed {s['front_speed']:.4g} m/s, front_fit.r_squared {ff.get('r_squared', float('nan')):.4f}; "
          f"front_farthest {1e3 * s['front_farthest']:.2f} mm at front_farthest_time {1e3 * s['front_farthest_time']:.1f} ms; "
          f"flow_stop_time {s['flow_stop_time']}")
    sf = s.get("structure_front")
    if sf:
        t_wall = s.get("structure_front_wall_time")
        t_end = t_wall if t_wall is not None else sf["time"][-1]
        print(f"structure front (f >= {s['structure_front_threshold']:.4g}): structure_front_wall_time {t_wall}; "
              f"final radius {1e3 * sf['value'][-1]:.1f} mm")
        for t1 in (0.050, t_end):
            pts = [(t, r) for t, r in zip(sf["time"], sf["value"]) if 0.005 - 1e-9 <= t <= t1 + 1e-9]
            slope, _, r2 = fit_line([p[0] for p in pts], [p[1] for p in pts])
            print(f"  fitted speed {slope:.4g} m/s, R^2 {r2:.4f} over {1e3 * pts[0][0]:.1f}-{1e3 * pts[-1][0]:.1f} ms "
                  f"({1e3 * pts[0][1]:.1f} -> {1e3 * pts[-1][1]:.1f} mm)")
    for p, d in zip(s["profiles"], s["newtonian_distance"]):
        r0 = p["r"][0]
        rot = [v * r0 / r for v, r in zip(p["v_over_ui"], p["r"])]
        band = []
        front = float("nan")
        for r, x in zip(p["r"][1:], rot[1:]):
            if x < 0.5:
                front = r
                break
            band.append(x)
        mean = sum(band) / len(band) if band else float("nan")
        print(f"profile {p['angle']:.2f} rad (t {1e3 * p['time']:.1f} ms): newtonian_distance {d:.4f}; v_theta/(omega_bob r) "
              f"{rot[1] if len(rot) > 1 else float('nan'):.3f} one cell from the bob, {rot[3] if len(rot) > 3 else float('nan'):.3f} "
              f"at 3 mm, mean {mean:.3f} over the band to its front at {1e3 * front:.1f} mm; max v/u_i {max(p['v_over_ui']):.3f}")
    oa = s["outer_arrest"]
    print(f"outer_arrest: peak {oa['peak']:.4f} at {1e3 * oa['peak_time']:.1f} ms, time {oa['time']}, final {oa['final']:.4f}")
    frames = sorted(glob.glob(os.path.join(run, "frames", "frame_*.h5")))
    if not frames:
        return
    r0 = s["profiles"][0]["r"][0]
    print("frame time [ms]: grains with r < r_0 + h: mean sigma_r_theta [kPa], f, granular pressure [kPa]; fluid pressure [kPa]")
    for fr in frames:
        t = h5_time(fr)
        xg = h5_array(fr, "/bodies/grains/position", 2)
        near = [i for i, x in enumerate(xg) if x[0] < r0 + h]
        sg = h5_array(fr, "/bodies/grains/stress", 6)
        fg = h5_array(fr, "/bodies/grains/f", 1)
        pg = h5_array(fr, "/bodies/grains/pressure", 1)
        xf = h5_array(fr, "/bodies/fluid/position", 2)
        nearf = [i for i, x in enumerate(xf) if x[0] < r0 + h]
        pf = h5_array(fr, "/bodies/fluid/fluid_pressure", 1)
        n = max(len(near), 1)
        print(f"{1e3 * t:7.2f}: {1e-3 * sum(sg[i][2] for i in near) / n:8.3f} {sum(fg[i][0] for i in near) / n:7.4f} "
              f"{1e-3 * sum(pg[i][0] for i in near) / n:8.3f}; {1e-3 * sum(pf[i][0] for i in nearf) / max(len(nearf), 1):8.3f}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for run in sys.argv[1:]:
        main(run)
