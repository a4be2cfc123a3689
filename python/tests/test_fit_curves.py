"""The joint curves fit recovers the parameters of a preset from synthetic flow curves (3 %
log-normal noise on the rate at each stress) within 2 standard errors, with larger errors from
fewer volume fractions; a parameter the data do not determine is held at the base value with a
warning (strict=True: an error); a first call with the defaults on rate-controlled curves below
DST succeeds."""
import numpy as np
import pandas as pd
import pytest

import oobleck

CASES = {"hermes2016": ([0.38, 0.42, 0.45, 0.48, 0.50, 0.52], [0.40, 0.45, 0.48, 0.52]),
         "singh2018b": ([0.50, 0.54, 0.56, 0.57, 0.58, 0.60], [0.50, 0.56, 0.58, 0.60])}


def synthetic(p, phis, noise=0.03, seed=1, stresses=np.geomspace(1e-2, 1e3, 16)):
    """Stress-controlled flow curves: the model's rate at each stress (tau* x `stresses`), times a
    log-normal factor exp(N(0, noise))."""
    rng = np.random.default_rng(seed)
    rows = []
    for phi in phis:
        tau = p.tau_star * np.asarray(stresses)
        rate = tau / oobleck.viscosity_at(p, phi, shear_stress=tau)[:, 0]
        rows += [(phi, r * np.exp(rng.normal(0.0, noise)), t) for r, t in zip(rate, tau)]
    return pd.DataFrame(rows, columns=["phi", "shear_rate", "shear_stress"])


def start_from(p, f=1.1):
    """A starting set 10 % (1 % in phi, 50 % in phi_i) away from the truth."""
    q = p.copy()
    q.a_0 *= f
    q.a_inf /= f
    q.tau_star *= f
    q.phi_j = q.phi_j * 1.01
    q.phi_c *= 0.99
    q.eta_B = [(a * f * 1.5, b * f) for a, b in q.eta_B]
    return q


def true_value(p, name):
    if name.startswith("eta_B["):
        term = p.eta_B[int(name[6])]
        return term[0] if name.endswith("phi_i") else term[1]
    return getattr(p, name)


@pytest.mark.parametrize("preset", CASES)
def test_recovers_preset_within_two_standard_errors(preset):
    truth = oobleck.load_params(preset)
    many, few = CASES[preset]
    fits = {}
    for phis in (many, few):
        r = oobleck.fit("curves", synthetic(truth, phis), start_from(truth))
        assert set(r.values) == set(["a_0", "phi_j", "a_inf", "phi_c", "tau_star"] +
                                    [f"eta_B[{i}].{k}" for i in range(len(truth.eta_B)) for k in ("phi_i", "alpha")])
        for name, v in r.values.items():
            z = (v - true_value(truth, name)) / r.stderr[name]
            assert abs(z) < 2.0, f"{preset}, {len(phis)} phi: {name} = {v} +- {r.stderr[name]}, z = {z:.2f}"
        assert 0.02 < r.rms < 0.04  # the noise level
        assert r.correlation.shape == (r.p, r.p)
        np.testing.assert_allclose(np.diag(r.correlation), 1.0)
        assert len(r.residuals) == r.n and {"model", "residual"} <= set(r.residuals.columns)
        fits[len(phis)] = r
    for name in fits[len(many)].stderr:
        assert fits[len(few)].stderr[name] > fits[len(many)].stderr[name], name


def test_residual_in_log_stress_at_measured_rate():
    truth = oobleck.load_params("hermes2016")
    start = truth.copy()
    start.a_0, start.phi_j, start.tau_star = 0.9, 0.54, 6.0
    r = oobleck.fit("curves", synthetic(truth, [0.36, 0.38, 0.40, 0.42], noise=0.0, stresses=np.geomspace(0.01, 3, 10)),
                    start, parameters=["a_0", "phi_j", "tau_star"], residual="stress",
                    bounds={"phi_j": (0.5, 0.6)})
    assert r.residual_kind == "stress"
    assert r.rms < 1e-4  # noise-free CST curves (below phi_c; near DST log stress at a rate is ill-conditioned)
    for name in r.values:
        assert r.values[name] == pytest.approx(true_value(truth, name), rel=1e-2)


def test_undetermined_parameter_is_an_error_when_strict():
    truth = oobleck.load_params("hermes2016")
    below = [0.30, 0.34, 0.38, 0.42]  # all below phi_c = 0.436
    low_stress = synthetic(truth, below, stresses=np.geomspace(1e-3, 3e-2, 10))
    with pytest.raises(oobleck.InputError, match=r"do not determine phi_c"):
        oobleck.fit("curves", low_stress, start_from(truth), parameters=["a_0", "phi_j", "phi_c"], strict=True)
    with pytest.raises(oobleck.InputError, match=r"do not determine a_inf"):
        oobleck.fit("curves", low_stress, start_from(truth), strict=True)
    # up to high stresses phi_c is determined by the thickened plateau (as fit --kind high), eta_B is not
    with pytest.raises(oobleck.InputError, match=r"do not determine eta_B\[0\]"):
        oobleck.fit("curves", synthetic(truth, below), start_from(truth), strict=True)


def test_undetermined_parameter_is_held_with_a_warning():
    truth = oobleck.load_params("hermes2016")
    below = [0.30, 0.34, 0.38, 0.42]
    low_stress = synthetic(truth, below, stresses=np.geomspace(1e-3, 3e-2, 10))
    start = start_from(truth)
    with pytest.warns(UserWarning, match=r"phi_c = 0\.43164 \(1 sigma: \+- [0-9.]+, beyond \+- 0\.1\)"):
        r = oobleck.fit("curves", low_stress, start, parameters=["a_0", "phi_j", "phi_c"])
    assert [name for name, _ in r.held] == ["phi_c"]
    assert r.params.phi_c == start.phi_c  # held at the base set's value
    assert set(r.values) == {"a_0", "phi_j"} and r.p == 2
    for name in r.values:  # the low-stress branch alone gives a_0 and phi_j (E12)
        assert abs(r.values[name] - true_value(truth, name)) < 3 * r.stderr[name], name
    # the thickened plateau below phi_c determines a_inf and phi_c, not the eta_B terms
    with pytest.warns(UserWarning, match=r"eta_B\[0\]"):
        r = oobleck.fit("curves", synthetic(truth, below), start)
    assert {name for name, _ in r.held} >= {"eta_B[0].phi_i"}
    assert all(name.startswith("eta_B[") for name, _ in r.held)
    # nothing left to fit: the error, whatever strict says
    with pytest.raises(oobleck.InputError, match=r"do not determine phi_c"):
        oobleck.fit("curves", low_stress, start, parameters=["phi_c"])
    with pytest.raises(oobleck.InputError, match=r"strict = 'yes'"):
        oobleck.fit("curves", low_stress, start, strict="yes")
    with pytest.raises(oobleck.InputError, match=r"strict: only for kind 'curves'"):
        oobleck.fit("low", pd.DataFrame({"phi": [0.3, 0.4, 0.5], "relative_viscosity": [3, 6, 20]}), strict=True)


def rate_controlled_below_dst(p, noise=0.02, seed=1):
    """Rate-controlled flow curves at five phi from 0.40 to 0.49: 12 rates per curve, log-spaced from
    1e-3 1/s to 0.8 gamma_dot_DST (10 1/s where there is no DST), the stress of the low-viscosity
    branch times exp(N(0, noise))."""
    rng = np.random.default_rng(seed)
    rows = []
    for phi in np.linspace(0.40, 0.49, 5):
        dst = oobleck.shear_rate_dst(p, phi)
        rates = np.geomspace(1e-3, 0.8 * dst if dst else 10.0, 12)
        tau = rates * oobleck.viscosity_at(p, phi, shear_rate=rates)[:, 0]
        rows += [(phi, g, t * np.exp(rng.normal(0.0, noise))) for g, t in zip(rates, tau)]
    return pd.DataFrame(rows, columns=["phi", "shear_rate", "shear_stress"])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_first_fit_with_defaults_succeeds_below_dst(seed):
    """fit('curves', data) with every default (base hermes2016, which is the truth here) holds the
    eta_B terms the data do not determine and recovers the rest within 3 standard errors."""
    truth = oobleck.load_params("hermes2016")
    data = rate_controlled_below_dst(truth, seed=seed)
    with pytest.warns(UserWarning, match=r"held at the base set's values.*eta_B\[1\]\.phi_i = 0\.0093"):
        r = oobleck.fit("curves", data)
    held = [name for name, _ in r.held]
    assert {"eta_B[1].phi_i", "eta_B[1].alpha"} <= set(held)
    assert all(name.startswith("eta_B[") and reason for name, reason in r.held)
    assert len(held) + r.p == 9 and set(held).isdisjoint(r.values)
    for name in held:
        assert true_value(r.params, name) == true_value(truth, name)
    for name in ("a_0", "phi_j", "phi_c", "tau_star", "a_inf"):
        z = (r.values[name] - true_value(truth, name)) / r.stderr[name]
        assert abs(z) < 3.0, f"{name} = {r.values[name]} +- {r.stderr[name]}, z = {z:.2f}"
    assert 0.01 < r.rms < 0.03
    with pytest.raises(oobleck.InputError, match=r"do not determine .*eta_B\[1\]\.phi_i"):
        oobleck.fit("curves", data, strict=True)


def test_plot():
    import matplotlib
    matplotlib.use("Agg")
    truth = oobleck.load_params("singh2018b")
    data = synthetic(truth, CASES["singh2018b"][1])
    r = oobleck.fit("curves", data, start_from(truth))
    ax = r.plot()
    # one marker series per phi holding that phi's data, as given
    markers = [line for line in ax.lines if line.get_marker() == "o"]
    assert len(markers) == 4
    for line, (phi, rows) in zip(markers, data.groupby("phi")):
        np.testing.assert_array_equal(line.get_xdata(), rows["shear_rate"].to_numpy())
        np.testing.assert_array_equal(line.get_ydata(), rows["shear_stress"].to_numpy())
    assert len(ax.get_legend().get_texts()) == 4  # one entry per phi
    lo, hi = ax.get_xlim()  # the data's span
    assert lo < data["shear_rate"].min() < data["shear_rate"].max() < hi < 2 * data["shear_rate"].max()
