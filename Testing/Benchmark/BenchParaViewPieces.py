"""Speed-up of ICTK's sources over MPI ranks in pvbatch (not a test; docs/paraview.md):
  mpirun -np N ./Scripts/paraview pvbatch --symmetric Testing/Benchmark/BenchParaViewPieces.py DATA
Times, per rank, the walnut sampled at 256^3 (one thread per rank, so that N ranks use N cores)
and the flower complex discretised at feature size 0.01; rank 0 prints the slowest rank's time.
"""
import sys
import time

from paraview.simple import *  # noqa: F401,F403
from vtkmodules.vtkParallelCore import vtkMultiProcessController

DATA = sys.argv[1]
controller = vtkMultiProcessController.GetGlobalController()
rank, ranks = controller.GetLocalProcessId(), controller.GetNumberOfProcesses()


def timed(proxy, runs=3):
    """Best wall time over runs of this rank's piece (every rank's algorithm asked for its own
    piece, as ParaView asks; the barriers make the slowest rank decide)."""
    algorithm = proxy.GetClientSideObject()
    best = float("inf")
    for _ in range(runs):
        algorithm.Modified()
        controller.Barrier()
        start = time.perf_counter()
        algorithm.UpdatePiece(rank, ranks, 0)
        controller.Barrier()
        best = min(best, time.perf_counter() - start)
    return best


sampler = ICTKFRepModel(ModelName="walnut", SampleDimensions=[256, 256, 256], NumberOfThreads=1)
sampling = timed(sampler)
flower = OpenDataFile(f"{DATA}/Models/flower/flower.json")
flower.FeatureSize = 0.01
flower.NumberOfThreads = 1
discretising = timed(flower, runs=1)
points = flower.GetClientSideObject().GetOutputDataObject(0).GetNumberOfPoints()
if rank == 0:
    print(f"ranks {ranks}: walnut 256^3 sampling {sampling:.3f} s; flower at 0.01 {discretising:.3f} s "
          f"(rank 0 has {points} points)", flush=True)
