#!/usr/bin/env python3
"""Writes the rheometer-export fixtures of tests/io/test_rheometer.cpp, tests/cli/test_rheometer_cli.cpp
and python/tests/test_read_rheometer.py from oobleck's own steady flow curves (hermes2016,
rate-controlled, on the low-viscosity branch below 0.8 gamma_dot_DST), one file per format and phi:

  trios_phi040.txt        TA TRIOS "Export to LIMS" (TAB, C locale, exponents; mPa.s, %, uN.m)
  rheocompass_phi044.csv  Anton Paar RheoCompass (UTF-16LE with BOM, ';', decimal comma; mPa·s, mN·m)
  rspace_phi046.csv       Malvern rSpace (';', decimal comma, E+003 exponents; kPa, s-¹, %, mm)
  generic_phi048.csv      generic CSV (UTF-8 BOM, ',', '#' comments, quoted names; min, kPa, mPa s)

Every number is printed to 5 significant digits in the file's unit; truth.csv holds the values in
SI with 17 digits (the rate as printed, the stress of the model at that rate), so a reader must
reproduce them to within the printed precision (relative 5e-5). Regenerate (from the repository
root, after building): /usr/bin/python3 tests/rheology/data/rheometer/make_fixtures.py
"""
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[3] / "python"))
import numpy as np  # noqa: E402
import oobleck  # noqa: E402

P = oobleck.load_params("hermes2016")
DIGITS = 5


def sig(x, digits=DIGITS):
    return float(f"{x:.{digits - 1}e}")


def flow(phi, rates):
    """(rate, stress, viscosity) in SI on the low-viscosity branch at the printed rates."""
    rates = np.array([sig(r, 4) for r in rates])
    eta = oobleck.viscosity_at(P, phi, shear_rate=rates)[:, 0]
    return [(float(r), float(e * r), float(e)) for r, e in zip(rates, eta)]


def sweep(phi):
    dst = oobleck.shear_rate_dst(P, phi)
    hi = 1e4 if dst is None else 0.8 * dst
    return flow(phi, np.geomspace(1e-2, hi, 16))


truth = []  # (file, step_name, time [s], shear_rate [1/s], shear_stress [Pa], viscosity [Pa s], strain [-])


def record(file, step, time, rows, step_times):
    out = []
    for t, st, (g, tau, eta) in zip(time, step_times, rows):
        strain = g * st
        truth.append((file, step, t, g, tau, eta, strain))
        out.append((t, st, g, tau, eta, strain))
    return out


def held(file, step, phi, rate, n, dt):
    """n points at a constant rate [1/s], dt [s] apart."""
    t = [sig(dt * (k + 1)) for k in range(n)]
    return record(file, step, t, flow(phi, [rate] * n), t)


def swept(file, step, phi, dt, t0=0.0):
    """The sweep of `phi`, one point per dt [s] of step time, t0 [s] the step's start."""
    curve = sweep(phi)
    st = [sig(dt * (k + 1)) for k in range(len(curve))]
    return record(file, step, [sig(t0 + s) for s in st], curve, st)


def e_trios(x):
    """5.4400e-4 (TRIOS: C locale, exponent without padding)."""
    m, e = f"{x:.4e}".split("e")
    return f"{m}e{int(e)}"


def g_comma(x):
    return f"{x:.5g}".replace(".", ",")


def e_rspace(x):
    """4,7528E+003 (rSpace: decimal comma, three exponent digits)."""
    m, e = f"{x:.4E}".split("E")
    return f"{m.replace('.', ',')}E{int(e):+04d}"


def trios():
    name = "trios_phi040.txt"
    phi = 0.40
    hold_rows = held(name, "Peak hold - 1", phi, 1.0, 4, 5.0)
    curve_rows = swept(name, "Flow sweep - 2", phi, 10.0, t0=20.0)
    L = ["Filename\tcornstarch_phi040.tri", "Instrument name\tDHR-3 5332-0001", "Operator\toobleck test",
         "rundate\t14/03/2024", "Sample name\tcornstarch phi 0.40 (synthetic, hermes2016)",
         "Geometry name\t40 mm parallel plate, 1000 um gap", "Procedure name\tFlow curve",
         "\tPeak hold", "\tFlow sweep", "proceduresegments\tPeak hold#Flow sweep", "",
         "[File Parameters]", "Instrument serial number\t5332-0001", "",
         "[Geometry Parameters]", "Geometry Type\tParallel plate", "Diameter\t40 mm", "Gap\t1000 \u00b5m",
         "Inertia\t12.3 \u00b5N.m.s\u00b2", "",
         "[Temperature Options]", "Temperature\t25 \u00b0C", ""]
    L += ["[step]", "Peak hold - 1", "Time\tStep time\tShear rate\tStress\tViscosity\tTemperature",
          "s\ts\t1/s\tPa\tPa.s\t\u00b0C"]
    for t, s, g, tau, eta, _ in hold_rows:
        L.append("\t".join([e_trios(t), e_trios(s), e_trios(g), e_trios(tau), e_trios(eta), "2.5000e1"]))
    L += ["", "[step]", "Flow sweep - 2",
          "Time\tStep time\tStress\tShear rate\tStrain\tViscosity\tTemperature\tTorque\tStatus",
          "s\ts\tPa\t1/s\t%\tmPa.s\t\u00b0C\t\u00b5N.m\t"]
    for t, s, g, tau, eta, strain in curve_rows:
        torque = tau * math.pi * 0.02 ** 3 / 2 * 1e6  # parallel plate, R = 20 mm, in uN.m
        L.append("\t".join([e_trios(t), e_trios(s), e_trios(tau), e_trios(g), e_trios(100 * strain),
                            e_trios(1e3 * eta), "2.5000e1", e_trios(torque), "0"]))
    L.append("")
    (HERE / name).write_text("\n".join(L), encoding="utf-8")


def rheocompass():
    name = "rheocompass_phi044.csv"
    phi = 0.44
    pre_rows = held(name, "Flow curve 1 - 1", phi, 5.0, 3, 10.0)
    curve_rows = swept(name, "Flow curve 1 - 2", phi, 6.0)
    S = ";"
    L = [f"Project:{S}Cornstarch", f"Test:{S}cornstarch phi 0.44 (synthetic, hermes2016)",
         f"Result:{S}Flow curve 1"]

    def interval(n, rows):
        out = [f"Interval and data points:{S}{n}{S}{len(rows)}",
               S.join(["Interval data:", "Point No.", "Time", "Shear Rate", "Shear Stress", "Viscosity", "Torque",
                       "Status"]),
               S * 7,
               S.join(["", "", "[s]", "[1/s]", "[Pa]", "[mPa\u00b7s]", "[mN\u00b7m]", "[]"])]
        for k, (t, s, g, tau, eta, _) in enumerate(rows):
            torque = "" if k == 1 else g_comma(tau * 2.5e-3)  # one missing value
            status = '"WMa,TruStrain\u2122"' if k % 2 else "Dy_auto"
            out.append(S.join(["", str(k + 1), g_comma(t), g_comma(g), g_comma(tau), g_comma(1e3 * eta), torque,
                               status]))
        return out

    L += interval(1, pre_rows) + interval(2, curve_rows) + [""]
    (HERE / name).write_bytes(b"\xff\xfe" + "\r\n".join(L).encode("utf-16-le"))


def rspace():
    name = "rspace_phi046.csv"
    phi = 0.46
    L = ["Action Name;Time (sequence)(s);Time (action)(s);Shear stress(kPa);Shear rate(s-\u00b9);"
         "Shear viscosity(Pa s);Shear strain(%);Normal force(N);Torque(N m);Temperature(\u00b0C);Gap(mm)"]
    for k in range(3):  # an action that measures no shear
        t = sig(30.0 * (k + 1))
        L.append(f"Equilibration;{e_rspace(t)};{e_rspace(t)};;;;;{e_rspace(0.01)};;{e_rspace(25.0)};{e_rspace(1.0)}")
    rows = swept(name, "Viscometry Table", phi, 8.0, t0=90.0)
    for t, s, g, tau, eta, strain in rows:
        L.append(";".join(["Viscometry Table", e_rspace(t), e_rspace(s), e_rspace(tau / 1e3), e_rspace(g),
                           e_rspace(eta), e_rspace(100 * strain), e_rspace(0.05), e_rspace(tau * 2.5e-3),
                           e_rspace(25.0), e_rspace(1.0)]))
    (HERE / name).write_text("\r\n".join(L) + "\r\n", encoding="utf-8")


def generic():
    name = "generic_phi048.csv"
    phi = 0.48
    rows = swept(name, "generic_phi048", phi, 12.0)
    L = ["# cornstarch phi 0.48 (synthetic, hermes2016): a hand-made table", "#",
         '"Time [min]","Shear rate [s^-1]","Shear stress (kPa)","Viscosity (mPa s)","Shear strain [%]","Note"']
    for k, (t, s, g, tau, eta, strain) in enumerate(rows):
        note = '"ramp, up"' if k < 8 else "plateau"
        L.append(",".join([f"{t / 60:.5g}", f"{g:.5g}", f"{tau / 1e3:.5g}", f"{1e3 * eta:.5g}",
                           f"{100 * strain:.5g}", note]))
    (HERE / name).write_bytes(b"\xef\xbb\xbf" + ("\n".join(L) + "\n").encode("utf-8"))


trios()
rheocompass()
rspace()
generic()
with open(HERE / "truth.csv", "w") as f:
    f.write("# the fixtures' values in SI (make_fixtures.py): time [s], shear_rate [1/s], shear_stress [Pa], "
            "viscosity [Pa s], strain [-]; parameters hermes2016, phi in the file names\n")
    f.write("file,step_name,time,shear_rate,shear_stress,viscosity,strain\n")
    for row in truth:
        f.write(",".join([row[0], row[1]] + [f"{v:.17g}" for v in row[2:]]) + "\n")
print(f"wrote 4 fixtures and truth.csv ({len(truth)} rows) in {HERE}")
