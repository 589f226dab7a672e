"""The Python package `ictk` in VTK pipelines (run with Debian's /usr/bin/python3)."""
import math
import sys

import os

import vtk
from ictk import ictkFiltersComplex, ictkFiltersDynamics, ictkFiltersFRep


def check(condition, message):
    if not condition:
        sys.exit("FAIL: " + message)


# The sampler as a pipeline source: the unit sphere f = 1 - x^2 - y^2 - z^2.
sampler = ictkFiltersFRep.ictkFRepSampler()
sampler.SetModelName("sphere")
sampler.SetSampleDimensions(5, 5, 5)
sampler.Update()
image = sampler.GetOutput()
check(image.GetDimensions() == (5, 5, 5), f"dimensions {image.GetDimensions()}")
f = image.GetPointData().GetArray("f")
for i in range(image.GetNumberOfPoints()):
    x, y, z = image.GetPoint(i)
    check(abs(f.GetTuple1(i) - (1 - x * x - y * y - z * z)) < 1e-6, f"f at point {i}")

# Sampler -> Flying Edges -> mass properties: the volume and area of the unit sphere.
sampler.SetSampleDimensions(96, 96, 96)
contour = vtk.vtkFlyingEdges3D()
contour.SetInputConnection(sampler.GetOutputPort())
contour.SetValue(0, 0.0)
mass = vtk.vtkMassProperties()
mass.SetInputConnection(contour.GetOutputPort())
mass.Update()
check(abs(mass.GetVolume() - 4 / 3 * math.pi) < 0.01 * 4 / 3 * math.pi, f"volume {mass.GetVolume()}")
check(abs(mass.GetSurfaceArea() - 4 * math.pi) < 0.01 * 4 * math.pi, f"area {mass.GetSurfaceArea()}")

# The implicit-function adaptor in VTK's own filters (negative inside, as VTK expects).
function = ictkFiltersFRep.ictkFRepImplicitFunction()
function.SetModelName("sphere")
check(abs(function.EvaluateFunction(0.5, 0, 0) + 0.75) < 1e-12, "implicit function value")
gradient = [0.0, 0.0, 0.0]
function.EvaluateGradient([0.5, 0.0, 0.0], gradient)
check(max(abs(g - e) for g, e in zip(gradient, (1.0, 0.0, 0.0))) < 1e-12, f"gradient {gradient}")
plane = vtk.vtkPlaneSource()
plane.SetOrigin(-2, -2, 0)
plane.SetPoint1(2, -2, 0)
plane.SetPoint2(-2, 2, 0)
plane.SetResolution(200, 200)
triangles = vtk.vtkTriangleFilter()
triangles.SetInputConnection(plane.GetOutputPort())
clip = vtk.vtkClipPolyData()
clip.SetInputConnection(triangles.GetOutputPort())
clip.SetClipFunction(function)
clip.InsideOutOn()
area = vtk.vtkMassProperties()
area.SetInputConnection(clip.GetOutputPort())
area.Update()
# The z = 0 section of the unit sphere is the unit disk.
check(abs(area.GetSurfaceArea() - math.pi) < 0.005 * math.pi, f"clipped area {area.GetSurfaceArea()}")
# The flower complex as a partitioned dataset collection: 12 cells, 4/3/2/3 by dimension in the
# assembly, a colour on every point.
source = ictkFiltersComplex.ictkComplexSource()
source.SetFileName(os.environ["ICTK_FLOWER"])
source.SetFeatureSize(0.04)
source.Update()
collection = source.GetOutput()
check(collection.GetNumberOfPartitionedDataSets() == 12, "flower: 12 cells")
assembly = collection.GetDataAssembly()
per_dimension = [assembly.GetNumberOfChildren(assembly.GetFirstNodeByPath(f"/flower/dimension_{p}"))
                 for p in range(4)]
check(per_dimension == [4, 3, 2, 3], f"flower: cells per dimension {per_dimension}")
for i in range(12):
    leaf = collection.GetPartitionedDataSet(i).GetPartition(0)
    check(leaf.GetPointData().GetArray("colour") is not None, f"flower: colour on cell {i}")
# A dynamic complex in VTK's temporal pipeline (thesis 5.1): the disk's centre is at x = -2 + t;
# before the tangency at t = 3 the instance is K1 (2 cells), after it K3 (7 cells).
dynamic = ictkFiltersDynamics.ictkDynamicComplexSource()
dynamic.SetFileName(os.environ["ICTK_DISK_RECTANGLE"])
dynamic.SetTimeStepSize(0.5)
dynamic.SetFeatureSize(0.1)
for t, instance, cells in ((2.0, "K1", 2), (4.5, "K3", 7)):
    dynamic.UpdateTimeStep(t)
    frame = dynamic.GetOutput()
    check(dynamic.GetInstanceName() == instance, f"disk at t = {t}: instance {dynamic.GetInstanceName()}")
    check(frame.GetNumberOfPartitionedDataSets() == cells, f"disk at t = {t}: {cells} cells")
    stamped = frame.GetInformation().Get(vtk.vtkDataObject.DATA_TIME_STEP())
    check(abs(stamped - t) < 1e-12, f"DATA_TIME_STEP {stamped}")
# The same run written as a time series (ictkTimeSeriesWriter): frames 4 to 8 (t = 2 .. 4), each
# frame as the source gives it at its time.
import tempfile
import xml.etree.ElementTree as ET
with tempfile.TemporaryDirectory() as work:
    writer = ictkFiltersDynamics.ictkTimeSeriesWriter()
    writer.SetInputConnection(dynamic.GetOutputPort())
    writer.SetFileName(os.path.join(work, "disk.pvd"))
    writer.SetFirstTimeStep(4)
    writer.SetLastTimeStep(8)
    check(writer.Write() == 1 and writer.GetNumberOfFramesWritten() == 5, "time series written")
    datasets = ET.parse(os.path.join(work, "disk.pvd")).getroot().findall("./Collection/DataSet")
    check([float(d.get("timestep")) for d in datasets] == [2.0, 2.5, 3.0, 3.5, 4.0],
          f"time series times {[d.get('timestep') for d in datasets]}")
    reader = vtk.vtkXMLPartitionedDataSetCollectionReader()
    reader.SetFileName(os.path.join(work, datasets[4].get("file")))
    reader.Update()
    dynamic.UpdateTimeStep(4.0)
    check(reader.GetOutput().GetNumberOfPartitionedDataSets() == dynamic.GetOutput().GetNumberOfPartitionedDataSets() == 7,
          "time series frame at t = 4")
print("python wrapping: all checks passed")
