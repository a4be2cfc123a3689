#!/usr/bin/python3
"""Compare two run folders of `oobleck run` bit for bit (bench/bitwise_check.sh).

Every HDF5 file (checkpoint.h5, frames/*.h5): every dataset and attribute, values compared by
their bytes; summary.json: every key but the wall-time ones; series.csv: byte for byte. Prints
one line per run folder: "identical", or the largest absolute and relative difference of the
numbers that differ and where. Exit status 1 when a folder differs (or a file is missing).
"""
import json
import math
import os
import sys

import h5py
import numpy as np

# summary.json keys that measure the wall clock, not the run
VOLATILE = {"wall_seconds", "point_updates_per_second", "timings_seconds"}


class Diff:
    def __init__(self):
        self.notes = []
        self.max_abs = 0.0
        self.max_rel = 0.0
        self.where = ""

    def numbers(self, a, b, where):
        a = np.asarray(a)
        b = np.asarray(b)
        if a.shape != b.shape or a.dtype != b.dtype:
            self.notes.append(f"{where}: shape/type {a.shape} {a.dtype} vs {b.shape} {b.dtype}")
            return
        if a.dtype.kind in "fc":
            same = a.tobytes() == b.tobytes()
            if not same:
                d = np.abs(a.astype(float) - b.astype(float))
                d = np.where(np.isnan(a) & np.isnan(b), 0.0, d)
                scale = np.maximum(np.abs(a), np.abs(b))
                rel = np.where(scale > 0, d / np.where(scale > 0, scale, 1), 0.0)
                m, r = float(np.nanmax(d)), float(np.nanmax(rel))
                if not math.isfinite(m) or m > self.max_abs or r > self.max_rel:
                    self.where = where
                self.max_abs = max(self.max_abs, m) if math.isfinite(m) else math.inf
                self.max_rel = max(self.max_rel, r) if math.isfinite(r) else math.inf
                self.notes.append(f"{where}: max |diff| {m:.3e}, rel {r:.3e}")
        elif a.dtype.kind in "OSU":
            if a.tolist() != b.tolist():
                self.notes.append(f"{where}: text differs")
        elif a.tobytes() != b.tobytes():
            self.notes.append(f"{where}: values differ")


def compare_h5(fa, fb, diff, tag):
    with h5py.File(fa, "r") as a, h5py.File(fb, "r") as b:
        names_a, names_b = [], []
        a.visit(names_a.append)
        b.visit(names_b.append)
        if sorted(names_a) != sorted(names_b):
            diff.notes.append(f"{tag}: objects differ {sorted(set(names_a) ^ set(names_b))[:5]}")
        for obj_name in [""] + sorted(set(names_a) & set(names_b)):
            oa = a[obj_name] if obj_name else a
            ob = b[obj_name] if obj_name else b
            if isinstance(oa, h5py.Dataset):
                diff.numbers(oa[()], ob[()], f"{tag}:{obj_name}")
            ka, kb = sorted(oa.attrs.keys()), sorted(ob.attrs.keys())
            if ka != kb:
                diff.notes.append(f"{tag}:{obj_name}: attributes {ka} vs {kb}")
            for k in set(ka) & set(kb):
                diff.numbers(oa.attrs[k], ob.attrs[k], f"{tag}:{obj_name}@{k}")


def compare_json(x, y, diff, where):
    if isinstance(x, dict) and isinstance(y, dict):
        if sorted(x) != sorted(y):
            diff.notes.append(f"{where}: keys {sorted(set(x) ^ set(y))}")
        for k in set(x) & set(y):
            if k in VOLATILE or k.startswith("units"):
                continue
            compare_json(x[k], y[k], diff, f"{where}.{k}")
    elif isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        for i, (u, v) in enumerate(zip(x, y)):
            compare_json(u, v, diff, f"{where}[{i}]")
    elif isinstance(x, float) or isinstance(y, float):
        if isinstance(x, (int, float)) and isinstance(y, (int, float)):
            diff.numbers(np.float64(x), np.float64(y), where)
        else:
            diff.notes.append(f"{where}: {x!r} vs {y!r}")
    elif x != y:
        diff.notes.append(f"{where}: {x!r} vs {y!r}")


def compare_series(fa, fb, diff, tag):
    la = open(fa).read().splitlines()
    lb = open(fb).read().splitlines()
    if la == lb:
        return
    if len(la) != len(lb):
        diff.notes.append(f"{tag}: {len(la)} vs {len(lb)} lines")
        return
    for i, (u, v) in enumerate(zip(la, lb)):
        if u == v:
            continue
        try:
            x = np.array([float(t) for t in u.split(",")])
            y = np.array([float(t) for t in v.split(",")])
            diff.numbers(x, y, f"{tag} line {i + 1}")
        except ValueError:
            diff.notes.append(f"{tag} line {i + 1}: text differs")


def compare_runs(ra, rb):
    diff = Diff()
    for root, _, files in os.walk(ra):
        for f in sorted(files):
            pa = os.path.join(root, f)
            rel = os.path.relpath(pa, ra)
            pb = os.path.join(rb, rel)
            if not os.path.exists(pb):
                diff.notes.append(f"{rel}: missing")
                continue
            if f.endswith(".h5"):
                compare_h5(pa, pb, diff, rel)
            elif f == "summary.json":
                compare_json(json.load(open(pa)), json.load(open(pb)), diff, "summary")
            elif f.endswith(".csv"):
                compare_series(pa, pb, diff, rel)
    return diff


def main():
    ref, new = sys.argv[1], sys.argv[2]
    tol = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    bad = 0
    for run in sorted(os.listdir(ref)):
        ra, rb = os.path.join(ref, run), os.path.join(new, run)
        if not os.path.isdir(ra):
            continue
        if not os.path.isdir(rb):
            print(f"{run:28s} MISSING")
            bad += 1
            continue
        d = compare_runs(ra, rb)
        if not d.notes:
            print(f"{run:28s} identical")
        else:
            other = [n for n in d.notes if "max |diff|" not in n]
            ok = not other and d.max_rel <= tol and "np2" in run
            print(f"{run:28s} {'within tolerance' if ok else 'DIFFERS'}: max |diff| {d.max_abs:.3e}, "
                  f"max rel {d.max_rel:.3e} ({d.where}); {len(d.notes)} item(s)")
            for n in other[:5]:
                print(f"    {n}")
            bad += 0 if ok else 1
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
