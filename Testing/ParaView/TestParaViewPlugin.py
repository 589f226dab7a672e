"""The ParaView plugin as a user meets it, run by pvpython through build/bin/ictk-paraview.

Checks that the plugin is loaded, that File > Open (OpenDataFile) picks ICTK's readers by
extension for every model file in Data/, and the numbers each reader and filter gives: values
against `ictk eval`, counts against `ictk validate` / `ictk tetra`, time steps and instances of an
.icm against the engine's own run (`ictk run --trace`).

usage: pvpython TestParaViewPlugin.py ICTK DATA WORK
"""
import glob
import json
import math
import os
import subprocess
import sys

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403 (ParaView's scripting interface)
from paraview.modules.vtkRemotingCore import vtkPVPluginTracker

ICTK, DATA, WORK = sys.argv[1:4]
os.makedirs(WORK, exist_ok=True)
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message)


def ictk_json(*args):
    out = subprocess.run([ICTK, *args, "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def fetch(proxy, time=None):
    """The proxy's output as the pipeline made it (pvpython's built-in server: the algorithm's
    own output, which keeps partitioned dataset collections as they are)."""
    if time is None:
        proxy.UpdatePipeline()
    else:
        proxy.UpdatePipeline(time)
    return proxy.GetClientSideObject().GetOutputDataObject(0)


# The plugin is known to ParaView's plugin tracker and loaded (it is what the Plugin Manager lists).
tracker = vtkPVPluginTracker.GetInstance()
names = {tracker.GetPluginName(i): tracker.GetPluginLoaded(i) for i in range(tracker.GetNumberOfPlugins())}
check(names.get("ICTK") is True or names.get("ICTK") == 1, f"plugin ICTK loaded: {names}")

# Every proxy the plugin defines exists, with its documented properties.
pxm = servermanager.ProxyManager()
expected = {
    ("sources", "ictkFRepReader"): ["FileName", "SampleDimensions", "ComputeAttributes", "TimeRange"],
    ("sources", "ictkFRepModelSource"): ["ModelName", "SampleDimensions"],
    ("sources", "ictkComplexReader"): ["FileName", "Selectors", "FeatureSize", "VolumeResolution"],
    ("sources", "ictkDynamicComplexReader"): ["FileName", "TimeStepSize", "FeatureSize"],
    ("filters", "ictkTetrahedralize"): ["Input", "Backend", "Size", "Deterministic"],
    ("filters", "ictkComplexValidator"): ["Input", "FeatureSize", "Tolerance", "FindUndeclared"],
}
for (group, name), properties in expected.items():
    proxy = pxm.SMProxyManager.GetPrototypeProxy(group, name)
    check(proxy is not None, f"proxy {group}/{name} defined")
    if proxy is not None:
        for p in properties:
            check(proxy.GetProperty(p) is not None, f"{name} has property {p}")

# The reader factory offers ICTK's readers for the extensions (File > Open's list).
factory = servermanager.vtkSMProxyManager.GetProxyManager().GetReaderFactory()
if factory.GetNumberOfRegisteredPrototypes() == 0:
    factory.UpdateAvailableReaders()
session = servermanager.ActiveConnection.Session


def readers_for(path):
    """File > Open's choices for a file (group, name, description triples)."""
    found = factory.GetReaders(path, session)
    return [found.GetString(i) for i in range(1, found.GetLength(), 3)]


for ext, reader in [("hf", "ictkFRepReader"), ("vm", "ictkFRepReader"), ("scn", "ictkFRepReader"),
                    ("icm", "ictkDynamicComplexReader")]:
    path = os.path.join(WORK, "probe." + ext)
    open(path, "w").close()
    ok = factory.CanReadFile(path, session)
    check(ok and factory.GetReaderName() == reader, f".{ext} opens with {reader} (got {factory.GetReaderName()})")

# Every HyperFun model of Data/ opens through OpenDataFile and samples with its attributes; values
# equal `ictk eval` at sampled points (float output: to float rounding).
for path in sorted(glob.glob(os.path.join(DATA, "Models", "*.hf"))):
    reader = OpenDataFile(path)
    check(reader is not None and reader.GetXMLName() == "ictkFRepReader", f"{path}: reader")
    if reader is None:
        continue
    # Models that use parameters (a[1], a[2]) get values for them; the others ignore them.
    text = open(path).read()
    params = [0.8, 0.3]
    reader.Parameters = params
    reader.SampleDimensions = [12, 12, 12]
    # Double: R-function unions far from the surface cancel catastrophically in float.
    reader.OutputScalarType = "double"
    image = fetch(reader)
    n = image.GetNumberOfPoints()
    dims = image.GetDimensions()
    check(n == dims[0] * dims[1] * dims[2] and n in (12 ** 3, 12 ** 2), f"{path}: {n} points {dims}")
    f = image.GetPointData().GetArray("f")
    check(f is not None, f"{path}: array f")
    timed = "x[4]" in text
    extra = ["--params", ",".join(map(str, params))] if params else []
    for i in (0, n // 3, n // 2, n - 1):
        x, y, z = image.GetPoint(i)
        at = f"{x!r},{y!r},{z!r}" + (",0" if timed else "")
        value = ictk_json("eval", path, "--at", at, *extra)["value"]
        got = f.GetTuple1(i)
        check(abs(got - value) <= 1e-9 * max(1.0, abs(value)), f"{path}: f({at}) {got} vs ictk eval {value}")
    Delete(reader)

# FRep XML: `ictk convert` of a model with attributes gives the same grid as the .hf.
xml = os.path.join(WORK, "vase.xml")
subprocess.run([ICTK, "convert", os.path.join(DATA, "Models", "coloured_vase.hf"), xml], check=True)
# .xml is shared with other readers (ParaView's CityGML reader accepts any XML), so File > Open
# lists the choices; ICTK's reader must be among them (its CanReadFile checks for <frep>).
check("ictkFRepReader" in readers_for(xml), f"File > Open offers ictkFRepReader for .xml: {readers_for(xml)}")
other = os.path.join(WORK, "other.xml")
with open(other, "w") as out:
    out.write('<?xml version="1.0"?>\n<VTKFile type="PolyData"/>\n')
check("ictkFRepReader" not in readers_for(other), "a non-FRep .xml is not offered to ictkFRepReader")
a = ICTKFRepModelReader(FileName=xml)
b = OpenDataFile(os.path.join(DATA, "Models", "coloured_vase.hf"))
for r in (a, b):
    r.SampleDimensions = [10, 10, 10]
    r.OutputScalarType = "double"
ia, ib = fetch(a), fetch(b)
fa, fb = ia.GetPointData().GetArray("f"), ib.GetPointData().GetArray("f")
check(ia.GetNumberOfPoints() == ib.GetNumberOfPoints() == 1000, "vase: 1000 points each")
check(max(abs(fa.GetTuple1(i) - fb.GetTuple1(i)) for i in range(1000)) < 1e-12, "vase: .xml == .hf")
check(ia.GetPointData().GetNumberOfArrays() == ib.GetPointData().GetNumberOfArrays() >= 2,
      "vase: the colour attribute is sampled")

# Fidget's .vm: a two-instruction model (x^2 + ... negated on import, docs/frep-kernel.md).
vm = os.path.join(WORK, "circle.vm")
with open(vm, "w") as out:
    out.write("_0 var-x\n_1 var-y\n_2 square _0\n_3 square _1\n_4 add _2 _3\n_5 const 1\n_6 sub _4 _5\n")
reader = OpenDataFile(vm)
reader.SampleDimensions = [5, 5, 1]
reader.ModelBounds = [-1, 1, -1, 1, 0, 0]
image = fetch(reader)
f = image.GetPointData().GetArray("f")
check(image.GetNumberOfPoints() == 25, f".vm: 25 points, got {image.GetNumberOfPoints()}")
for i in range(image.GetNumberOfPoints()):
    x, y, _ = image.GetPoint(i)
    check(abs(f.GetTuple1(i) - (1 - x * x - y * y)) < 1e-6, f".vm: f at ({x}, {y})")

# The registered XYZT model animates: time steps advertised and the values follow the time.
morph = ICTKFRepModel(ModelName="morph", SampleDimensions=[7, 7, 7], OutputScalarType="double")
morph.UpdatePipelineInformation()
steps = list(morph.TimestepValues)
check(len(steps) == 11 and steps[0] == 0 and steps[-1] == 1, f"morph: time steps {steps}")
for t in (0.0, 0.5, 1.0):
    image = fetch(morph, t)
    f = image.GetPointData().GetArray("f")
    x, y, z = image.GetPoint(100)
    value = ictk_json("eval", "morph", "--at", f"{x!r},{y!r},{z!r},{t!r}")["value"]
    check(abs(f.GetTuple1(100) - value) < 1e-12, f"morph at t={t}: {f.GetTuple1(100)} vs {value}")

# The flower complex: one partitioned dataset per cell, the assembly by dimension; selectors.
flower_json = os.path.join(DATA, "Models", "flower", "flower.json")
info = ictk_json("info", flower_json)
cells = info["cells"]
flower = OpenDataFile(flower_json)
check(flower.GetXMLName() == "ictkComplexReader", "flower.json opens with ictkComplexReader")
pdc = fetch(flower)
check(pdc.GetNumberOfPartitionedDataSets() == len(cells), f"flower: {pdc.GetNumberOfPartitionedDataSets()} datasets for {len(cells)} cells")
assembly = pdc.GetDataAssembly()
by_dimension = {d: len(assembly.GetDataSetIndices(assembly.FindFirstNodeWithName(f"dimension_{d}"))) for d in range(4)}
expected_dims = {d: sum(1 for c in cells if c["dimension"] == d) for d in range(4)}
check(by_dimension == expected_dims, f"flower by dimension {by_dimension} vs {expected_dims}")
# The block selector (Properties panel) gets the reader's assembly before any discretisation.
domain = flower.GetProperty("Selectors").SMProperty.FindDomain("vtkSMDataAssemblyDomain")
check(domain is not None and domain.GetDataAssembly() is not None
      and domain.GetDataAssembly().FindFirstNodeWithName("dimension_2") > 0,
      "the Selectors property offers the complex's assembly")
flower.Selectors = ["//dimension_2"]
pdc = fetch(flower)
for i in range(pdc.GetNumberOfPartitionedDataSets()):
    part = pdc.GetPartitionedDataSet(i)
    dim = part.GetFieldData().GetArray("CellDimension").GetValue(0)
    points = sum(part.GetPartition(j).GetNumberOfPoints() for j in range(part.GetNumberOfPartitions()) if part.GetPartition(j))
    check((points > 0) == (dim == 2), f"flower selector /dimension_2: cell {i} (dimension {dim}) has {points} points")
flower.Selectors = []

# Validation as a table: the same findings as `ictk validate`.
report = ictk_json("validate", flower_json)
validator = ICTKValidateComplex(Input=flower)
table = fetch(validator)
rows = table.GetNumberOfRows()
status = table.GetColumnByName("Status")
counts = {k: sum(1 for r in range(rows) if status.GetValue(r) == k) for k in ("satisfied", "violated", "undeclared")}
check(counts["satisfied"] == len(report["satisfied"]) and counts["violated"] == len(report["violated"]),
      f"validator {counts} vs ictk validate {len(report['satisfied'])} satisfied, {len(report['violated'])} violated")
check(table.GetFieldData().GetArray("Valid").GetValue(0) == (1 if report["ok"] else 0), "validator Valid")

# Tetrahedral meshing of the two-material bar: the same mesh as `ictk tetra` (TetGen is
# deterministic), quality report in the field data.
bar_json = os.path.join(DATA, "Models", "bar", "two_material_bar.json")
cli = ictk_json("tetra", bar_json, "-o", os.path.join(WORK, "bar.vtu"), "--backend", "tetgen", "--size", "0.05")
bar = OpenDataFile(bar_json)
tets = ICTKTetrahedralize(Input=bar, Backend="TetGen", Size=0.05)
grid = fetch(tets)
check(grid.GetNumberOfCells() == cli["tetrahedra"], f"bar: {grid.GetNumberOfCells()} tets vs {cli['tetrahedra']}")
check(grid.GetNumberOfPoints() == cli["points"], f"bar: {grid.GetNumberOfPoints()} points vs {cli['points']}")
angle = grid.GetFieldData().GetArray("MinDihedralAngle").GetValue(0)
check(abs(angle - cli["min_dihedral_degrees"]) < 1e-9, f"bar min dihedral {angle} vs {cli['min_dihedral_degrees']}")
volumes = grid.GetFieldData().GetArray("MaterialVolume")
for m in cli["materials"]:
    got = volumes.GetValue(m["material"] - 1)
    check(abs(got - m["mesh_volume"]) < 1e-12, f"bar material {m['name']} volume {got} vs {m['mesh_volume']}")
materials = grid.GetCellData().GetArray("MaterialId").GetRange()
check(materials == (1.0, 2.0), f"bar MaterialId range {materials}")

# The dynamic complex: time steps over the model's span, the instances of the engine's own run.
icm = os.path.join(DATA, "Models", "icm", "ch5_1_disk_rectangle.icm")
trace = os.path.join(WORK, "disk.jsonl")
subprocess.run([ICTK, "run", icm, "--frames", "0:6:1", "-o", os.path.join(WORK, "disk.pvd"), "--trace", trace],
               check=True, capture_output=True)
engine = {}
for line in open(trace):
    record = json.loads(line)
    if not record["transition"]:
        engine[round(record["time"], 9)] = record["instance"]
dynamic = OpenDataFile(icm)
check(dynamic.GetXMLName() == "ictkDynamicComplexReader", ".icm opens with ictkDynamicComplexReader")
dynamic.TimeStepSize = 0.5
dynamic.UpdatePipelineInformation()
steps = list(dynamic.TimestepValues)
# The model's film is TIMESPAN(0, 10): 21 steps of 0.5.
check(len(steps) == 21 and steps[0] == 0 and abs(steps[-1] - 10) < 1e-12, f"disk: time steps {steps}")
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
for t in (1.0, 2.0, 4.0, 5.0):
    frame = fetch(dynamic, t)
    instance = frame.GetFieldData().GetAbstractArray("Instance").GetValue(0)
    check(instance == engine[t], f"disk at t={t}: instance {instance}, engine {engine[t]}")
    time = frame.GetFieldData().GetArray("Time").GetValue(0)
    check(abs(time - t) < 1e-12, f"disk frame time {time} vs {t}")

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("all checks passed")
