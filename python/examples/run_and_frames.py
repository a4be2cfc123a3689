# %% A short settling run (V4) and a look at its frames.
import sys
from pathlib import Path

import oobleck

root = Path(__file__).resolve().parents[2]
out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_examples") / "settling"
summary = oobleck.run(root / "scenes" / "verification" / "settling.toml", out, threads=1,
                      set={"time.duration": 0.01})
print({k: summary[k] for k in ("points", "steps", "wall_seconds", "complete")})

# %% the run folder: summary, series (DataFrame) and frames (h5py, read lazily)
run = oobleck.open_run(out)
print(run.series.tail(3))
last = run.frames[-1]
body = last.bodies[0]
print(f"frame at t = {last.time:.4g} s, body {body!r}: fields {last[body].keys()}")
v = last[body]["velocity"]
print("mean settling velocity [m/s]:", v[:, 1].mean())
