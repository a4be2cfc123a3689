"""flow_curve's two return types (DataFrame, as_frame=False: dict of numpy arrays) hold the same
numbers; the DataFrame wraps the module's block without a copy and owns its column index."""
import numpy as np
import pandas as pd
import pytest

import oobleck


def test_dict_and_frame_agree():
    p = oobleck.load_params("hermes2016")
    df = oobleck.flow_curve(p, [0.40, 0.47], 50)
    d = oobleck.flow_curve(p, [0.40, 0.47], 50, as_frame=False)
    assert isinstance(d, dict) and list(d) == list(oobleck.FLOW_CURVE_COLUMNS) == list(df.columns)
    assert len(df) == 100 and all(v.shape == (100,) and v.dtype == np.float64 for v in d.values())
    for k, v in d.items():
        np.testing.assert_array_equal(df[k].to_numpy(), v, err_msg=k)
    assert isinstance(df.index, pd.RangeIndex)
    assert np.isnan(d["shear_rate_dst"][:50]).all() and np.isfinite(d["shear_rate_dst"][50:]).all()  # CST, DST
    assert d["shear_rate_dst"][50] == oobleck.shear_rate_dst(p, 0.47)


def test_frames_are_independent():
    a, b = oobleck.flow_curve("hermes2016", 0.45, 20), oobleck.flow_curve("hermes2016", 0.45, 20)
    a.columns.name = "mine"
    a["phi"] = 0.0
    a["extra"] = 1.0
    assert b.columns.name is None and (b["phi"] == 0.45).all() and list(b.columns) == list(oobleck.FLOW_CURVE_COLUMNS)
    assert oobleck.flow_curve("hermes2016", 0.45, 20).columns.name is None


def test_bad_input_on_the_fast_path():
    p = oobleck.load_params("hermes2016")
    with pytest.raises(oobleck.InputError, match=r"phi \(parameters: hermes2016\) = nan: must lie in \(0, phi_j\)"):
        oobleck.flow_curve(p, float("nan"), as_frame=False)
    with pytest.raises(oobleck.InputError, match=r"phi \(parameters: hermes2016\) = -0.1: must lie in \(0, phi_j\)"):
        oobleck.flow_curve(p, -0.1)
    with pytest.raises(oobleck.InputError, match=r"phi = True \(bool\): must be a number"):
        oobleck.flow_curve(p, True)
    with pytest.raises(oobleck.InputError, match=r"as_frame = 'no' \(str\): must be True or False"):
        oobleck.flow_curve(p, 0.4, as_frame="no")
    with pytest.raises(oobleck.InputError, match=r"points = 1: must be >= 2"):
        oobleck.flow_curve(p, 0.4, 1, as_frame=False)
    assert oobleck.flow_curve(p, [], 10, as_frame=False)["phi"].shape == (0,)
