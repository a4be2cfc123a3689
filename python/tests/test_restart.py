"""oobleck.run(restart=True, set=...) continues a run with new [time] settings, as
`oobleck run --restart DIR --set time.cfl=...` does; other keys are refused."""
import pytest

import oobleck


def test_restart_with_a_smaller_cfl_halves_the_step(root, tmp_path):
    out = tmp_path / "run"
    scene = root / "scenes" / "verification" / "settling.toml"
    first = oobleck.run(scene, out, threads=1, set={"time.cfl": 0.4}, stop_after=30, progress=False)
    assert first["complete"] is False and first["steps"] == 30
    with pytest.raises(oobleck.InputError, match=r"only \[time\] keys.*'region.0.phi'"):
        oobleck.run(out=out, restart=True, set={"phi": 0.2}, progress=False)
    s = oobleck.run(out=out, restart=True, set={"time.cfl": 0.2}, stop_after=50, threads=1, progress=False)
    assert s["steps"] == 50 and s["steps_this_run"] == 20
    assert s["dt"] == pytest.approx(0.5 * first["dt"], rel=1e-14)
    assert s["time"] == pytest.approx(first["time"] + 20 * s["dt"], rel=1e-12)
    assert s["restart_overrides"] == ["time.cfl=0.2"]
