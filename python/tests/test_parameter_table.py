"""oobleck.parameter_table() and Params.from_dict: the table that drives Params' properties."""
import math

import pytest

import oobleck


def test_parameter_table_lists_every_property_of_params_with_its_unit():
    t = oobleck.parameter_table()
    material = t[t.section.isin(["steady", "granular"])]
    p = oobleck.load_params("hermes2016")
    # Every steady and granular row is a property of Params, and the property's doc names its unit.
    for _, row in material.iterrows():
        assert hasattr(p, row["name"])
        unit = "[-]" if row["unit"] == "1" else f"[{row['unit']}]"
        assert getattr(oobleck.Params, row["name"]).__doc__.startswith(unit)
    assert set(t[t.section == "fluid"].name) == {"rho_f", "kappa", "eta_0"}
    tau = t[t.name == "tau_star"].iloc[0]
    assert (tau.unit, tau.default, tau.lower, tau.lower_open, math.isinf(tau.upper)) == ("Pa", "required", 0.0, True, True)


def test_params_from_dict_round_trips_to_dict_and_validates_as_a_whole():
    p = oobleck.load_params("hermes2016")
    assert oobleck.Params.from_dict(p.to_dict()) == p
    d = p.to_dict()
    d["phi_c"], d["phi_j"] = 0.5, 0.6  # valid together, each invalid against the other's old value
    q = oobleck.Params.from_dict(d)
    assert (q.phi_c, q.phi_j) == (0.5, 0.6)
    minimal = {k: d[k] for k in ("phi_c", "phi_j", "a_0", "a_inf", "tau_star", "eta_0", "mu_c")}
    r = oobleck.Params.from_dict(minimal)
    assert r.K_3 == 4.715 and r.eta_B == []  # the granular defaults; no E8 terms
    with pytest.raises(oobleck.InputError, match="missing 'phi_j'"):
        oobleck.Params.from_dict({"a_0": 0.8})
    with pytest.raises(oobleck.InputError, match="did you mean 'tau_star'"):
        oobleck.Params.from_dict(dict(minimal, tau_str=1.0))
    with pytest.raises(oobleck.InputError, match="steady.phi_c"):
        oobleck.Params.from_dict(dict(minimal, phi_c=0.7))
