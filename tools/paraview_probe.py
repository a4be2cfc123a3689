"""Open an XDMF index with ParaView's readers and print what they see, one line per block and
time, as JSON. Run with ParaView's Python:  pvbatch tools/paraview_probe.py RUN/frames.xmf

Each line: {"reader", "time", "block", "class", "points", "cells", "bounds", "arrays": {name:
components}, "first": {name: first tuple}}. Used by the io tests (when ParaView is installed) to
prove that ParaView opens the frames the writer produces.
"""
import json
import sys

from paraview import servermanager as sm
from paraview.simple import XDMFReader, Xdmf3ReaderS


def probe(reader_name, reader):
    for t in list(reader.TimestepValues) or [0.0]:
        reader.UpdatePipeline(t)
        data = sm.Fetch(reader)
        it = data.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            blk = it.GetCurrentDataObject()
            meta = it.GetCurrentMetaData()
            name = meta.Get(data.NAME()) if meta is not None and meta.Has(data.NAME()) else None
            pd = blk.GetPointData()
            arrays = {pd.GetArrayName(i): pd.GetArray(i).GetNumberOfComponents() for i in range(pd.GetNumberOfArrays())}
            first = {n: list(pd.GetArray(n).GetTuple(0)) for n in arrays if blk.GetNumberOfPoints() > 0}
            print(json.dumps({"reader": reader_name, "time": t, "block": name, "class": blk.GetClassName(),
                              "points": blk.GetNumberOfPoints(), "cells": blk.GetNumberOfCells(),
                              "bounds": list(blk.GetBounds()), "arrays": arrays, "first": first}))
            it.GoToNextItem()


path = sys.argv[1]
probe("xdmf2", XDMFReader(FileNames=[path]))
probe("xdmf3", Xdmf3ReaderS(FileName=[path]))
