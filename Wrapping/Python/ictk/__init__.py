"""ICTK, the Implicit Complex ToolKit: VTK algorithms for heterogeneous FRep objects, and a
Pythonic layer over them (ictk.load, ictk.Model, ictk.Complex, ictk.DynamicModel; see
ictk.models). The same package imports in /usr/bin/python3 and in ParaView's pvpython.

    import ictk
    model = ictk.load("Data/Models/bracket.hf")
    values = model.evaluate(numpy_points)          # (N, 3) -> (N,), no copies

    from ictk import ictkFiltersFRep               # the VTK classes themselves
    sampler = ictkFiltersFRep.ictkFRepSampler()
    sampler.SetModelName("walnut")
"""
from .models import Complex, DynamicModel, Error, Frame, Grid, Model, load  # noqa: F401
