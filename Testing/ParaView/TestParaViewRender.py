"""One picture through ParaView with the plugin: the walnut model cut open, its surface f = 0
(the half behind the cut) and, on the cut, its material attribute (shell 1, kernel 2, outside -1), compared with a baseline image (VTK's vtkImageDifference, a small error
allowed for rasteriser differences). Run by pvbatch under xvfb-run.

usage: pvbatch TestParaViewRender.py BASELINE.png OUTPUT.png [--make-baseline]
"""
import sys

from paraview.simple import *  # noqa: F401,F403
from vtkmodules.vtkImagingCore import vtkImageDifference
from vtkmodules.vtkIOImage import vtkPNGReader

baseline, output = sys.argv[1:3]
walnut = ICTKFRepModel(ModelName="walnut", SampleDimensions=[80, 80, 80])
surface = Contour(Input=walnut, ContourBy=["POINTS", "f"], Isosurfaces=[0.0], ComputeScalars=0)
half = Clip(Input=surface, ClipType="Plane")
half.ClipType.Origin = [0, 0, 0]
half.ClipType.Normal = [1, 0, 0]
cut = Slice(Input=walnut, SliceType="Plane")
cut.SliceType.Origin = [0, 0, 0]
cut.SliceType.Normal = [1, 0, 0]
solid = Clip(Input=cut, ClipType="Scalar", Scalars=["POINTS", "f"], Value=0.0, Invert=0)
view = CreateView("RenderView")
view.ViewSize = [400, 300]
view.OrientationAxesVisibility = 0
view.Background = [1, 1, 1]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
shell = Show(half, view)
shell.ColorArrayName = ["POINTS", ""]
shell.DiffuseColor = [0.75, 0.6, 0.4]
inside = Show(solid, view)
ColorBy(inside, ("POINTS", "material"))
lut = GetColorTransferFunction("material")
lut.ApplyPreset("Cool to Warm", True)
lut.RescaleTransferFunction(-1.0, 2.0)
view.CameraPosition = [4.5, -2.2, 1.8]
view.CameraFocalPoint = [0, 0, 0]
view.CameraViewUp = [0, 0, 1]
view.CameraParallelProjection = 0
Render(view)
SaveScreenshot(output, view, ImageResolution=[400, 300])
if "--make-baseline" in sys.argv:
    SaveScreenshot(baseline, view, ImageResolution=[400, 300])

images = []
for path in (baseline, output):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    images.append(reader.GetOutput())
if images[0].GetDimensions() != images[1].GetDimensions():
    sys.exit(f"FAIL: image size {images[1].GetDimensions()} vs baseline {images[0].GetDimensions()}")
difference = vtkImageDifference()
difference.SetInputData(images[1])
difference.SetImageData(images[0])
difference.Update()
error = difference.GetThresholdedError()
print(f"thresholded error {error:.3f} (pixels differing beyond VTK's threshold, averaged)")
if error > 10.0:
    sys.exit(f"FAIL: the picture differs from the baseline (thresholded error {error:.3f} > 10)")
print("all checks passed")
