"""oobleck.sweep runs `oobleck sweep` and returns sweep.csv as a DataFrame: one row per run, the
varied keys first, then run, the summaries' scalars, status and message."""
import json
import os
from pathlib import Path

import pytest

import oobleck

SHORT = {"time.duration": 0.002, "analysis.average_from": 0.001, "output.frame_interval": 0.001}


@pytest.fixture(scope="module")
def exe(root):
    path = Path(os.environ.get("OOBLECK_BUILD_DIR") or root / "build" / "release") / "oobleck"
    if not path.exists():
        pytest.skip(f"no CLI at {path}")
    return path


def test_sweep_grid_as_dataframe(root, tmp_path, exe):
    scene = root / "scenes" / "verification" / "settling.toml"
    out = tmp_path / "sweep"
    df = oobleck.sweep(scene, {"phi": "0.2:0.3:0.1", "d": [1e-4, 2e-4]}, jobs=2, out=out, sets=SHORT, threads=1,
                       executable=exe, progress=False)
    assert df.shape[0] == 4
    cols = list(df.columns)
    assert cols[:3] == ["phi", "d", "run"] and cols[-2:] == ["status", "message"]
    assert "settling_velocity" in cols and "parameters.phi" in cols
    assert df["phi"].tolist() == [0.2, 0.2, 0.3, 0.3]
    assert df["d"].tolist() == [1e-4, 2e-4, 1e-4, 2e-4]
    assert df["run"].tolist() == ["phi=0.2_d=0.0001", "phi=0.2_d=0.0002", "phi=0.3_d=0.0001", "phi=0.3_d=0.0002"]
    assert (df["status"] == "ok").all()
    # sweep.csv's units line: d is material.granular.d, "# [m]" in settling.toml (phi has no unit
    # comment), then the summaries' numbers with the units their "units" give
    assert (out / "sweep.csv").read_text().startswith("# units: d=m, ")
    units = df.attrs["units"]
    assert units["d"] == "m" and "phi" not in units and "run" not in units
    assert units["dt"] == "s" and units["parameters.d"] == "m" and units["settling_velocity"] == "m/s"
    assert not any(c.startswith("units.") for c in cols)
    for _, row in df.iterrows():
        s = json.loads((out / row["run"] / "summary.json").read_text())
        assert row["settling_velocity"] == s["settling_velocity"]  # round trip exact
        assert row["parameters.phi"] == s["parameters"]["phi"]
        assert row["steps"] == s["steps"]

    # Called again: every run is complete and skipped; the same table.
    again = oobleck.sweep(scene, {"phi": "0.2:0.3:0.1", "d": [1e-4, 2e-4]}, out=out, sets=SHORT, threads=1,
                          executable=exe, progress=False)
    assert again.shape == df.shape
    assert (again["message"] == "skipped: complete summary.json").all()
    assert again["settling_velocity"].tolist() == df["settling_velocity"].tolist()


def test_sweep_failed_run_and_bad_input(root, tmp_path, exe):
    scene = root / "scenes" / "verification" / "settling.toml"
    sets = {k: v for k, v in SHORT.items() if k != "time.duration"}
    df = oobleck.sweep(scene, {"time.duration": [0.002, -0.001]}, out=tmp_path / "f", sets=sets, threads=1,
                       executable=exe, progress=False)
    assert df["status"].tolist() == ["ok", "failed"]
    assert "must be positive" in df["message"].iloc[1]
    assert df.attrs["returncode"] == 3
    with pytest.raises(oobleck.NumericalError):
        oobleck.sweep(scene, {"time.duration": [0.002, -0.001]}, out=tmp_path / "f", sets=sets, threads=1,
                      executable=exe, check=True, progress=False)
    with pytest.raises(oobleck.InputError, match="step 0 must be > 0"):
        oobleck.sweep(scene, {"phi": "0.1:0.2:0"}, out=tmp_path / "bad", executable=exe, progress=False)
    assert not (tmp_path / "bad").exists()
