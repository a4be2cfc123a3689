"""oobleck.read_rheometer and fit("curves", exports, phi=...) on the instrument-export fixtures of
tests/rheology/data/rheometer (make_fixtures.py: hermes2016 flow curves printed to 5 significant
digits in each instrument's units; truth.csv holds them in SI at full precision)."""
import numpy as np
import pandas as pd
import pytest

import oobleck

FILES = {"trios_phi040.txt": ("trios", 0.40, "Flow sweep"), "rheocompass_phi044.csv": ("rheocompass", 0.44, 2),
         "rspace_phi046.csv": ("rspace", 0.46, None), "generic_phi048.csv": ("csv", 0.48, None)}


@pytest.fixture(scope="module")
def data(root):
    return root / "tests" / "rheology" / "data" / "rheometer"


@pytest.mark.parametrize("name", FILES)
def test_round_trip_within_the_printed_precision(data, name):
    df = oobleck.read_rheometer(data / name)
    assert list(df.columns[:6]) == list(oobleck.RHEOMETER_COLUMNS)
    assert df.attrs["format"] == FILES[name][0]
    assert (df["step_name"] != "").all() and df["step"].dtype.kind == "i"
    truth = pd.read_csv(data / "truth.csv", comment="#")
    truth = truth[truth["file"] == name]
    got = df[df["step_name"].isin(truth["step_name"].unique())].reset_index(drop=True)
    assert len(got) == len(truth)
    for col in ("time", "shear_rate", "shear_stress", "viscosity"):
        np.testing.assert_allclose(got[col], truth[col], rtol=5e-5, err_msg=f"{name}: {col}")


def test_attrs_hold_the_sample_geometry_and_units(data):
    df = oobleck.read_rheometer(data / "trios_phi040.txt", step="flow sweep")
    assert set(df["step_name"]) == {"Flow sweep - 2"} and set(df["step"]) == {2}
    assert df.attrs["sample"] == "cornstarch phi 0.40 (synthetic, hermes2016)"
    assert df.attrs["geometry"] == "40 mm parallel plate, 1000 um gap"
    assert df.attrs["units"]["viscosity"] == "mPa.s" and df.attrs["si_units"]["viscosity"] == "Pa s"
    assert df.attrs["metadata"]["Geometry Parameters/Gap"] == "1000 \u00b5m"
    rc = oobleck.read_rheometer(data / "rheocompass_phi044.csv")
    assert rc.attrs["encoding"] == "UTF-16LE" and rc.attrs["decimal"] == ","
    assert rc["status"].iloc[1] == "WMa,TruStrain\u2122"
    assert np.isnan(rc["torque"].iloc[1])


def test_joint_fit_over_exports_recovers_the_parameters(data):
    truth = oobleck.load_params("hermes2016")
    start = truth.copy()
    start.a_0, start.a_inf, start.phi_j, start.phi_c, start.tau_star = 0.88, 0.72, 0.54, 0.43, 6.0
    names = ["a_0", "phi_j", "a_inf", "phi_c", "tau_star"]
    r = oobleck.fit("curves", [data / f for f in FILES], start, parameters=names,
                    phi=[v[1] for v in FILES.values()], step=[v[2] for v in FILES.values()])
    assert r.n == 64 and r.rms < 5e-5
    for name in names:
        v, se, want = r.values[name], r.stderr[name], getattr(truth, name)
        assert abs(v - want) < 3 * se, f"{name} = {v} +- {se}, truth {want}"
        assert abs(v - want) < 1e-3 * want


def test_errors_name_the_file_line_and_rule(data, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("shear_rate [1/s];viscosity [mPa-s]\n1;2\n")
    with pytest.raises(oobleck.InputError, match=r"bad.csv:1: column 'viscosity': unknown unit 'mPa-s'"):
        oobleck.read_rheometer(bad)
    with pytest.raises(oobleck.InputError, match=r"step = 'Flow sweeps': no such step"):
        oobleck.read_rheometer(data / "trios_phi040.txt", step="Flow sweeps")
    with pytest.raises(oobleck.InputError, match=r"2 steps hold shear rate and stress"):
        oobleck.fit("curves", data / "trios_phi040.txt", phi=0.40, parameters=["a_0"])
    with pytest.raises(oobleck.InputError, match=r"data: 2 export\(s\), phi: 1 value"):
        oobleck.fit("curves", [data / "rspace_phi046.csv", data / "generic_phi048.csv"], phi=0.46)
    with pytest.raises(oobleck.InputError, match=r"a rspace export has no phi column: give its volume fraction"):
        oobleck.fit("curves", data / "rspace_phi046.csv")
    with pytest.raises(oobleck.InputError, match=r"phi: only for kind 'curves'"):
        oobleck.fit("low", data / "generic_phi048.csv", phi=0.48)
