"""Every command that README.md and docs/user-guide.md quote runs and exits 0 (issue 43).

The commands are read from the documents themselves: every line of their ```bash blocks that
starts with `$B `, `oobleck `, `bash scripts/`, `mpirun ` or `/usr/bin/python3 ` (lines joined at
a trailing backslash, comments left to bash), and the `$B ...` commands of the user guide's table
of scenes. Each document's commands run in order, with `B` = this build's CLI, in a scratch folder
that links the repository's folders (scenes/, docs/, tests/, tools/, scripts/, build/, ...) and
holds its own out/, so later commands find the runs of earlier ones (the plots) and nothing is
written into the checkout.

A command that would run long is made short by the table SHORTER (arguments appended: a later
`--set` wins) or rewritten by REPLACED (a placeholder in the text); SKIPPED names the commands
that cannot run here, with the reason. Every key of the three tables must still be quoted by its
document, so the tables cannot go stale; a command that is in none runs exactly as written.
Each `oobleck run`/`sweep` is given `--threads 1`. `pytest -s` prints each command as run, with
its wall time.
"""
import os
import re
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("OOBLECK_BUILD_DIR") or ROOT / "build" / "release")
EXE = BUILD / "oobleck"
STARTS = ("$B ", "oobleck ", "bash scripts/", "mpirun ", "/usr/bin/python3 ")
TIMEOUT_S = 120  # per command: a command this slow needs an entry in SHORTER

# Short runs: 2 ms of simulated time and the coarse grids of the quick variants.
INTRUSION = "--set cell_size=0.0025 --set duration=0.002"
ROD = "--set cell_size=0.005 --set duration=0.004"
WHEEL = '--set "cells=[50,25]" --set time.dt=2e-4 --set duration=0.02'
SHORTER = {
    # README.md
    "$B run scenes/verification/settling.toml --out out/settling":
        "--set time.duration=0.002 --set analysis.average_from=0",
    "$B run scenes/verification/couette_axisym.toml": "--set time.duration=0.002",
    "$B run scenes/paper/annular_shear.toml --set u_inner=0.084": "--set duration=0.002",
    "$B run scenes/paper/intrusion.toml --set phi=0.49 --set v0=0.5": INTRUSION,
    "$B run scenes/paper/rod_impact.toml --set v0=1.0": ROD,
    "$B run scenes/paper/wheel.toml --set omega=1": WHEEL,
    "$B sweep scenes/paper/intrusion.toml --vary phi=0.46:0.50:0.01 --vary v0=0.2,0.5 --jobs 2 "
    "--out out/s3_sweep --plot k_l_over_k_t": INTRUSION,
    # docs/user-guide.md: the table of scenes
    "$B run scenes/paper/annular_shear.toml --out out/annular": "--set duration=0.004",
    "$B run scenes/paper/intrusion.toml --set phi=0.49 --set v0=0.5 --out out/intrusion": INTRUSION,
    "$B run scenes/paper/intrusion_deep.toml --set phi=0.49 --out out/intrusion_deep":
        "--set cell_size=0.005 --set duration=0.002",
    "$B run scenes/paper/rod_impact.toml --set v0=1.0 --out out/rod": ROD,
    "$B run scenes/paper/rod_impact_large.toml --set v0=2 --out out/rod_large":
        "--set cell_size=0.0075 --set duration=0.002",
    "$B run scenes/paper/wheel.toml --set omega=10 --out out/wheel10": WHEEL,
    # docs/user-guide.md: the coarse variants (the plots below read them) and the sweep
    "$B run scenes/paper/intrusion.toml --set cell_size=0.0025 --set duration=0.01 --out out/intrusion_quick":
        '--set duration=0.004 --set "analysis.snapshot_times=[0.002,0.004]"',
    '$B run scenes/paper/rod_impact.toml --set cell_size=0.005 --set duration=0.02 '
    '--set "analysis.snapshot_times=[0.02]" --out out/rod_quick':
        '--set duration=0.006 --set "analysis.snapshot_times=[0.006]"',
    '$B run scenes/paper/wheel.toml --set "cells=[50,25]" --set time.dt=2e-4 --set duration=1.0 --set omega=1 '
    '--out out/wheel_quick': '--set duration=0.04 --set "analysis.snapshot_times=[0.02,0.04]"',
    '$B run scenes/paper/wheel.toml --set "cells=[50,25]" --set time.dt=2e-4 --set duration=1.0 --set omega=10 '
    '--out out/wheel10_quick': '--set duration=0.04 --set "analysis.snapshot_times=[0.02,0.04]"',
    '$B run scenes/paper/wheel.toml --set "cells=[50,25]" --set time.dt=1e-4 --set duration=1.0 --set G=3.8e6 '
    '--set K=8.3e6 --out out/wheel10_stiff_quick': "--set duration=0.04",
    "$B sweep scenes/paper/intrusion.toml --vary phi=0.46:0.50:0.01 --vary v0=0.2,0.5 --set cell_size=0.0025 "
    "--set duration=0.01 --jobs 2 --out out/s3_sweep --plot k_l_over_k_t": "--set duration=0.002",
}
REPLACED = {
    # SCENE.toml and "..." are placeholders: a real scene, a checkpoint, a stop and the restart.
    "$B run SCENE.toml --checkpoint-every 500 ...; $B run --restart out/NAME":
        f"$B run scenes/paper/intrusion.toml {INTRUSION} --checkpoint-every 200 --stop-after 400 --out out/NAME"
        " --threads 1; $B run --restart out/NAME --threads 1",
    # "..." stands for more run folders: the one quick run.
    "/usr/bin/python3 tools/plot_intrusion.py --factors out/k.png out/intrusion_quick ...":
        "/usr/bin/python3 tools/plot_intrusion.py --factors out/k.png out/intrusion_quick",
    "/usr/bin/python3 tools/plot_rod.py --dynamics out/rod_dyn.png out/rod_quick ...":
        "/usr/bin/python3 tools/plot_rod.py --dynamics out/rod_dyn.png out/rod_quick",
}
SKIPPED = {
    "bash scripts/demo": "installs Debian packages and builds (scripts/bootstrap): what CI did before this test",
    "bash scripts/test": "the whole test suite, this test included",
    "mpirun --allow-run-as-root -np 2 $B run scenes/verification/settling_3d.toml --threads 1":
        "needs Open MPI and two ranks; decomposed runs are ctest's MPI tests (docs/mpi.md)",
    "mpirun -np 8 $B run scenes/paper/rod_impact_3d.toml --out out/rod_3d": "8 MPI ranks, 8.0e6 points",
    "mpirun -np 8 $B run scenes/paper/wheel_3d.toml --set omega=10 --out out/wheel_3d": "8 MPI ranks, 3.9e6 points",
    "$B reproduce --quick --out out/reproduce":
        "about 2 minutes on one thread: ctest ReproduceCli.QuickReportsEveryClaimWithNumbersAndAVerdict runs it whole",
    "$B reproduce --out out/reproduce_full": "the paper's resolutions: hours",
}


def commands(doc):
    """The commands `doc` quotes, in the document's order: the command lines of its ```bash blocks
    and the `$B run ...` cells of its tables."""
    found, block = [], None
    for line in (ROOT / doc).read_text(encoding="utf-8").splitlines():
        if block is not None:
            if line.startswith("```"):
                for cmd in re.sub(r"\\\n\s*", "", "\n".join(block)).splitlines():
                    cmd = re.sub(r"\s+#.*$", "", cmd.strip())  # a trailing comment (none sits inside quotes)
                    if cmd.startswith(STARTS):
                        found.append(cmd)
                block = None
            else:
                block.append(line)
        elif line.startswith("```bash"):
            block = []
        elif line.startswith("|"):
            found += [c for c in re.findall(r"`([^`]+)`", line) if c.startswith(("$B run ", "mpirun "))]
    return found


def plan(doc):
    """(quoted command, command to run or None, why) for each command of `doc`."""
    out = []
    for cmd in commands(doc):
        if cmd in SKIPPED:
            out.append((cmd, None, SKIPPED[cmd]))
            continue
        run = REPLACED.get(cmd, cmd)
        if run.startswith("oobleck "):
            run = "$B " + run[len("oobleck "):]
        if cmd in SHORTER:
            run += " " + SHORTER[cmd]
        if re.match(r"\$B (run|sweep) ", run) and "--threads" not in run:
            run += " --threads 1"
        why = "shortened" if cmd in SHORTER else "placeholder replaced" if cmd in REPLACED else "as written"
        out.append((cmd, run, why))
    return out


def scratch(tmp_path):
    """A folder that looks like the checkout (links to its top-level entries) with its own out/."""
    for entry in ROOT.iterdir():
        if entry.name not in ("out", ".git") and not entry.name.startswith(".venv"):
            (tmp_path / entry.name).symlink_to(entry)
    (tmp_path / "out").mkdir()
    return tmp_path


def test_the_tables_name_quoted_commands():
    quoted = set(commands("README.md")) | set(commands("docs/user-guide.md"))
    stale = sorted((set(SHORTER) | set(REPLACED) | set(SKIPPED)) - quoted)
    assert stale == [], "entries for commands the documents no longer quote:\n" + "\n".join(stale)
    assert len(quoted) > 20


@pytest.mark.parametrize("doc", ["README.md", "docs/user-guide.md"])
def test_every_quoted_command_runs(doc, tmp_path):
    if not EXE.exists():
        pytest.skip(f"no CLI at {EXE}")
    cwd = scratch(tmp_path)
    env = dict(os.environ, B=str(EXE), OOBLECK=str(EXE), CI="1", MPLBACKEND="Agg")
    failures, ran = [], []
    for cmd, run, why in plan(doc):
        if run is None:
            continue
        t0 = time.monotonic()
        try:
            r = subprocess.run(["bash", "-c", "set -eo pipefail; " + run], cwd=cwd, env=env, capture_output=True,
                               text=True, timeout=TIMEOUT_S)
            code, tail = r.returncode, (r.stdout + r.stderr).strip().splitlines()[-3:]
        except subprocess.TimeoutExpired:
            code, tail = "timeout", [f"over {TIMEOUT_S} s: give it a shorter run in SHORTER"]
        ran.append(f"{time.monotonic() - t0:6.1f} s  {why:20}  {run}")
        if code != 0:
            failures.append(f"{cmd}\n  ran: {run}\n  exit {code}: " + "\n  ".join(tail))
    print(f"{doc}: {len(ran)} commands\n" + "\n".join(ran))
    assert failures == [], f"{doc}: commands that failed:\n" + "\n".join(failures)
