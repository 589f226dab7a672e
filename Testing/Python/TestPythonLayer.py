"""The Pythonic layer (ictk.load, Model, Complex, DynamicModel), run by /usr/bin/python3 and by
pvpython: values against formulas and the VTK classes, NumPy arrays shared without copies, errors
as ictk.Error with the place.

usage: python3 TestPythonLayer.py DATA
"""
import math
import os
import sys

import numpy as np

import ictk
from ictk import ictkFiltersFRep

DATA = sys.argv[1]
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message, flush=True)


rng = np.random.default_rng(7)
points = rng.uniform(-1.2, 1.2, size=(20000, 3))

# The unit sphere: f = 1 - |p|^2, grad f = -2p.
sphere = ictk.load("sphere")
f = sphere.evaluate(points)
check(f.shape == (20000,), f"values shape {f.shape}")
check(np.max(np.abs(f - (1 - np.sum(points ** 2, axis=1)))) < 1e-14, "sphere values")
g = sphere.gradient(points)
check(g.shape == (20000, 4), f"gradient shape {g.shape}")
check(np.max(np.abs(g[:, :3] + 2 * points)) < 1e-14 and not np.any(g[:, 3]), "sphere gradient")
check(sphere.bounds == (-1.2, 1.2, -1.2, 1.2, -1.2, 1.2), f"sphere bounds {sphere.bounds}")
check(not sphere.time_dependent, "sphere has no time")

# Without copies: the arrays handed to C++ are the NumPy arrays' own memory.
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from ictk.models import _output, _points

array, vpoints = _points(points)
check(array is points and np.shares_memory(vtk_to_numpy(vpoints), points), "points are not copied")
out, vout = _output(5)
check(np.shares_memory(vtk_to_numpy(vout), out), "results are written in place")
# Float32 or strided points are converted once, and give the same values.
check(np.array_equal(sphere.evaluate(points.astype(np.float32)),
                     sphere.evaluate(points.astype(np.float32).astype(np.float64))), "float32 points")
check(np.array_equal(sphere.evaluate(np.asfortranarray(points)), f), "Fortran-ordered points")

# The walnut's attributes equal the sampler's at grid points; the grid as NumPy views.
walnut = ictk.load("walnut")
check(walnut.attribute_names == {"material": 1, "density": 1, "colour": 3}, f"walnut attributes {walnut.attribute_names}")
grid = walnut.sample((24, 20, 16), double=True)
check(grid.f.shape == (16, 20, 24), f"grid shape {grid.f.shape}")
check(grid.attributes["colour"].shape == (16, 20, 24, 3), "colour grid shape")
nx, ny, nz = grid.dimensions
k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
xyz = np.stack([grid.origin[a] + grid.spacing[a] * idx for a, idx in enumerate((i, j, k))], axis=-1).reshape(-1, 3)
check(np.max(np.abs(walnut.evaluate(xyz) - grid.f.reshape(-1))) < 1e-12, "walnut values == sampler")
attributes = walnut.attributes(xyz)
check(np.array_equal(attributes["material"], grid.attributes["material"].reshape(-1)), "material == sampler")
check(np.max(np.abs(attributes["colour"] - grid.attributes["colour"].reshape(-1, 3))) < 1e-12, "colour == sampler")
shell = np.count_nonzero(attributes["material"] == 1)
kernel = np.count_nonzero(attributes["material"] == 2)
check(shell > 0 and kernel > 0, f"walnut: {shell} shell and {kernel} kernel points")

# A space-time HyperFun file: 4-column points carry t; 3-column ones use `time`.
ball = ictk.load(os.path.join(DATA, "Models", "growing_ball.hf"))
check(ball.time_dependent, "growing_ball is XYZT")
p4 = np.array([[0.1, 0.2, 0.3, 0.0], [0.1, 0.2, 0.3, 0.8]])
expected = [(0.5 + t) ** 2 - (0.1 - t) ** 2 - 0.04 - 0.09 for t in (0.0, 0.8)]
check(np.allclose(ball.evaluate(p4), expected, rtol=0, atol=1e-14), f"growing_ball {ball.evaluate(p4)}")
check(abs(ball.evaluate(p4[:1, :3], time=0.8)[0] - expected[1]) < 1e-14, "3-column points at time 0.8")

# A model with parameters (HyperFun's a[1], a[2]): a torus of radii 0.8 and 0.3.
ring = ictk.load(os.path.join(DATA, "Models", "parametric_ring.hf"), parameters=(0.8, 0.3))
on = np.array([[1.1, 0.0, 0.0], [0.8, 0.0, 0.3], [0.0, 0.5, 0.0]])
values = ring.evaluate(on)
check(abs(values[0]) < 1e-9 and abs(values[1]) < 1e-9 and abs(values[2]) < 1e-9, f"ring surface points {values}")

# Errors: ictk.Error with the place, not a print.
bad = os.path.join(os.environ.get("TMPDIR", "/tmp"), "ictk_bad_%d.hf" % os.getpid())
with open(bad, "w") as out:
    out.write("m(x[3], a[1])\n{\n  m = 1 - * x[1];\n}\n")
try:
    ictk.load(bad)
    check(False, "a syntax error raises")
except ictk.Error as e:
    check(f"{bad}:3:11: error" in str(e), f"the error names the place: {e}")
os.remove(bad)
for wrong, what in ((np.zeros((4, 2)), "(N, 3) or (N, 4)"), (np.zeros(3), "(N, 3) or (N, 4)")):
    try:
        sphere.evaluate(wrong)
        check(False, f"shape {wrong.shape} raises")
    except ictk.Error as e:
        check(what in str(e), f"bad shape: {e}")
try:
    ictk.load("no_such_model")
    check(False, "an unknown model raises")
except ictk.Error as e:
    check("unknown model 'no_such_model'" in str(e), f"unknown model: {e}")

# The flower complex: discretised, by selector, validated; the bar meshed in tetrahedra.
flower = ictk.load(os.path.join(DATA, "Models", "flower", "flower.json"))
data = flower.discretise(feature_size=0.05)
check(data.GetNumberOfPartitionedDataSets() == 12, "flower: 12 cells")
curves = flower.discretise(feature_size=0.05, selectors=["//dimension_1"])
with_points = [i for i in range(12) if curves.GetPartitionedDataSet(i).GetNumberOfPoints()]
dims = [curves.GetPartitionedDataSet(i).GetFieldData().GetArray("CellDimension").GetValue(0) for i in with_points]
check(dims == [1, 1, 1], f"flower //dimension_1 gives the three curves: {dims}")
report = flower.validate()
check(report and all(r["status"] != "violated" for r in report), "flower relations hold")
bar = ictk.load(os.path.join(DATA, "Models", "bar", "two_material_bar.json"))
mesh = bar.tetrahedralize(0.05, backend="tetgen")
material = vtk_to_numpy(mesh.GetCellData().GetArray("MaterialId"))
check(set(np.unique(material)) == {1, 2}, f"bar materials {np.unique(material)}")
volume = mesh.GetFieldData().GetArray("Volume").GetValue(0)
check(abs(volume - 0.08) < 1e-9, f"bar volume {volume} (2 x 0.2 x 0.2)")

# A dynamic complex, frame by frame: thesis 5.1, K1 before the tangency at t = 3, K3 after.
disk = ictk.load(os.path.join(DATA, "Models", "icm", "ch5_1_disk_rectangle.icm"), time_step=0.5, feature_size=0.1)
check(len(disk.time_steps) == 21, f"disk: {len(disk.time_steps)} time steps")
frames = list(disk.frames([1.0, 2.0, 4.0, 5.0]))
check([fr.instance for fr in frames] == ["K1", "K1", "K3", "K3"], f"disk instances {[fr.instance for fr in frames]}")
check([fr.data.GetNumberOfPartitionedDataSets() for fr in frames] == [2, 2, 7, 7], "disk cells per frame")

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("all checks passed")
