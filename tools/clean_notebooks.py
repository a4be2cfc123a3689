#!/usr/bin/env python3
"""Strip a notebook to what is committed: no outputs, no execution counts, no cell metadata, the
notebook's metadata reduced to its kernel (python3) and language.

    /usr/bin/python3 tools/clean_notebooks.py python/examples/*.ipynb      # rewrite in place
    /usr/bin/python3 tools/clean_notebooks.py --check python/examples/*.ipynb  # exit 1 if not clean

python/tests/test_notebooks.py checks the committed notebooks with `is_clean` and runs them."""
import argparse
import sys

import nbformat

KERNELSPEC = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}


def clean(nb):
    """The notebook without outputs, execution counts and metadata noise (modified in place)."""
    nb.metadata = nbformat.from_dict({"kernelspec": KERNELSPEC, "language_info": {"name": "python"}})
    for cell in nb.cells:
        cell.metadata = nbformat.from_dict({})
        if cell.cell_type == "code":
            cell.outputs = []
            cell.execution_count = None
    return nb


def is_clean(nb) -> bool:
    return nbformat.writes(clean(nbformat.from_dict(nb))) == nbformat.writes(nb)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebooks", nargs="+")
    ap.add_argument("--check", action="store_true", help="only report notebooks that are not clean (exit 1)")
    args = ap.parse_args()
    dirty = []
    for path in args.notebooks:
        nb = nbformat.read(path, as_version=4)
        if is_clean(nb):
            continue
        dirty.append(path)
        if not args.check:
            nbformat.write(clean(nb), path)
            print(f"cleaned {path}")
    if args.check and dirty:
        print("not clean: " + ", ".join(dirty), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
