"""oobleck.run's progress: a tqdm bar when tqdm imports, else a text line on stderr; tqdm is not a
Debian dependency, so the tqdm path is tested with a stand-in module."""
import sys
import types

import pytest

import oobleck


def _run(root, out, **kw):
    scene = root / "scenes" / "verification" / "settling.toml"
    return oobleck.run(scene, out, threads=1, set={"time.duration": 0.01}, **kw)


def test_text_progress_without_tqdm(root, tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # `import tqdm` raises ImportError, installed or not
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    s = _run(root, tmp_path / "run", progress=True)
    err = capsys.readouterr().err
    assert s["complete"]
    last = err.strip().splitlines()[-1]
    assert last.startswith("settling: 100.0% (") and f"{s['steps']}/{s['steps']} steps" in last, err


def test_no_progress(root, tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm", None)
    _run(root, tmp_path / "run", progress=False)
    assert capsys.readouterr().err == ""


class FakeTqdm:
    made = []

    def __init__(self, desc=None, unit=None):
        self.desc, self.unit, self.total, self.n, self.postfix, self.closed = desc, unit, None, 0, None, False
        FakeTqdm.made.append(self)

    def update(self, k):
        assert k >= 0
        self.n += k

    def set_postfix(self, refresh=True, **kw):
        self.postfix = kw

    def close(self):
        self.closed = True


@pytest.fixture
def fake_tqdm(monkeypatch):
    pkg, auto = types.ModuleType("tqdm"), types.ModuleType("tqdm.auto")
    auto.tqdm = FakeTqdm
    pkg.auto = auto
    monkeypatch.setitem(sys.modules, "tqdm", pkg)
    monkeypatch.setitem(sys.modules, "tqdm.auto", auto)
    FakeTqdm.made.clear()
    return FakeTqdm


def test_tqdm_progress_when_installed(root, tmp_path, fake_tqdm, capsys):
    s = _run(root, tmp_path / "run", progress=True)
    assert len(fake_tqdm.made) == 1
    bar = fake_tqdm.made[0]
    assert bar.desc == "settling" and bar.unit == "step"
    assert bar.total == s["steps"] and bar.n == s["steps"] and bar.closed
    assert bar.postfix["t"].endswith(" s")
    assert capsys.readouterr().err == ""  # no text lines beside the bar


def test_tqdm_bar_closed_when_the_run_fails(root, tmp_path, fake_tqdm):
    scene = root / "scenes" / "verification" / "settling.toml"
    with pytest.raises(oobleck.InputError, match="no_such_key"):  # raised by the library, after the bar is made
        oobleck.run(scene, tmp_path / "run", threads=1, set={"no_such_key": 1}, progress=True)
    assert len(fake_tqdm.made) == 1
    assert all(b.closed for b in fake_tqdm.made)


def test_progress_error_stops_the_run(root, tmp_path, monkeypatch):
    """An exception raised by the bar (here: from update) stops the run cleanly and propagates."""
    class Broken(FakeTqdm):
        def update(self, k):
            raise RuntimeError("bar broke")

    monkeypatch.setitem(sys.modules, "tqdm.auto", types.SimpleNamespace(tqdm=Broken))
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    with pytest.raises(RuntimeError, match="bar broke"):
        _run(root, tmp_path / "run", progress=True)
    assert (tmp_path / "run" / "summary.json").exists()
