"""pytest set-up: the package from this checkout (python/oobleck with the module CMake built in
$OOBLECK_BUILD_DIR or build/release), unless OOBLECK_TEST_INSTALLED=1 tests an installed one."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("OOBLECK_BUILD_DIR") or ROOT / "build" / "release")
if not os.environ.get("OOBLECK_TEST_INSTALLED"):
    sys.path.insert(0, str(ROOT / "python"))


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """Runs the CLI of the same build; returns its stdout (fails on a non-zero exit)."""
    exe = BUILD / "oobleck"
    if not exe.exists():
        pytest.skip(f"no CLI at {exe}")

    def run(*args, check=True):
        r = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, cwd=ROOT)
        if check and r.returncode != 0:
            raise AssertionError(f"oobleck {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}")
        return r
    return run
