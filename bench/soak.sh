#!/usr/bin/env bash
# Soak test (docs/reliability.md): the wheel for 1 s of simulated time (50 000 steps) with a frame
# and a checkpoint every 0.1 s, while its resident memory (VmRSS) and open file descriptors are
# sampled every 0.5 s of wall time. Writes OUT/soak.csv (wall_s, rss_kB, fds) and OUT/soak.png,
# and fails when
#   - the resident memory grows after the first second of wall time by more than 2 % (+1 MB),
#   - the open file descriptors at the end exceed those at the start of the stepping,
#   - the run folder holds other than 11 frames and one checkpoint, or a left-over temporary file.
#
#   bash bench/soak.sh [THREADS] [OUT]     (defaults: 2, out/soak; ~4 min on 2 threads)
set -euo pipefail
cd "$(dirname "$0")/.."
THREADS=${1:-2}
OUT=${2:-out/soak}
B=build/release/oobleck
[ -x "$B" ] || { echo "soak: build first (cmake --preset release && cmake --build --preset release)"; exit 2; }
rm -rf "$OUT" && mkdir -p "$(dirname "$OUT")"
LOG=$(mktemp)
"$B" run scenes/paper/wheel.toml --set duration=1.0 --set output.frame_interval=0.1 \
  --checkpoint-every 5000 --threads "$THREADS" --quiet --out "$OUT" >"$LOG" 2>&1 &
pid=$!
samples=$(mktemp)
echo "wall_s,rss_kB,fds" >"$samples"
t0=$EPOCHREALTIME
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  fds=$(ls "/proc/$pid/fd" 2>/dev/null | wc -l || true)
  [ -n "$rss" ] && echo "$(awk -v a="$EPOCHREALTIME" -v b="$t0" 'BEGIN {printf "%.2f", a - b}'),$rss,$fds" >>"$samples"
  sleep 0.5
done
wait "$pid" || { cat "$LOG"; echo "soak: the run failed"; exit 1; }
cat "$LOG"
mv "$samples" "$OUT/soak.csv"
/usr/bin/python3 - "$OUT" <<'EOF'
import csv, glob, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

out = sys.argv[1]
rows = [tuple(map(float, r)) for r in list(csv.reader(open(f"{out}/soak.csv")))[1:]]
t, rss, fds = zip(*rows)
settled = [r for r in rows if r[0] >= 1.0]
ok = True
if len(settled) < 10:
    print(f"soak: only {len(settled)} samples after 1 s of wall time: too short to judge"); ok = False
else:
    r1, rmax = settled[0][1], max(r[1] for r in settled)
    growth = (rmax - r1) / r1
    print(f"soak: RSS {r1 / 1024:.1f} MB at {settled[0][0]:.1f} s, max {rmax / 1024:.1f} MB after it "
          f"(+{100 * growth:.2f} %), {len(rows)} samples over {t[-1]:.0f} s")
    if rmax - r1 > 0.02 * r1 + 1024:
        print("soak: FAIL resident memory grows"); ok = False
    f_start, f_end = settled[0][2], rows[-1][2]
    print(f"soak: open file descriptors {int(f_start)} after 1 s, {int(f_end)} at the end, max {int(max(fds))}")
    if f_end > f_start:
        print("soak: FAIL file descriptors left open"); ok = False
frames = sorted(glob.glob(f"{out}/frames/*.h5"))
sizes = [os.path.getsize(f) for f in frames]
leftovers = [p for p in os.listdir(out) if ".tmp" in p] + [p for p in os.listdir(f"{out}/frames") if ".tmp" in p]
total = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(out) for f in fs)
print(f"soak: {len(frames)} frames of {min(sizes) / 1e6:.2f}-{max(sizes) / 1e6:.2f} MB, checkpoint "
      f"{os.path.getsize(out + '/checkpoint.h5') / 1e6:.2f} MB, run folder {total / 1e6:.1f} MB")
if len(frames) != 11 or leftovers:
    print(f"soak: FAIL expected 11 frames and no temporary file, found {len(frames)} and {leftovers}"); ok = False
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(t, [r / 1024 for r in rss], label="resident memory")
ax.set_xlabel("wall time [s]"); ax.set_ylabel("VmRSS [MB]")
ax.set_ylim(0, 1.2 * max(rss) / 1024)
ax.set_title("wheel, 1 s simulated, frame + checkpoint every 0.1 s")
fig.tight_layout(); fig.savefig(f"{out}/soak.png", dpi=120)
print(f"soak: {out}/soak.csv, {out}/soak.png")
sys.exit(0 if ok else 1)
EOF
