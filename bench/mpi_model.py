#!/usr/bin/python3
"""Parallel efficiency of decomposed runs projected to many ranks (docs/results.md, "Decomposed
runs"). The model, per rank and step, for cubic blocks of a 3D two-phase bed:

  compute        t_c = n / R                          n points per rank, R one core's rate
  halo bytes     B   = sum over split axes of 5 layers x (s + 5)^2 nodes x d doubles x 8 B
                       (s cells per block side; d = 31 for the two phases alone: sums of 3 layers
                       up and 2 down of mass, momentum, force of both phases and the fluid's
                       pressure force and volume, 18 doubles; copies of 2 up and 3 down of both
                       phases' velocities and old velocities and the porosity, 13 doubles; exactly
                       the 2.20 MB that summary.json reports for mpi_3d's two phases. A third body
                       with its contact adds its own sums and copies and the contact's arrays:
                       d = 51 gives the 3.62 MB reported for mpi_3d with its plunger, the default)
  communication  t_x = c_B B + m alpha + 2 P alpha + 2 log2(P) alpha
                       c_B: measured time per halo byte of a whole exchange on this host (packing,
                       the copy, unpacking, and waiting for the slower neighbour), m = 12
                       sendrecv per step; the points' all-to-all (one per body: P messages);
                       the per-step reductions
  efficiency     E   = t_c / (t_c + t_x)             (no overlap of communication and compute)

Defaults are this host's measurements (bench/mpi_scaling.sh, bench/mpi_exchange.cpp).
usage: mpi_model.py [--points 1e8] [--rate 2.1e6] [--c-byte 4.9e-9] [--alpha 0.8e-6] [--doubles 51]
"""
import argparse
import math

ap = argparse.ArgumentParser()
ap.add_argument("--points", type=float, default=1e8, help="total points")
ap.add_argument("--points-per-cell", type=float, default=16.0, help="points per cell (both phases)")
ap.add_argument("--rate", type=float, default=2.1e6, help="point updates/s of one rank (1 thread)")
ap.add_argument("--c-byte", type=float, default=4.9e-9, help="s per halo byte of a whole exchange")
ap.add_argument("--alpha", type=float, default=0.8e-6, help="s per message (latency)")
ap.add_argument("--doubles", type=float, default=51.0, help="halo doubles per node (31: two phases alone)")
args = ap.parse_args()

print(f"{args.points:.3g} points, {args.points_per_cell:g} per cell, R = {args.rate:.3g} /s per rank, "
      f"c_B = {args.c_byte:.2g} s/B, alpha = {args.alpha:.2g} s, d = {args.doubles:g} doubles per halo node")
print(f"{'ranks':>6} {'points/rank':>12} {'block side':>10} {'halo MB':>8} {'t_c [ms]':>9} {'t_x [ms]':>9} "
      f"{'E':>6} {'E, neighbour-only moves':>24}")
for P in (2, 8, 64, 1024):
    n = args.points / P
    s = (n / args.points_per_cell) ** (1.0 / 3.0)
    split_axes = 3 if P >= 8 else 1
    B = split_axes * 5 * (s + 5) ** 2 * args.doubles * 8
    t_c = n / args.rate
    t_x = args.c_byte * B + 12 * args.alpha + 2 * math.log2(P) * args.alpha
    t_all = t_x + 2 * P * args.alpha          # all-to-all of the points (today)
    t_nb = t_x + 2 * 26 * args.alpha          # the 26 neighbours only
    print(f"{P:>6} {n:>12.3g} {s:>10.1f} {B / 1e6:>8.2f} {1e3 * t_c:>9.2f} {1e3 * t_all:>9.2f} "
          f"{t_c / (t_c + t_all):>6.3f} {t_c / (t_c + t_nb):>24.3f}")
