"""Every function returns the CLI's numbers bit for bit (the same library): CSVs are written with
17 significant digits (round trip exact) and read back with pandas' round-trip parser."""
import json

import numpy as np
import pandas as pd
import pytest

import oobleck


def read(path):
    return pd.read_csv(path, comment="#", float_precision="round_trip")  # (point CSVs: a '# units:' line first)


def assert_same(py, csv):
    assert list(py.columns) == list(csv.columns)
    for c in csv.columns:
        if csv[c].dtype == object:
            assert py[c].tolist() == csv[c].tolist(), c
        else:
            np.testing.assert_array_equal(py[c].to_numpy(dtype=float), csv[c].to_numpy(dtype=float), err_msg=c)


@pytest.mark.parametrize("preset,phis", [("hermes2016", [0.40, 0.45, 0.5]), ("singh2018b", [0.56, 0.6])])
def test_flow_curve(cli, tmp_path, preset, phis):
    args = [a for phi in phis for a in ("--phi", phi)]
    cli("rheology", "flow-curve", "--preset", preset, *args, "--points", 200, "--out", tmp_path / "fc.csv")
    csv = read(tmp_path / "fc.csv")
    assert_same(oobleck.flow_curve(preset, phis, points=200), csv)
    assert_same(pd.DataFrame(oobleck.flow_curve(oobleck.load_params(preset), phis, 200, as_frame=False)), csv)
    for phi in phis:  # one phi as a float (the module's fast path) and as np.float64
        one = csv[csv["phi"] == phi].reset_index(drop=True)
        assert_same(oobleck.flow_curve(preset, float(phi)), one)
        assert_same(pd.DataFrame(oobleck.flow_curve(preset, np.float64(phi), as_frame=False)), one)


def test_dst(cli):
    for phi in (0.40, 0.45, 0.52):
        j = json.loads(cli("rheology", "dst", "--preset", "hermes2016", "--phi", phi, "--json").stdout)
        assert oobleck.shear_rate_dst("hermes2016", phi) == j["shear_rate_dst"]
    assert oobleck.shear_rate_dst("hermes2016", 0.40) is None


def test_structure_and_volume_fraction(cli, tmp_path):
    cli("rheology", "structure", "--preset", "singh2018a", "--points", 50, "--out", tmp_path / "s.csv")
    assert_same(oobleck.structure("singh2018a", points=50), read(tmp_path / "s.csv"))
    j = json.loads(cli("rheology", "volume-fraction", "--mass-fraction", 0.44, "--rho-cs", 1630, "--rho-liquid",
                       1000, "--rho-water", 1000, "--json").stdout)
    assert oobleck.volume_fraction(0.44, 1630, 1000, 1000) == j["phi"]


@pytest.mark.parametrize("kind,data,base", [("low", "min_viscosity.csv", "dhaene1993"),
                                            ("high", "plateau_viscosity.csv", "dhaene1993"),
                                            ("dst", "dst_rates.csv", "dhaene1993")])
def test_fit_asymptotes(cli, root, tmp_path, kind, data, base):
    path = root / "docs" / "fitting" / data
    j = json.loads(cli("rheology", "fit", "--kind", kind, "--data", path, "--preset", base, "--out",
                       tmp_path / "f.toml", "--json").stdout)
    r = oobleck.fit(kind, str(path), base)
    assert r.n == j["n"] and r.rms == j["rms"]
    for name, v in j["parameters"].items():
        assert r.values[name] == v["value"], name
        assert r.stderr[name] == v["std_error"], name
    # the written parameter file holds the same fitted set
    assert oobleck.load_params(tmp_path / "f.toml").to_dict() | {"name": 0, "source": 0, "file": 0} == \
        r.params.to_dict() | {"name": 0, "source": 0, "file": 0}


def test_fit_curves_cli(cli, tmp_path):
    truth = oobleck.load_params("singh2018b")
    rows = []
    for phi in (0.5, 0.56, 0.58, 0.6):
        tau = truth.tau_star * np.geomspace(0.01, 1000, 12)
        rate = tau / oobleck.viscosity_at(truth, phi, shear_stress=tau)[:, 0]
        rows += [(phi, r * (1.02 if k % 2 else 0.98), t) for k, (r, t) in enumerate(zip(rate, tau))]
    d = pd.DataFrame(rows, columns=["phi", "shear_rate", "shear_stress"])
    d.to_csv(tmp_path / "curves.csv", index=False, float_format="%.17g")
    j = json.loads(cli("rheology", "fit", "--kind", "curves", "--data", tmp_path / "curves.csv", "--preset",
                       "singh2018b", "--out", tmp_path / "c.toml", "--json").stdout)
    r = oobleck.fit("curves", tmp_path / "curves.csv", "singh2018b")
    for name, v in j["parameters"].items():
        assert r.values[name] == v["value"] and r.stderr[name] == v["std_error"], name
    np.testing.assert_array_equal(r.correlation.to_numpy().ravel(), np.asarray(j["correlation"]))
    assert oobleck.load_params(tmp_path / "c.toml").phi_c == r.params.phi_c


def test_point_shear_and_relax(cli, tmp_path):
    cli("point", "shear", "--preset", "hermes2016", "--phi", 0.44, "--shear-rate", 10, "--duration", 0.05,
        "--samples", 50, "--out", tmp_path / "p.csv")
    assert_same(oobleck.point_shear("hermes2016", 0.44, shear_rate=10, duration=0.05, samples=50),
                read(tmp_path / "p.csv"))
    cli("point", "shear", "--preset", "hermes2016", "--phi", 0.44, "--shear-stress", 20, "--duration", 0.02,
        "--samples", 20, "--G", 2e4, "--out", tmp_path / "ps.csv")
    assert_same(oobleck.point_shear("hermes2016", 0.44, shear_stress=20, duration=0.02, samples=20, G=2e4),
                read(tmp_path / "ps.csv"))
    cli("point", "relax", "--preset", "hermes2016", "--phi", 0.44, "--shear-rate", 5, "--G", 1e4, "--G", 1e5,
        "--duration", 0.01, "--samples", 30, "--out", tmp_path / "r.csv")
    assert_same(oobleck.point_relax("hermes2016", 0.44, shear_rate=5, G=[1e4, 1e5], duration=0.01, samples=30),
                read(tmp_path / "r.csv"))


def test_run(cli, root, tmp_path):
    scene = root / "scenes" / "verification" / "settling.toml"
    cli("run", scene, "--set", "time.duration=0.01", "--threads", 1, "--out", tmp_path / "cli", "--quiet")
    s = oobleck.run(scene, tmp_path / "py", threads=1, set={"time.duration": 0.01}, progress=False)
    c = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert s["steps"] == c["steps"] and s["complete"] and s["points"] == c["points"]
    assert_same(read(tmp_path / "py" / "series.csv"), read(tmp_path / "cli" / "series.csv"))
    run = oobleck.open_run(tmp_path / "py")
    assert run.summary["steps"] == s["steps"]
    assert len(run.frames) >= 2 and run.times[0] <= run.times[-1]
    body = run.frames[-1].bodies[0]
    pos = run.frames[-1][body]["position"]
    assert pos.shape == (s["points_per_body"][body], 2)
    assert len(run.series) == len(read(tmp_path / "cli" / "series.csv"))
