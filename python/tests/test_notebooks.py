"""The example notebooks (python/examples/*.ipynb) run from top to bottom without a cell error, as
a user opens them: the notebook's folder as the working directory, a python3 kernel of ipykernel
(Debian's python3-nbclient and python3-ipykernel, installed by scripts/bootstrap). The kernel runs
this interpreter (a kernel spec in a temporary JUPYTER_PATH; Jupyter's and IPython's folders are
temporary too, so nothing is written to the home folder) with this checkout's package, as
conftest.py imports it; the notebooks write their outputs to OOBLECK_EXAMPLES_OUT, a temporary
folder. The committed notebooks carry no outputs (tools/clean_notebooks.py)."""
import json
import os
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "python" / "examples"
NOTEBOOKS = sorted(EXAMPLES.glob("*.ipynb"))
# What each notebook must leave in its output folder (and nowhere else).
WRITES = {"flow_curves_and_dst": ["flow_curves.png"], "read_export_and_fit": ["fit.png", "fitted.toml"],
          "run_and_frames": ["intrusion_frames.png", "intrusion/summary.json", "intrusion/series.csv"]}
KERNEL = "oobleck-test-python3"


def _import(name):
    try:
        return __import__(name)
    except ImportError:
        pytest.fail(f"{name} is missing: the notebooks run with Debian's python3-nbclient, python3-nbformat "
                    "and python3-ipykernel (bash scripts/bootstrap)")


def test_every_notebook_is_listed():
    assert {p.stem for p in NOTEBOOKS} == set(WRITES)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_committed_notebook_is_clean(path):
    nbformat = _import("nbformat")
    sys.path.insert(0, str(ROOT / "tools"))
    import clean_notebooks  # tools/clean_notebooks.py
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    assert nb.metadata.kernelspec.name == "python3"
    assert clean_notebooks.is_clean(nb), (f"{path.relative_to(ROOT)} holds outputs or metadata: "
                                          f"/usr/bin/python3 tools/clean_notebooks.py {path.relative_to(ROOT)}")


@pytest.fixture
def kernel_env(tmp_path, monkeypatch):
    """A kernel spec for this interpreter, and Jupyter's and IPython's folders, in tmp_path."""
    _import("ipykernel")
    spec = tmp_path / "jupyter" / "kernels" / KERNEL
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Python 3 (oobleck tests)", "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    for var, name in (("JUPYTER_DATA_DIR", "data"), ("JUPYTER_RUNTIME_DIR", "runtime"),
                      ("JUPYTER_CONFIG_DIR", "config"), ("IPYTHONDIR", "ipython")):
        monkeypatch.setenv(var, str(tmp_path / name))
    monkeypatch.setenv("PYDEVD_DISABLE_FILE_VALIDATION", "1")  # the debugger's frozen-modules warning
    if not os.environ.get("OOBLECK_TEST_INSTALLED"):  # the kernel imports this checkout's package
        monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(ROOT / "python"),
                                                                       os.environ.get("PYTHONPATH")])))
    return tmp_path


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs(path, kernel_env, monkeypatch):
    nbformat = _import("nbformat")
    nbclient = _import("nbclient")
    out = kernel_env / "out"
    monkeypatch.setenv("OOBLECK_EXAMPLES_OUT", str(out))
    before = sorted(p.name for p in EXAMPLES.iterdir())
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(nb, kernel_name=KERNEL, timeout=120, allow_errors=False,
                                     resources={"metadata": {"path": str(EXAMPLES)}})
    t0 = time.monotonic()
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as e:
        pytest.fail(f"{path.relative_to(ROOT)}: a cell failed:\n{e}")
    seconds = time.monotonic() - t0
    print(f"{path.name}: {seconds:.1f} s")
    for name in WRITES[path.stem]:
        assert (out / name).is_file(), f"{path.name} did not write {name} to OOBLECK_EXAMPLES_OUT"
    assert sorted(p.name for p in EXAMPLES.iterdir()) == before, f"{path.name} wrote into python/examples"
