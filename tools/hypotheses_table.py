"""Table of the runs of bench/hypotheses.sh CLAIM OUT as Markdown: one row per variant, per point
(a column group) the claim's own quantities from each run's summary.json.

    /usr/bin/python3 tools/hypotheses_table.py s1|s3|s4 OUT

s3: k_l / k_t / k_l/k_t (R² longitudinal / transverse) of the u_z = 0.5 v0 front, whole run
    (velocity_front.speeds) and up to each front's farthest extent (speeds_to_farthest).
s3_recession: how far the u_z = 0.5 v0 front ran ahead of the tip (longitudinal) and past the
    intruder's edge (transverse) before it fell back: farthest extent and its time, and the
    extent at the end of the run (velocity_front.series).
s1: the velocity band's farthest extent (front_farthest, _time), the front speed (front_speed, R²),
    the outer half's arrest (outer_arrest.peak, .time) and the structure front at the wall
    (structure_front_wall_time).
s2: the rod's peak deceleration from the contact force (in g), its speed at 10 and 20 ms and at the
    end, and reproduce's criterion (peak > 10 g and final speed < v0/2).
s4: hub height initial -> final (min), distance, runs_on_surface, sinks.
"""
import json
import pathlib
import sys


def num(x, fmt="{:.3g}"):
    return "—" if x is None else fmt.format(x)


def s3_cell(sp):
    if not sp:
        return "no fit"
    lf, tf = sp["longitudinal_fit"], sp["transverse_fit"]
    return (f"{num(sp['k_l'], '{:.2f}')} / {num(sp['k_t'], '{:.2f}')} / **{num(sp.get('k_l_over_k_t'), '{:.2f}')}** "
            f"({lf['r_squared']:.2f} / {tf['r_squared']:.2f})")


def s3(j):
    vf = j["velocity_front"]
    return [s3_cell(vf.get("speeds")), s3_cell(vf.get("speeds_to_farthest"))]


def recession(frames, side, key):
    """(farthest extent, its time, extent at the end) of one front, in mm and ms."""
    found = [(f[side][key], f["time"]) for f in frames if f[side]["found"]]
    if not found:
        return None
    far = max(found)
    return far[0] * 1e3, far[1] * 1e3, found[-1][0] * 1e3


def s3_recession(j):
    frames = j["velocity_front"]["series"]["frames"]
    cells = []
    for side, key in (("longitudinal", "ahead"), ("transverse", "from_edge")):
        r = recession(frames, side, key)
        cells.append("no front" if r is None else
                     f"{r[0]:.1f} mm at {r[1]:.1f} ms → {r[2]:.1f} mm ({100 * (r[0] - r[2]) / r[0]:.0f}% back)")
    return cells


def s1(j):
    a = j.get("outer_arrest") or {}
    fit = j.get("front_fit") or {}
    return [f"{num(j.get('front_farthest'), '{:.4f}')} m at {num(j.get('front_farthest_time'), '{:.3f}')} s; "
            f"{num(j.get('front_speed'), '{:.3f}')} m/s (R² {num(fit.get('r_squared'), '{:.3f}')}); "
            f"outer peak {num(a.get('peak'), '{:.2f}')}, arrest {num(a.get('time'), '{:.3f}')} s; "
            f"structure at the wall {num(j.get('structure_front_wall_time'), '{:.3f}')} s"]


def s2(j):
    v = j["rod_velocity"]
    v0 = abs(v["value"][0])

    def at(t):
        i = min(range(len(v["time"])), key=lambda k: abs(v["time"][k] - t))
        return abs(v["value"][i])

    # reproduce's criterion: the sustained deceleration (filtered position) > 10 g and a final speed
    # below v0/2; the contact force's peak (the first step's impact spike) is shown beside it
    spike = j["peak_deceleration_from_force"]["peak_deceleration"] / 9.81
    peak = j["peak_deceleration"]["peak_deceleration"] / 9.81 if "peak_deceleration" in j else 0.0
    final = abs(j["final_velocity"])
    met = peak > 10 and final < v0 / 2
    return [f"{peak:.1f} g (spike {spike:.0f} g); {at(0.01):.2f}, {at(0.02):.2f} → {final:.2f} m/s; "
            f"depth {1e3 * j['final_depth']:.0f} mm; {'met' if met else 'not met'}"]


def s4(j):
    return [f"{j['hub_height_initial']:.3f} → {j['hub_height_final']:.3f} ({j['hub_height_min']:.3f}) m, "
            f"{j['distance']:.2f} m; runs: {'yes' if j['runs_on_surface'] else 'no'}, "
            f"sinks: {'yes' if j['sinks'] else 'no'}"]


CLAIMS = {
    "s3": (s3, ["whole run", "to farthest"],
           "k_l / k_t / **k_l/k_t** (R² longitudinal / transverse) of the u_z = 0.5 v_0 front"),
    "s3_recession": (s3_recession, ["ahead of the tip", "past the edge"],
                     "farthest extent of the u_z = 0.5 v_0 front (time) → extent at the end of the run"),
    "s1": (s1, [""], "band's farthest extent, front speed, outer half's arrest, structure front at the wall"),
    "s2": (s2, [""], "sustained deceleration (filtered position; the contact force's impact spike); speed at 10, 20 ms → at the end; final depth; criterion"),
    "s4": (s4, [""], "hub initial → final (min), distance, the two criteria"),
}


def main(claim, out):
    cell, parts, caption = CLAIMS[claim]
    rows, points = {}, []
    for d in sorted(pathlib.Path(out).iterdir()):
        s = d / "summary.json"
        if not d.is_dir() or not s.is_file():
            continue
        variant, point = d.name.rsplit("_", 2)[0], "_".join(d.name.rsplit("_", 2)[1:])
        if not claim.startswith("s3"):
            variant, point = d.name.rsplit("_", 1)
        if point not in points:
            points.append(point)
        rows.setdefault(variant, {})[point] = cell(json.loads(s.read_text()))
    print(caption + "\n")
    heads = [f"{p} {part}".strip() for p in points for part in parts]
    print("| variant | " + " | ".join(heads) + " |")
    print("|---|" + "---|" * len(heads))
    order = ["defaults"] + sorted(v for v in rows if v != "defaults")
    for v in order:
        if v not in rows:
            continue
        cells = []
        for p in points:
            cells += rows[v].get(p, ["not run"] * len(parts))
        print(f"| {v} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
