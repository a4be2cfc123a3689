"""FitResult.plot: data against the fitted model as rheologists look at it (shear stress or
viscosity against shear rate or stress), one legend entry per phi, axes over the data; the model
lines are the library's flow curves of the fitted set, every branch."""
import numpy as np
import pandas as pd
import pytest

import oobleck


@pytest.fixture(scope="module")
def fitted():
    import matplotlib
    matplotlib.use("Agg")
    truth = oobleck.load_params("hermes2016")
    rows = []
    for phi in (0.40, 0.45, 0.48):
        tau = np.geomspace(0.01, 30.0, 10)
        rate = tau / oobleck.viscosity_at(truth, phi, shear_stress=tau)[:, 0]
        rows += [(phi, g * (1 + 0.02 * np.sin(3.0 * k)), t) for k, (g, t) in enumerate(zip(rate, tau))]
    data = pd.DataFrame(rows, columns=["phi", "shear_rate", "shear_stress"])
    r = oobleck.fit("curves", data, truth, parameters=["a_0", "phi_j", "tau_star"])
    return r, data


@pytest.mark.parametrize("x,y", [("rate", "stress"), ("rate", "viscosity"), ("stress", "viscosity")])
def test_axes_and_data(fitted, x, y):
    import matplotlib.pyplot as plt
    r, data = fitted
    ax = r.plot(x=x, y=y)
    want_x = data["shear_rate"] if x == "rate" else data["shear_stress"]
    want_y = data["shear_stress"] if y == "stress" else data["shear_stress"] / data["shear_rate"]
    markers = [line for line in ax.lines if line.get_marker() == "o"]
    assert len(markers) == 3
    np.testing.assert_allclose(np.concatenate([m.get_xdata() for m in markers]), want_x, rtol=1e-15)
    np.testing.assert_allclose(np.concatenate([m.get_ydata() for m in markers]), want_y, rtol=1e-15)
    lo, hi = ax.get_xlim()
    assert lo < want_x.min() and want_x.max() < hi and hi / lo < 3 * want_x.max() / want_x.min()
    assert ("rate" if x == "rate" else "stress") in ax.get_xlabel()
    assert ("viscosity" if y == "viscosity" else "stress") in ax.get_ylabel()
    assert [t.get_text().split()[2] for t in ax.get_legend().get_texts()] == ["0.4", "0.45", "0.48"]
    # the model lines of phi = 0.48 are the fitted set's flow curve (every branch: the S's points)
    fc = oobleck.flow_curve(r.params, 0.48, 400)
    model = [line for line in ax.lines if line.get_marker() != "o" and len(line.get_xdata()) > 2
             and tuple(line.get_color()) == tuple(markers[2].get_color())]
    assert sum(len(m.get_xdata()) for m in model) == len(fc) + len(model) - 1
    plt.close("all")


def test_bad_axes(fitted):
    r, _ = fitted
    with pytest.raises(oobleck.InputError, match="y = 'rate'"):
        r.plot(y="rate")
    with pytest.raises(oobleck.InputError, match="against itself"):
        r.plot(x="stress", y="stress")
