#!/usr/bin/env python3
"""Write an S3 intruder case for the authors' code (aaronbaumgarten/mpm_3d, `mpm_v3 -c`).

The set-up of scenes/paper/intrusion.toml in their input format: an axisymmetric 50 x 35 mm grid
of 1 mm linear cells (CartesianLinear, TYPE = 4), a bed 30 mm deep of grains (Cornstarch) and
fluid (SlurryFluidPhase), each filled with 2 x 2 points per cell at the cell's quarter points
(the positions oobleck's fill_box uses), and a rigid flat-ended intruder of radius 5 mm from the
surface to the grid's top, driven down at v0 (AssignedVelocity) with frictionless contact
(SlurryContact, mu_f = 0), explicit USL with pure FLIP (their only update; `--cpdi` picks their
solver's shape-function option). Parameters: oobleck's hermes2016 preset with the scene's G, K, K_0,
rho_s = rho_f = 1620, eta_0 = 4.6 mPa s, kappa = 1e8 Pa (docs/cross_code.md lists each one).

Initial state (= oobleck's `initial_state = "hydrostatic"` for this density-matched bed): grain
stress zero (the buoyant weight phi (rho_s - rho_f) g is zero), fluid pressure rho_f g (30 mm - z)
(HydrostaticBody on the fluid). HydrostaticBody measures depth from its highest point; one
inactive fluid point (active = 0, zero mass) at z = 30 mm puts that height on the free surface,
as in oobleck (without it the top row's pressure would be 0 instead of rho_f g h/4 = 4 Pa).

Point files (their DefaultPoints format, 2D): first line the count, then per point
`m v r z v_r v_z active`, with m and v per unit area of the (r, z) plane; their reader multiplies
both by r (per-radian values in axisymmetric jobs).

    python3 mpm3d_case.py --phi 0.47 --v0 0.2 --duration 0.008 --frame-interval 2.5e-4 --out DIR
    (cd DIR && mpm_v3 -c intrusion.cfg)      # frames: DIR/output/fpd.<body id>.<name>.<frame>.vtk
"""
import argparse
import os

# hermes2016 preset (presets/hermes2016.toml) with the S3 scene's overrides
# (scenes/paper/intrusion.toml): G, K, K_0, rho_s, rho_f, eta_0, kappa.
G = 3.8e7          # [Pa] granular shear modulus (scene)
K = 8.3e7          # [Pa] granular bulk modulus (scene)
MU_1 = 1.19        # [-] mu_c
A_0 = 0.8          # [-] a at f = 0
A_INF = 0.8        # [-] a at f = 1
K_3 = 4.715        # [-] dilatancy slope
K_4 = 0.0          # [-] compaction-rate weight
K_0 = 0.2          # [-] structure rate constant (scene; their K_5)
ETA_B1 = 1.86e4    # [1/(Pa s)] E8 first term coefficient (their K_6), exponent ALPHA
ALPHA = 4.0        # [-]
ETA_B2 = 9.3e-3    # [1/(Pa s)] E8 second term (their K_7; its exponent 0.1 is fixed in their code)
PHI_J = 0.535      # [-]
PHI_C = 0.436      # [-]
DELTA = 0.0        # [-]
TAU_STAR = 5.35    # [Pa]
RHO_S = 1620.0     # [kg/m^3] grains (density matched)
RHO_F = 1620.0     # [kg/m^3] fluid
ETA_0 = 4.6e-3     # [Pa s] (scene)
D = 5.85e-6        # [m] grain diameter
KAPPA = 1.0e8      # [Pa] fluid bulk modulus
F_0 = 0.0          # [-] initial structure (oobleck starts every grain point at f = 0)
G_ACC = 9.81       # [m/s^2] their DefaultDriver's fixed gravity (-9.81 along z)

# geometry (scene)
LR, LZ, H = 0.050, 0.035, 0.001   # grid [m], cell [m]
BED = 0.030                       # bed depth [m]
R_INT = 0.005                     # intruder radius [m]
PPC = 2                           # points per cell per axis
RHO_INTRUDER = 1.0e9              # [kg/m^3]: their contact shares momentum with the body's nodal
                                  # mass; a prescribed body is infinitely heavy in oobleck, so a
                                  # heavy intruder (m_b/m_grains ~ 1e6) gives the same impulse


def youngs_and_poisson(g, k):
    e = 9.0 * k * g / (3.0 * k + g)
    nu = (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g))
    return e, nu


def box_points(r0, r1, z0, z1):
    dx = H / PPC
    nr, nz = round((r1 - r0) / dx), round((z1 - z0) / dx)
    # oobleck's fill_box order: the last axis fastest
    return [(r0 + (i + 0.5) * dx, z0 + (j + 0.5) * dx) for i in range(nr) for j in range(nz)]


def write_points(path, pts, density, velocity=(0.0, 0.0), extra=()):
    area = (H / PPC) ** 2
    with open(path, "w") as f:
        f.write("%d\n" % (len(pts) + len(extra)))
        for r, z in pts:
            f.write("%.17g %.17g %.17g %.17g %.17g %.17g 1\n" % (density * area, area, r, z, velocity[0], velocity[1]))
        for line in extra:
            f.write(line + "\n")


CFG = """# S3 intruder (scenes/paper/intrusion.toml) for mpm_3d; written by oobleck's bench/cross_code/mpm3d_case.py
# phi = {phi}, v0 = {v0} m/s, dt = {dt} s, to {duration} s
job
{{
    dt = {dt}
    t = 0
    TYPE = 4
}}

serializer
{{
    class = "DefaultVTK"
    properties = {{{fps}}}
    int-properties = {{}}
    str-properties = {{"output","save","intrusion"}}
}}

driver
{{
    class = "DefaultDriver"
    #{{stop time}}: the duration and 2.5 steps, so that the frame at the duration is written
    properties = {{{stop}}}
    int-properties = {{}}
    str-properties = {{}}
}}

solver
{{
    class = "ExplicitUSL"
    properties = {{}}
    #{{cpdi_spec (1: their default, linear shape functions averaged over the point's domain; 0: plain linear), contact_spec = 1: implicit (on the predicted momenta)}}
    int-properties = {{{cpdi}, 1}}
    str-properties = {{}}
}}

grid
{{
    class = "CartesianLinear"
    properties = {{{lr}, {lz}}}
    int-properties = {{{nr}, {nz}}}
    str-properties = {{}}
}}

body
{{
    class = "DefaultBody"
    name = "grains"
    point-file = "grains.points"
    properties = {{}}

    point-class = "DefaultPoints"
    point-props = {{}}
    point-int-props = {{}}
    point-str-props = {{}}

    node-class = "DefaultNodes"
    node-props = {{}}
    node-int-props = {{}}
    node-str-props = {{}}

    material-class = "Cornstarch"
    #{{E, nu, mu_1, a_0, a_inf, K_3, K_4, K_5, K_6, phi_j, phi_c, Delta, tau_star, alpha, grains_rho, eta_0, grains_d, fluid_rho, K_7, c_0}}
    material-props = {{{cornstarch}}}
    material-int-props = {{}}
    material-str-props = {{"fluid"}}

    boundary-class = "CartesianBoxCustom"
    #{{-r: axis (frictionless), +r: no-slip, -z: no-slip, +z: free}}
    boundary-props = {{}}
    boundary-int-props = {{1, 0, 0, -1}}
    boundary-str-props = {{}}
}}

body
{{
    class = "HydrostaticBody"
    name = "fluid"
    point-file = "fluid.points"
    #{{g, effective density}}: p = rho_f g (z_top - z), z_top = the highest point (the inactive one at the surface)
    properties = {{{g}, {rho_f}}}

    point-class = "DefaultPoints"
    point-props = {{}}
    point-int-props = {{}}
    point-str-props = {{}}

    node-class = "DefaultNodes"
    node-props = {{}}
    node-int-props = {{}}
    node-str-props = {{}}

    material-class = "SlurryFluidPhase"
    #{{K, eta_0, solid_rho}}
    material-props = {{{kappa}, {eta_0}, {rho_s}}}
    material-int-props = {{}}
    material-str-props = {{"grains"}}

    boundary-class = "CartesianBoxCustom"
    boundary-props = {{}}
    boundary-int-props = {{1, 0, 0, -1}}
    boundary-str-props = {{}}
}}

body
{{
    class = "DefaultBody"
    name = "intruder"
    point-file = "intruder.points"
    properties = {{}}

    point-class = "DefaultPoints"
    point-props = {{}}
    point-int-props = {{}}
    point-str-props = {{}}

    node-class = "DefaultNodes"
    node-props = {{}}
    node-int-props = {{}}
    node-str-props = {{}}

    boundary-class = "AssignedVelocity"
    boundary-props = {{0, {vz}}}
    boundary-int-props = {{}}
    boundary-str-props = {{}}
}}

contact
{{
    class = "SlurryMixture"
    name = "mixture"
    #{{grains_rho, grains_d, eta_0, fluid_rho}} (Beetstra drag)
    properties = {{{rho_s}, {d}, {eta_0}, {rho_f}}}
    int-properties = {{}}
    str-properties = {{"grains", "fluid"}}
}}

contact
{{
    class = "SlurryContact"
    name = "intruder_contact"
    #{{mu_f}}: frictionless
    properties = {{{mu_f}}}
    int-properties = {{}}
    str-properties = {{"intruder", "grains", "fluid"}}
}}
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--phi", type=float, required=True)
    ap.add_argument("--v0", type=float, required=True, help="intruder speed [m/s] (downward)")
    ap.add_argument("--duration", type=float, required=True, help="[s]")
    ap.add_argument("--dt", type=float, default=1e-6, help="[s]")
    ap.add_argument("--frame-interval", type=float, default=2.5e-4, help="[s]")
    ap.add_argument("--friction", type=float, default=0.0, help="intruder-grains Coulomb coefficient")
    ap.add_argument("--cpdi", type=int, choices=(0, 1), default=1,
                    help="their solver's cpdi_spec: 1 (its default when int-properties is empty): the linear "
                         "shape functions averaged over the 4 corners at +-extent/2 of each point (their "
                         "'not true CPDI', Dunatunga & Kamrin 2017); 0: plain linear shape functions")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()

    os.makedirs(os.path.join(a.out, "output"), exist_ok=True)
    os.makedirs(os.path.join(a.out, "save"), exist_ok=True)
    bed = box_points(0.0, LR, 0.0, BED)
    write_points(os.path.join(a.out, "grains.points"), bed, a.phi * RHO_S)
    # the inactive, massless point at the free surface (see the module docstring)
    write_points(os.path.join(a.out, "fluid.points"), bed, (1.0 - a.phi) * RHO_F,
                 extra=["0 %.17g %.17g %.17g 0 0 0" % ((H / PPC) ** 2, LR / 2, BED)])
    write_points(os.path.join(a.out, "intruder.points"), box_points(0.0, R_INT, BED, LZ), RHO_INTRUDER,
                 velocity=(0.0, -a.v0))
    e, nu = youngs_and_poisson(G, K)
    cornstarch = [e, nu, MU_1, A_0, A_INF, K_3, K_4, K_0, ETA_B1, PHI_J, PHI_C, DELTA, TAU_STAR, ALPHA,
                  RHO_S, ETA_0, D, RHO_F, ETA_B2, F_0]
    fmt = lambda x: "%.17g" % x
    with open(os.path.join(a.out, "intrusion.cfg"), "w") as f:
        f.write(CFG.format(phi=a.phi, v0=a.v0, dt=fmt(a.dt), duration=fmt(a.duration), stop=fmt(a.duration + 2.5 * a.dt), fps=fmt(1.0 / a.frame_interval),
                           lr=fmt(LR), lz=fmt(LZ), nr=round(LR / H), nz=round(LZ / H),
                           cornstarch=", ".join(fmt(x) for x in cornstarch), g=fmt(G_ACC), rho_f=fmt(RHO_F),
                           rho_s=fmt(RHO_S), kappa=fmt(KAPPA), eta_0=fmt(ETA_0), d=fmt(D), vz=fmt(-a.v0),
                           mu_f=fmt(a.friction), cpdi=a.cpdi))


if __name__ == "__main__":
    main()
