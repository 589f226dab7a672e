"""ICTK's sources under MPI: `mpirun -np N pvbatch --symmetric` with the plugin. Every rank runs
this script; ParaView asks each for its piece. Checks that each rank computed a part (not rank 0
everything), that the parts equal a one-process computation at the same points, and that the
parts add up to the whole: grid cells (ghosts discounted), contour triangles and area, the
flower complex's cells and points.

usage: mpirun -np 2 pvbatch --symmetric TestParaViewPieces.py DATA
"""
import sys

from paraview.simple import *  # noqa: F401,F403
from vtkmodules.vtkFiltersCore import vtkContourFilter, vtkMassProperties, vtkTriangleFilter
from vtkmodules.vtkParallelCore import vtkMultiProcessController
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkIdList
from vtkmodules.vtkCommonDataModel import vtkTriangle
from ictk import ictkFiltersComplex, ictkFiltersDynamics, ictkFiltersFRep

DATA = sys.argv[1]
controller = vtkMultiProcessController.GetGlobalController()
rank, ranks = controller.GetLocalProcessId(), controller.GetNumberOfProcesses()
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print(f"[rank {rank}] FAIL: {message}", flush=True)


def total(value):
    """The sum over ranks (every rank gets it)."""
    send, receive = vtkDoubleArray(), vtkDoubleArray()
    send.InsertNextValue(float(value))
    receive.SetNumberOfTuples(1)
    controller.AllReduce(send, receive, 2)  # vtkCommunicator::SUM_OP
    return receive.GetValue(0)


def area(polydata):
    triangles = vtkTriangleFilter()
    triangles.SetInputData(polydata)
    mass = vtkMassProperties()
    mass.SetInputConnection(triangles.GetOutputPort())
    mass.Update()
    return mass.GetSurfaceArea() if polydata.GetNumberOfCells() else 0.0


check(ranks >= 2, f"{ranks} process(es): run under mpirun -np 2")

# Sampling: each rank samples its piece of the grid.
dims = [41, 37, 33]
sampler = ICTKFRepModel(ModelName="walnut", SampleDimensions=dims, OutputScalarType="double")
contour = Contour(Input=sampler, ContourBy=["POINTS", "f"], Isosurfaces=[0.0], ComputeScalars=0)
contour.UpdatePipeline()
piece = sampler.GetClientSideObject().GetOutputDataObject(0)
whole_cells = (dims[0] - 1) * (dims[1] - 1) * (dims[2] - 1)
check(0 < piece.GetNumberOfPoints() < dims[0] * dims[1] * dims[2],
      f"rank {rank} sampled {piece.GetNumberOfPoints()} of {dims[0] * dims[1] * dims[2]} points")
ghosts = piece.GetCellGhostArray()
owned = sum(1 for c in range(piece.GetNumberOfCells()) if not ghosts or ghosts.GetValue(c) == 0)
check(total(owned) == whole_cells, f"grid cells over ranks {total(owned)} vs {whole_cells}")

# The one-process reference, computed here by a plain VTK pipeline (no pieces).
reference = ictkFiltersFRep.ictkFRepSampler()
reference.SetModelName("walnut")
reference.SetSampleDimensions(*dims)
reference.SetOutputScalarTypeToDouble()
reference.Update()
ref = reference.GetOutput()
f, ref_f = piece.GetPointData().GetArray("f"), ref.GetPointData().GetArray("f")
mismatches = sum(1 for i in range(piece.GetNumberOfPoints())
                 if f.GetTuple1(i) != ref_f.GetTuple1(ref.FindPoint(piece.GetPoint(i))))
check(mismatches == 0, f"rank {rank}: {mismatches} values differ from the one-process grid")

surface = contour.GetClientSideObject().GetOutputDataObject(0)


def owned_part(surface, piece):
    """(triangles, area) of a piece's contour inside the piece proper, not its ghost layer: with
    ghosts, neighbouring pieces both contour the shared layer."""
    point_ghosts = piece.GetPointGhostArray()
    inside = [i for i in range(piece.GetNumberOfPoints()) if not point_ghosts or point_ghosts.GetValue(i) == 0]
    lo = [min(piece.GetPoint(i)[a] for i in inside) for a in range(3)]
    hi = [max(piece.GetPoint(i)[a] for i in inside) for a in range(3)]
    count, area = 0, 0.0
    for c in range(surface.GetNumberOfCells()):
        ids = surface.GetCell(c).GetPointIds()
        corners = [surface.GetPoint(ids.GetId(k)) for k in range(3)]
        centre = [sum(p[a] for p in corners) / 3 for a in range(3)]
        if all(lo[a] <= centre[a] <= hi[a] for a in range(3)):
            count += 1
            area += vtkTriangle.TriangleArea(*corners)
    return count, area


check(piece.GetPointGhostArray() is not None or ranks == 1, f"rank {rank}: no ghost layer was asked for")
local_triangles, local_area = owned_part(surface, piece)
whole_contour = vtkContourFilter()
whole_contour.SetInputConnection(reference.GetOutputPort())
whole_contour.SetValue(0, 0.0)
whole_contour.Update()
expected_triangles = whole_contour.GetOutput().GetNumberOfCells()
expected_area = area(whole_contour.GetOutput())
triangles = total(local_triangles)
check(surface.GetNumberOfCells() > 0, f"rank {rank} contoured nothing")
check(triangles == expected_triangles, f"contour triangles over ranks {triangles} vs {expected_triangles}")
surface_area = total(local_area)
check(abs(surface_area - expected_area) < 1e-9 * expected_area, f"contour area {surface_area} vs {expected_area}")

# The flower complex: each rank discretises its share of the cells.
flower = OpenDataFile(f"{DATA}/Models/flower/flower.json")
flower.UpdatePipeline()
mine = flower.GetClientSideObject().GetOutputDataObject(0)
one = ictkFiltersComplex.ictkComplexSource()
one.SetFileName(f"{DATA}/Models/flower/flower.json")
one.Update()
whole = one.GetOutput()
check(mine.GetNumberOfPartitionedDataSets() == whole.GetNumberOfPartitionedDataSets(), "same cells on every rank")
local_cells = 0
for i in range(whole.GetNumberOfPartitionedDataSets()):
    n = mine.GetPartitionedDataSet(i).GetNumberOfPoints()
    if n:
        local_cells += 1
        check(n == whole.GetPartitionedDataSet(i).GetNumberOfPoints(), f"rank {rank}: cell {i} has {n} points")
check(0 < local_cells < whole.GetNumberOfPartitionedDataSets(), f"rank {rank} discretised {local_cells} cells")
check(total(local_cells) == whole.GetNumberOfPartitionedDataSets(), f"cells over ranks {total(local_cells)}")
check(total(mine.GetNumberOfPoints()) == whole.GetNumberOfPoints(),
      f"complex points over ranks {total(mine.GetNumberOfPoints())} vs {whole.GetNumberOfPoints()}")

# The dynamic complex (thesis 5.1) at t = 4 (instance K3, 7 cells): shared out the same way.
icm = f"{DATA}/Models/icm/ch5_1_disk_rectangle.icm"
dynamic = OpenDataFile(icm)
dynamic.TimeStepSize = 0.5
dynamic.FeatureSize = 0.05
dynamic.UpdatePipeline(4.0)
frame = dynamic.GetClientSideObject().GetOutputDataObject(0)
one_dynamic = ictkFiltersDynamics.ictkDynamicComplexSource()
one_dynamic.SetFileName(icm)
one_dynamic.SetTimeStepSize(0.5)
one_dynamic.SetFeatureSize(0.05)
one_dynamic.UpdateTimeStep(4.0)
whole_frame = one_dynamic.GetOutput()
n = whole_frame.GetNumberOfPartitionedDataSets()
check(frame.GetNumberOfPartitionedDataSets() == n == 7, f"disk at t = 4: {frame.GetNumberOfPartitionedDataSets()} cells, {n} in one process")
mine = [i for i in range(n) if frame.GetPartitionedDataSet(i).GetNumberOfPoints()]
check(all(i % ranks == rank for i in mine), f"rank {rank}: disk cells {mine}")
for i in mine:
    check(frame.GetPartitionedDataSet(i).GetNumberOfPoints() == whole_frame.GetPartitionedDataSet(i).GetNumberOfPoints(),
          f"rank {rank}: disk cell {i} points")
check(total(frame.GetNumberOfPoints()) == whole_frame.GetNumberOfPoints(),
      f"disk points over ranks {total(frame.GetNumberOfPoints())} vs {whole_frame.GetNumberOfPoints()}")
check(frame.GetFieldData().GetAbstractArray("Instance").GetValue(0) == "K3", "disk at t = 4 is K3 on every rank")

bad = total(len(failures))
if rank == 0:
    print(f"{ranks} ranks; grid cells {whole_cells}; contour {expected_triangles} triangles; "
          f"flower {whole.GetNumberOfPartitionedDataSets()} cells", flush=True)
    print("all checks passed" if bad == 0 else f"{int(bad)} check(s) failed", flush=True)
# No sys.exit: raising SystemExit in symmetric pvbatch aborts its MPI teardown; the ctest driver
# (run_checked.py) reads the closing line and the exit code.
