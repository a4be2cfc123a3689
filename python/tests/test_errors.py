"""Bad input raises oobleck.InputError naming the argument and the rule."""
import numpy as np
import pandas as pd
import pytest

import oobleck


def test_unknown_preset():
    with pytest.raises(oobleck.InputError, match=r"unknown preset 'hermes2061' \(did you mean 'hermes2016'\?\)"):
        oobleck.load_params("hermes2061")
    with pytest.raises(oobleck.InputError, match="unknown preset"):
        oobleck.flow_curve("nope", 0.4)


def test_phi_at_or_above_phi_j():
    with pytest.raises(oobleck.InputError, match=r"phi \(parameters: hermes2016\) = 0.535: must lie in \(0, phi_j\)"):
        oobleck.flow_curve("hermes2016", [0.4, 0.535])
    with pytest.raises(oobleck.InputError, match=r"phi.* = 0.6: must lie in \(0, phi_j\)"):
        oobleck.viscosity_at("hermes2016", 0.6, shear_rate=1.0)


def test_wrong_types():
    with pytest.raises(oobleck.InputError, match=r"phi = 'abc' \(str\): must be a number or a list of numbers"):
        oobleck.flow_curve("hermes2016", "abc")
    with pytest.raises(oobleck.InputError, match=r"points = 2.5 \(float\): must be an integer"):
        oobleck.flow_curve("hermes2016", 0.4, points=2.5)
    with pytest.raises(oobleck.InputError, match=r"params = 3 \(int\): must be a Params"):
        oobleck.shear_rate_dst(3, 0.4)
    with pytest.raises(oobleck.InputError, match=r"data = 7 \(int\): must be a pandas DataFrame"):
        oobleck.fit("low", 7)
    with pytest.raises(oobleck.InputError, match=r"kind = 'mid': must be one of"):
        oobleck.fit("mid", pd.DataFrame({"phi": [0.3]}))
    with pytest.raises(oobleck.InputError, match=r"points = 1: must be >= 2"):
        oobleck.flow_curve("hermes2016", 0.4, points=1)


def test_data_columns_and_nan():
    d = pd.DataFrame({"phi": [0.4, 0.45, 0.5, 0.52], "shear_rate": [1.0, 2.0, np.nan, 1.0],
                      "shear_stress": [1.0, 2.0, 3.0, 4.0]})
    with pytest.raises(oobleck.InputError, match=r"row 3: column 'shear_rate' = nan: must be a finite number"):
        oobleck.fit("curves", d)
    with pytest.raises(oobleck.InputError, match=r"missing column 'shear_stress' \(columns present: phi, shear_rate\)"):
        oobleck.fit("curves", d.fillna(1.0).drop(columns="shear_stress"))
    with pytest.raises(oobleck.InputError, match=r"missing column 'shear_rate_dst'"):
        oobleck.fit("dst", d)
    with pytest.raises(oobleck.InputError, match=r"row 1: column 'shear_stress' = 'x': is not a number"):
        oobleck.fit("curves", d.fillna(1.0).assign(shear_stress=["x", 1, 2, 3]))
    with pytest.raises(oobleck.InputError, match=r"unknown parameter 'tau_str' \(did you mean 'tau_star'\?\)"):
        oobleck.fit("curves", d.fillna(1.0), parameters=["tau_str"])


def test_params_validate_on_assignment():
    p = oobleck.load_params("hermes2016")
    with pytest.raises(oobleck.InputError, match=r"Params.phi_c: key 'steady.phi_c' = 0.6: must be smaller than "
                                                 r"steady.phi_j = 0.535 \(phi_c < phi_j\)"):
        p.phi_c = 0.6
    assert p.phi_c == 0.436  # unchanged
    with pytest.raises(oobleck.InputError, match=r"eta_B\[0\].phi_i' = -1: must be >= 0"):
        p.eta_B = [(-1.0, 2.0)]
    with pytest.raises(oobleck.InputError, match=r"shear_rate = -1: must be positive"):
        oobleck.point_shear(p, 0.44, shear_rate=-1, duration=1.0)
    assert isinstance(oobleck.InputError("x"), ValueError)


def test_params_round_trip(tmp_path):
    p = oobleck.load_params("singh2018b")
    p.tau_star = 2.5
    p.to_toml(tmp_path / "p.toml")
    q = oobleck.load_params(tmp_path / "p.toml")
    assert q.tau_star == 2.5 and q.eta_B == p.eta_B and q.to_dict()["a_0"] == 0.455
    assert set(oobleck.presets()) >= {"hermes2016", "singh2018b"}


def test_viscosity_at_branches():
    # the S-shaped singh2018a curve at phi = 0.5679: the rate turns back from 0.01493 to 0.009546 1/s,
    # so three states at a rate between, one at a lower rate
    rate = 0.012
    v = oobleck.viscosity_at("singh2018a", 0.5679, shear_rate=rate)
    assert v.shape == (3,) and np.all(np.diff(v) > 0)
    both = oobleck.viscosity_at("singh2018a", 0.5679, shear_rate=[1e-3 * rate, rate])
    assert both.shape == (2, 3) and np.isnan(both[0, 1:]).all()
    full = oobleck.viscosity_at("singh2018a", 0.5679, shear_rate=rate, full=True)
    np.testing.assert_allclose(full["shear_stress"] / full["shear_rate"], v, rtol=1e-14)
    np.testing.assert_allclose(full["shear_rate"], rate, rtol=1e-12)
