#!/usr/bin/python3
"""Validate an oobleck XDMF index (frames.xmf) against its HDF5 frame files.

    /usr/bin/python3 tools/check_xdmf.py RUN/frames.xmf [--quiet]

Checks the XML structure (Xdmf > Domain > one temporal collection per block of Uniform grids
with a Time each: Polyvertex point grids with XY/XYZ geometry, 3DCoRectMesh node grids), that every
attribute's dimensions agree with its grid and its AttributeType, and that every HDF5 reference
points to an existing HDF5 file. With h5py installed it also opens every dataset and compares
its shape and type with the index; without h5py it checks the HDF5 signature of each file.
Set CHECK_XDMF_NO_H5PY=1 to skip h5py even when it is installed.
Exit status 0 when valid, 1 with one line per problem otherwise, 2 on usage errors.
"""
import os
import sys
import xml.etree.ElementTree as ET

try:
    import h5py  # optional
except ImportError:  # pragma: no cover - depends on the machine
    h5py = None
if os.environ.get("CHECK_XDMF_NO_H5PY"):  # test the fallback where h5py is installed
    h5py = None

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
COMPONENTS = {"Scalar": None, "Vector": 3, "Tensor6": 6, "Tensor": 9}


class Checker:
    def __init__(self, xmf):
        self.xmf = xmf
        self.base = os.path.dirname(os.path.abspath(xmf))
        self.problems = []
        self.files = {}
        self.datasets = 0
        self.frames = 0

    def problem(self, where, what):
        self.problems.append(f"{self.xmf}: {where}: {what}")

    def dims(self, item, where):
        text = item.get("Dimensions", "")
        try:
            dims = [int(x) for x in text.split()]
        except ValueError:
            self.problem(where, f"Dimensions '{text}' is not a list of integers")
            return None
        if not dims or any(d < 0 for d in dims):
            self.problem(where, f"Dimensions '{text}' is empty or negative")
            return None
        return dims

    def hdf_reference(self, item, dims, where):
        ref = (item.text or "").strip()
        if ":" not in ref:
            self.problem(where, f"HDF reference '{ref}' lacks 'file:/dataset'")
            return
        fname, dset = ref.split(":", 1)
        path = os.path.join(self.base, fname)
        if not os.path.isfile(path):
            self.problem(where, f"HDF5 file '{fname}' does not exist")
            return
        if path not in self.files:
            with open(path, "rb") as f:
                ok = f.read(8) == HDF5_SIGNATURE
            self.files[path] = ok
            if not ok:
                self.problem(where, f"'{fname}' is not an HDF5 file")
        if not self.files[path]:
            return
        self.datasets += 1
        if h5py is None:
            return
        with h5py.File(path, "r") as h5:
            if dset not in h5:
                self.problem(where, f"dataset '{dset}' missing in '{fname}'")
                return
            d = h5[dset]
            if list(d.shape) != dims:
                self.problem(where, f"dataset '{ref}' has shape {list(d.shape)}, index says {dims}")
            number = item.get("NumberType", "Float")
            kind = {"Float": "f", "Int": "i", "UInt": "u", "Char": "i", "UChar": "u"}.get(number, "?")
            if d.dtype.kind != kind or d.dtype.itemsize != int(item.get("Precision", "4")):
                self.problem(where, f"dataset '{ref}' has type {d.dtype}, index says {number}/{item.get('Precision')}")

    def data_item(self, parent, where, expect=None):
        item = parent.find("DataItem")
        if item is None:
            self.problem(where, "no DataItem")
            return None
        dims = self.dims(item, where)
        if dims is None:
            return None
        if expect is not None and dims != expect:
            self.problem(where, f"Dimensions {dims}, expected {expect}")
        fmt = item.get("Format", "XML")
        if fmt == "HDF":
            self.hdf_reference(item, dims, where)
        elif fmt == "XML":
            values = (item.text or "").split()
            count = 1
            for d in dims:
                count *= d
            if len(values) != count:
                self.problem(where, f"{len(values)} inline values for Dimensions {dims}")
            try:
                [float(v) for v in values]
            except ValueError:
                self.problem(where, "inline values are not numbers")
        else:
            self.problem(where, f"unknown Format '{fmt}'")
        return dims

    def attributes(self, grid, lead, where):
        for attr in grid.findall("Attribute"):
            name = attr.get("Name")
            w = f"{where}/Attribute[{name}]"
            if not name:
                self.problem(w, "attribute without Name")
            kind = attr.get("AttributeType", attr.get("Type"))
            if kind not in COMPONENTS:
                self.problem(w, f"AttributeType '{kind}' not one of {sorted(COMPONENTS)}")
                continue
            if attr.get("Center") != "Node":
                self.problem(w, f"Center '{attr.get('Center')}', expected 'Node'")
            comps = COMPONENTS[kind]
            self.data_item(attr, w, lead + ([comps] if comps else []))

    def uniform(self, grid, where):
        topo = grid.find("Topology")
        geom = grid.find("Geometry")
        if topo is None or geom is None:
            self.problem(where, "uniform grid without Topology or Geometry")
            return
        ttype = topo.get("TopologyType")
        if ttype == "Polyvertex":
            try:
                n = int(topo.get("NumberOfElements", ""))
            except ValueError:
                self.problem(where, "Polyvertex without integer NumberOfElements")
                return
            if n <= 0:
                self.problem(where, "Polyvertex with no points (ParaView rejects it)")
            if topo.find("DataItem") is not None:
                self.data_item(topo, where + "/Topology", [n])
            gtype = geom.get("GeometryType")
            if gtype not in ("XY", "XYZ"):
                self.problem(where, f"point geometry '{gtype}', expected XY or XYZ")
                return
            self.data_item(geom, where + "/Geometry", [n, 2 if gtype == "XY" else 3])
            self.attributes(grid, [n], where)
        elif ttype in ("3DCoRectMesh", "2DCoRectMesh"):
            rank = 3 if ttype.startswith("3") else 2
            dims = self.dims(topo, where + "/Topology")
            if dims is None:
                return
            if len(dims) != rank:
                self.problem(where, f"{ttype} with {len(dims)} dimensions")
            gtype = geom.get("GeometryType")
            want = "ORIGIN_DXDYDZ" if rank == 3 else "ORIGIN_DXDY"
            if gtype != want:
                self.problem(where, f"mesh geometry '{gtype}', expected {want}")
            items = geom.findall("DataItem")
            if len(items) != 2:
                self.problem(where, f"{want} needs 2 DataItems (origin, spacing), found {len(items)}")
            for i, item in enumerate(items):
                if self.dims(item, where) != [rank]:
                    self.problem(where, f"geometry DataItem {i} should have Dimensions '{rank}'")
                try:
                    values = [float(v) for v in (item.text or "").split()]
                    if len(values) != rank:
                        self.problem(where, f"geometry DataItem {i} holds {len(values)} values")
                    if i == 1 and any(v <= 0 for v in values):
                        self.problem(where, "spacing must be positive")
                except ValueError:
                    self.problem(where, f"geometry DataItem {i} is not numeric")
            self.attributes(grid, dims, where)
        else:
            self.problem(where, f"unexpected TopologyType '{ttype}'")

    def run(self):
        try:
            root = ET.parse(self.xmf).getroot()
        except (ET.ParseError, OSError) as e:
            self.problem("XML", str(e))
            return
        if root.tag != "Xdmf":
            self.problem("root", f"root element <{root.tag}>, expected <Xdmf>")
            return
        domain = root.find("Domain")
        if domain is None:
            self.problem("Xdmf", "no <Domain>")
            return
        blocks = domain.findall("Grid")
        if not blocks:
            self.problem("Domain", "no <Grid>")
        names = set()
        for block in blocks:
            name = block.get("Name")
            where = f"block '{name}'"
            if name in names:
                self.problem(where, "two blocks with this name")
            names.add(name)
            if block.get("GridType") != "Collection" or block.get("CollectionType") != "Temporal":
                self.problem(where, "expected a temporal collection")
                continue
            last_time = None
            steps = block.findall("Grid")
            self.frames = max(self.frames, len(steps))
            for i, grid in enumerate(steps):
                w = f"{where}[{i}]"
                if grid.get("GridType", "Uniform") != "Uniform":
                    self.problem(w, "expected a Uniform grid")
                time = grid.find("Time")
                try:
                    t = float(time.get("Value")) if time is not None else None
                except (TypeError, ValueError):
                    t = None
                if t is None:
                    self.problem(w, "no numeric <Time Value=...>")
                elif last_time is not None and t < last_time:
                    self.problem(w, f"time {t} goes back from {last_time}")
                else:
                    last_time = t
                self.uniform(grid, w)


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    quiet = "--quiet" in argv
    if len(args) != 1:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    c = Checker(args[0])
    c.run()
    for p in c.problems:
        print(p)
    if not quiet:
        mode = "datasets checked with h5py" if h5py else "h5py absent: files checked, not dataset shapes"
        print(f"{args[0]}: {c.frames} frames, {c.datasets} HDF5 references, {len(c.problems)} problems ({mode})")
    return 1 if c.problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
