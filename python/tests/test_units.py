"""Units in a run's outputs (docs/output.md, "Units"): series.csv starts with one '# units:' line
naming every column (per radian in an axisymmetric run), which pandas and open_run skip; every
dataset of a frame file carries a `units` attribute."""
import pandas as pd
import pytest

import oobleck


@pytest.fixture(scope="module")
def axisym_run(cli, root, tmp_path_factory):
    out = tmp_path_factory.mktemp("units") / "couette"
    cli("run", root / "scenes" / "verification" / "couette_axisym.toml", "--set", "time.duration=0.002",
        "--threads", 1, "--quiet", "--out", out)
    return out


def test_series_units_line_names_every_column(axisym_run):
    lines = (axisym_run / "series.csv").read_text().splitlines()
    assert lines[0].startswith("# units: ") and not lines[1].startswith("#")
    units = dict(item.split("=", 1) for item in lines[0][len("# units: "):].split(", "))
    header = lines[1].split(",")
    assert list(units) == header
    assert units["time"] == "s" and units["step"] == "1"
    assert units["mass_fluid"] == "kg/rad"  # axisymmetric: per radian
    assert units["kinetic_energy_fluid"] == "J/rad"
    df = pd.read_csv(axisym_run / "series.csv", comment="#")
    assert list(df.columns) == header
    assert list(oobleck.open_run(axisym_run).series.columns) == header
    assert len(df) == len(lines) - 2


def test_every_frame_dataset_has_units(axisym_run):
    h5py = pytest.importorskip("h5py")
    with h5py.File(sorted((axisym_run / "frames").glob("frame_*.h5"))[0], "r") as f:
        found = {}
        f.visititems(lambda name, obj: found.__setitem__(name, obj.attrs.get("units"))
                     if isinstance(obj, h5py.Dataset) else None)
    assert found, "no datasets"
    missing = [name for name, u in found.items() if u is None]
    assert not missing, missing
    text = {name: (u.decode() if isinstance(u, bytes) else str(u)) for name, u in found.items()}
    assert text["bodies/fluid/position"] == "m"
    assert text["bodies/fluid/mass"] == "kg/rad"
    assert text["bodies/fluid/velocity"] == "m/s"
