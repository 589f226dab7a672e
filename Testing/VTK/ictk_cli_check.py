#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Runs the ictk command-line tool as a user would and checks what it prints and writes.

Usage: ictk_cli_check.py --ictk PATH --work DIR CHECK [ARGS...]
  models | eval-json | eval-plain | sample-sphere | sample-walnut | sample-disk2d | bench
  | bench-scaling | bench-peer | render
  run-disk DATA | run-errors DATA   (ictk run on the .icm models in DATA/Models/icm)
  sample-icm DATA   (ictk sample on DATA/Models/icm/ch5_3_space_time_blend.icm)
  tetra-bar DATA | solve-bar DATA   (ictk tetra and ictk solve on DATA/Models/bar)
  study DATA   (ictk study on DATA/Studies/ct-implant and its bad inputs; needs invesalius-examples)
  expect-error REGEX -- ICTK-ARGS...   (exit code 2, one 'ictk: error:' line matching REGEX)
"@WORK@" in ICTK-ARGS is replaced by the work folder.
"""
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys


def run(ictk, args, check=True):
    p = subprocess.run([ictk] + args, capture_output=True, text=True, timeout=100)
    if check and p.returncode != 0:
        sys.exit(f"FAIL: ictk {' '.join(args)} exited {p.returncode}\nstdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p


def near(a, b, tol, what):
    if not (abs(a - b) <= tol):
        sys.exit(f"FAIL: {what}: {a} != {b} (tolerance {tol})")


def check_models(ictk, work):
    out = run(ictk, ["models"]).stdout
    for name in ("sphere", "walnut"):
        if not re.search(rf"^{name}\s+\[", out, re.M):
            sys.exit(f"FAIL: 'ictk models' does not list {name}:\n{out}")
    models = json.loads(run(ictk, ["models", "--json"]).stdout)
    sphere = [m for m in models if m["name"] == "sphere"]
    if len(sphere) != 1 or len(sphere[0]["bounds"]) != 6 or not sphere[0]["description"]:
        sys.exit(f"FAIL: 'ictk models --json' has no proper sphere entry: {models}")


def check_eval_json(ictk, work):
    # The bundled sphere is f = 1 - x^2 - y^2 - z^2.
    x, y, z = 0.3, 0.4, 0.5
    r = json.loads(run(ictk, ["eval", "sphere", "--at", f"{x},{y},{z}", "--json"]).stdout)
    if r["model"] != "sphere" or r["point"] != [x, y, z, 0.0]:
        sys.exit(f"FAIL: model/point wrong: {r}")
    near(r["value"], 1 - x * x - y * y - z * z, 1e-12, "value")
    for got, want in zip(r["gradient"], [-2 * x, -2 * y, -2 * z, 0.0]):
        near(got, want, 1e-12, "gradient")
    # A finite difference agrees with the reported gradient.
    h = 1e-5
    plus = json.loads(run(ictk, ["eval", "sphere", "--at", f"{x + h},{y},{z}", "--json"]).stdout)["value"]
    minus = json.loads(run(ictk, ["eval", "sphere", "--at", f"{x - h},{y},{z}", "--json"]).stdout)["value"]
    near((plus - minus) / (2 * h), r["gradient"][0], 1e-6, "finite-difference d/dx")
    norm = math.sqrt(x * x + y * y + z * z)
    for got, want in zip(r["normal"], [x / norm, y / norm, z / norm]):
        near(got, want, 1e-12, "outward normal")
    if r["membership"] != 2 or r["attributes"] != {}:
        sys.exit(f"FAIL: membership/attributes wrong: {r}")
    outside = json.loads(run(ictk, ["eval", "sphere", "--at", "2,0,0,0.5", "--json"]).stdout)
    if outside["membership"] != 0 or outside["point"][3] != 0.5:
        sys.exit(f"FAIL: outside point: {outside}")
    # --time is an instant in every command: x,y,z with --time t is the point x,y,z,t.
    timed = json.loads(run(ictk, ["eval", "sphere", "--at", "2,0,0", "--time", "0.5", "--json"]).stdout)
    if timed != outside:
        sys.exit(f"FAIL: --time 0.5 gives {timed}, not {outside}")
    on = json.loads(run(ictk, ["eval", "sphere", "--at", "1,0,0", "--json"]).stdout)
    if on["membership"] != 1:
        sys.exit(f"FAIL: boundary point: {on}")
    # Attributes of the heterogeneous walnut at a point of its shell on the x axis.
    w = json.loads(run(ictk, ["eval", "walnut", "--at", "0.9,0,0", "--json"]).stdout)
    attributes = w["attributes"]
    if set(attributes) != {"material", "density", "colour"} or len(attributes["colour"]) != 3:
        sys.exit(f"FAIL: walnut attributes: {attributes}")
    near(attributes["material"], 1.0, 0, "walnut material in the shell")
    near(attributes["density"], 1.2 - 0.4 * 0.9, 1e-12, "walnut density")


def check_eval_plain(ictk, work):
    out = run(ictk, ["eval", "sphere", "--at", "0.5,0,0"]).stdout.strip()
    near(float(out), 0.75, 1e-15, "plain eval")


def read_image(path):
    import vtk
    r = vtk.vtkXMLImageDataReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def read_polydata(path):
    import vtk
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def no_leftovers(work):
    left = [f for f in os.listdir(work) if ".tmp-" in f]
    if left:
        sys.exit(f"FAIL: temporary files left behind: {left}")


def check_sample_sphere(ictk, work):
    vti, vtp = os.path.join(work, "sphere.vti"), os.path.join(work, "sphere.vtp")
    p = run(ictk, ["sample", "sphere", "-o", vti, "--dims", "21,17,13", "--bounds", "-1.2,1.2,-1,1,-1.5,1.5",
                   "--threads", "2", "--surface", vtp])
    if vti not in p.stdout or vtp not in p.stdout:
        sys.exit(f"FAIL: the output paths are not printed:\n{p.stdout}")
    image = read_image(vti)
    if image.GetDimensions() != (21, 17, 13):
        sys.exit(f"FAIL: dimensions {image.GetDimensions()}")
    bounds = image.GetBounds()
    for got, want in zip(bounds, (-1.2, 1.2, -1, 1, -1.5, 1.5)):
        near(got, want, 1e-12, "bounds")
    f = image.GetPointData().GetArray("f")
    if f is None or f.GetDataType() != 10:  # VTK_FLOAT
        sys.exit("FAIL: no float array 'f'")
    for i in (0, 7, 1234, image.GetNumberOfPoints() // 2, image.GetNumberOfPoints() - 1):
        x, y, z = image.GetPoint(i)
        near(f.GetValue(i), 1 - x * x - y * y - z * z, 1e-6, f"f at point {i}")
    surface = read_polydata(vtp)
    if surface.GetNumberOfPolys() < 100:
        sys.exit(f"FAIL: surface has {surface.GetNumberOfPolys()} triangles")
    normals = surface.GetPointData().GetNormals()
    for i in range(0, surface.GetNumberOfPoints(), 17):
        x, y, z = surface.GetPoint(i)
        near(math.sqrt(x * x + y * y + z * z), 1.0, 0.05, "surface point radius")
        n = normals.GetTuple3(i)
        if n[0] * x + n[1] * y + n[2] * z < 0.9:
            sys.exit(f"FAIL: normal {n} at {(x, y, z)} does not point outwards")
    # --double writes double arrays.
    run(ictk, ["sample", "sphere", "-o", vti, "--resolution", "8", "--double"])
    if read_image(vti).GetPointData().GetArray("f").GetDataType() != 11:  # VTK_DOUBLE
        sys.exit("FAIL: --double did not write doubles")
    no_leftovers(work)


def check_sample_band(ictk, work):
    # `ictk sample -o x.vdb` (voxel::sampleNarrowBand): the sphere model f = 1 - r^2 with band 0.1
    # keeps the points with 0.9 <= r^2 <= 1.1, a shell of volume 4/3 pi (1.1^1.5 - 0.9^1.5).
    vdb = os.path.join(work, "band.vdb")
    p = run(ictk, ["sample", "sphere", "-o", vdb, "--bounds", "-1.2,1.2,-1.2,1.2,-1.2,1.2",
                   "--resolution", "97", "--band", "0.1", "--threads", "2"])
    m = re.search(r"narrow band \|f\| <= 0.1 of 97 x 97 x 97 points: (\d+) active voxels", p.stdout)
    if not m:
        sys.exit(f"FAIL: no active voxel count in:\n{p.stdout}")
    h = 2.4 / 96
    shell = 4 / 3 * math.pi * (1.1 ** 1.5 - 0.9 ** 1.5) / h ** 3
    near(int(m.group(1)) / shell, 1.0, 0.03, "active voxels over the shell's volume in voxels")
    with open(vdb, "rb") as f:
        if f.read(4) != b" BDV":  # OpenVDB's magic number, little-endian
            sys.exit("FAIL: the .vdb does not start with OpenVDB's magic number")
    no_leftovers(work)
    # A point of Scripts/scale-plots: one JSON line.
    point = json.loads(run(ictk, ["bench", "--scale-point", "sample-band=32"]).stdout)
    for key in ("cpu_seconds", "peak_rss_bytes", "active_voxels", "grid_bytes"):
        if not point.get(key, 0) > 0:
            sys.exit(f"FAIL: --scale-point sample-band=32: {key} missing or not positive: {point}")


def check_scale_plots(ictk, work, script):
    # Scripts/scale-plots --quick: every kind measured twice, the CSV and the four plots written.
    run_command = [script, "--ictk", ictk, "--out", work, "--quick"]
    p = subprocess.run(run_command, capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        sys.exit(f"FAIL: {run_command} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    with open(os.path.join(work, "scale.csv")) as f:
        rows = list(csv.DictReader(f))
    kinds = sorted({r["kind"] for r in rows})
    if len(rows) != 14 or kinds != ["contour", "frames", "frames-full", "primitives", "sample-band",
                                    "sample-dense", "tets"]:
        sys.exit(f"FAIL: scale.csv rows {len(rows)}, kinds {kinds}")
    for r in rows:
        if not (float(r["cpu_seconds"]) > 0 and float(r["peak_rss_mib"]) > 1):
            sys.exit(f"FAIL: scale.csv row without CPU time or memory: {r}")
    for name in ("resolution", "primitives", "tets", "frames"):
        path = os.path.join(work, f"scale-{name}.png")
        if not os.path.isfile(path) or os.path.getsize(path) < 10000:
            sys.exit(f"FAIL: {path} missing or too small")


def check_sample_walnut(ictk, work):
    vti = os.path.join(work, "walnut.vti")
    run(ictk, ["sample", "walnut", "-o", vti, "--resolution", "24"])
    image = read_image(vti)
    if image.GetDimensions() != (24, 24, 24):
        sys.exit(f"FAIL: dimensions {image.GetDimensions()}")
    pd = image.GetPointData()
    components = {pd.GetArrayName(i): pd.GetArray(i).GetNumberOfComponents() for i in range(pd.GetNumberOfArrays())}
    if components != {"f": 1, "material": 1, "density": 1, "colour": 3}:
        sys.exit(f"FAIL: arrays {components}")
    material = set(pd.GetArray("material").GetValue(i) for i in range(image.GetNumberOfPoints()))
    if not {-1.0, 1.0, 2.0} <= material:
        sys.exit(f"FAIL: material values {material}")
    # The corner is outside: material -1, colour 0.
    if pd.GetArray("material").GetValue(0) != -1.0 or pd.GetArray("colour").GetTuple3(0) != (0, 0, 0):
        sys.exit("FAIL: outside defaults at the corner")
    # Surface attributes are taken from inside the solid: the shell's and the kernel's boundaries
    # carry materials 1 and 2 only, never the outside default -1 nor a blend of both sides.
    vtp = os.path.join(work, "walnut.vtp")
    run(ictk, ["sample", "walnut", "-o", vti, "--resolution", "48", "--surface", vtp])
    surface = read_polydata(vtp)
    material = surface.GetPointData().GetArray("material")
    if material is None or surface.GetPointData().GetArray("colour").GetNumberOfComponents() != 3:
        sys.exit("FAIL: surface attribute arrays missing")
    values = {material.GetValue(i) for i in range(surface.GetNumberOfPoints())}
    if values != {1.0, 2.0}:
        sys.exit(f"FAIL: surface material values {values}, expected {{1, 2}}")
    no_leftovers(work)


def check_sample_disk2d(ictk, work):
    vti = os.path.join(work, "disk.vti")
    run(ictk, ["sample", "disk2d", "-o", vti, "--resolution", "9"])
    image = read_image(vti)
    if image.GetDimensions() != (9, 9, 1):
        sys.exit(f"FAIL: a 2D model gives {image.GetDimensions()}, not (9, 9, 1)")


def check_render(ictk, work):
    """ictk render writes a PNG of the size asked, with the model in it; the depth buffer as
    .vti; an empty view gives the background and a warning."""
    import vtk
    png, vti = os.path.join(work, "walnut.png"), os.path.join(work, "walnut.vti")
    p = run(ictk, ["render", "walnut", "-o", png, "--size", "64,48", "--threads", "2", "--depth", vti])
    if png not in p.stdout or vti not in p.stdout:
        sys.exit(f"FAIL: the output paths are not printed:\n{p.stdout}")
    r = vtk.vtkPNGReader()
    r.SetFileName(png)
    r.Update()
    image = r.GetOutput()
    if image.GetDimensions() != (64, 48, 1) or image.GetNumberOfScalarComponents() != 4:
        sys.exit(f"FAIL: {image.GetDimensions()} with {image.GetNumberOfScalarComponents()} components")
    scalars = image.GetPointData().GetScalars()
    covered = [i for i in range(image.GetNumberOfPoints()) if scalars.GetComponent(i, 3) == 255]
    if not 300 <= len(covered) < 64 * 48:
        sys.exit(f"FAIL: {len(covered)} opaque pixels")
    # The walnut's shell colour (0.55, 0.36, 0.2), shaded: red is the largest channel.
    i = covered[len(covered) // 2]
    rgb = [scalars.GetComponent(i, c) for c in range(3)]
    if not rgb[0] > rgb[1] > rgb[2] > 0:
        sys.exit(f"FAIL: pixel {i} is {rgb}, not the walnut's brown")
    if scalars.GetComponent(0, 3) != 0:
        sys.exit("FAIL: the corner is not background")
    depth = read_image(vti)
    d = depth.GetPointData().GetArray("depth")
    if depth.GetDimensions() != (64, 48, 1) or d is None:
        sys.exit("FAIL: the depth buffer")
    for k in range(depth.GetNumberOfPoints()):
        if (scalars.GetComponent(k, 3) == 255) != math.isfinite(d.GetValue(k)):
            sys.exit(f"FAIL: pixel {k}: colour and depth disagree on coverage")
    # The eye is 2.5 half-diagonals of the walnut's box from its centre: its surface lies
    # between 1.5 and 3.5 half-diagonals away, and what is seen mostly on the near side.
    finite = [d.GetValue(k) for k in covered]
    b = [m for m in json.loads(run(ictk, ["models", "--json"]).stdout) if m["name"] == "walnut"][0]["bounds"]
    h = 0.5 * math.sqrt(sum((b[2 * a + 1] - b[2 * a]) ** 2 for a in range(3)))
    finite.sort()
    if not (1.5 * h < finite[0] and finite[-1] < 3.5 * h and finite[len(finite) * 9 // 10] < 2.5 * h):
        sys.exit(f"FAIL: depths {min(finite)}..{max(finite)}")
    # A camera inside the solid: a picture of the cut, with a warning.
    p = run(ictk, ["render", "sphere", "-o", os.path.join(work, "inside.png"), "--size", "8,8", "--view", "0,0,0.1"])
    if "ictk: warning: 64 pixel(s) see 'sphere' cut open" not in p.stderr:
        sys.exit(f"FAIL: no warning for a camera inside the solid:\n{p.stderr}")
    # Nothing in view: an empty model's picture is all background, with a warning.
    empty = os.path.join(work, "empty.hf")
    with open(empty, "w") as f:
        f.write("empty(x[3], a[1])\n{\n  empty = -1 - x[1] * x[1];\n}\n")
    out = os.path.join(work, "empty.png")
    p = run(ictk, ["render", empty, "-o", out, "--size", "8,8", "--projection", "orthographic"])
    if "ictk: warning: no surface" not in p.stderr or not os.path.exists(out):
        sys.exit(f"FAIL: no warning or no picture for an empty view:\n{p.stderr}")
    r.SetFileName(out)
    r.Update()
    alpha = r.GetOutput().GetPointData().GetScalars()
    if any(alpha.GetComponent(k, 3) != 0 for k in range(64)):
        sys.exit("FAIL: the empty picture is not background")
    # A model with a surface, but a camera that looks away from it: the same honest empty picture.
    away = os.path.join(work, "away.json")
    with open(away, "w") as f:
        f.write('{"position": [0, 5, 0], "focal_point": [0, 10, 0]}')
    out = os.path.join(work, "away.png")
    p = run(ictk, ["render", "sphere", "-o", out, "--size", "8,8", "--camera", away])
    if "ictk: warning: no surface of 'sphere' is in view" not in p.stderr or \
            "0 pixels covered" not in p.stdout or not os.path.exists(out):
        sys.exit(f"FAIL: no warning or no picture for a camera looking away:\n{p.stderr}")
    no_leftovers(work)


def check_error(ictk, work, pattern, args):
    args = [a.replace("@WORK@", work) for a in args if a != ""]
    p = run(ictk, args, check=False)
    if p.returncode != 2:
        sys.exit(f"FAIL: ictk {' '.join(args)} exited {p.returncode}, not 2\nstderr:\n{p.stderr}")
    lines = [l for l in p.stderr.splitlines() if l.strip()]
    if len(lines) != 1 or not lines[0].startswith("ictk: error: "):
        sys.exit(f"FAIL: expected one 'ictk: error:' line, got:\n{p.stderr}")
    if not re.search(pattern, lines[0]):
        sys.exit(f"FAIL: {lines[0]!r} does not match {pattern!r}")
    # Every error test writes to @WORK@/x.<ext> (or the folder x): none of them may exist.
    written = [f for f in os.listdir(work) if f == "x" or f.startswith("x.")] if os.path.isdir(work) else []
    if written:
        sys.exit(f"FAIL: output written despite the error: {written}")
    no_leftovers(work)


def check_mesh_formats(ictk, work):
    """ictk mesh writes the same surface in every format; each file is read back by VTK's own
    reader for that format and measured: the unit sphere's area is 4 pi within 1 %."""
    import vtk
    counts = {}
    readers = {"vtp": vtk.vtkXMLPolyDataReader, "stl": vtk.vtkSTLReader, "ply": vtk.vtkPLYReader,
               "obj": vtk.vtkOBJReader}
    for ext, reader_class in readers.items():
        path = os.path.join(work, "sphere." + ext)
        p = run(ictk, ["mesh", "sphere", "-o", path, "--resolution", "80"])
        if path not in p.stdout:
            sys.exit(f"FAIL: mesh did not print {path}:\n{p.stdout}")
        reader = reader_class()
        reader.SetFileName(path)
        triangles = vtk.vtkTriangleFilter()
        triangles.SetInputConnection(reader.GetOutputPort())
        mass = vtk.vtkMassProperties()
        mass.SetInputConnection(triangles.GetOutputPort())
        mass.Update()
        counts[ext] = triangles.GetOutput().GetNumberOfPolys()
        near(mass.GetSurfaceArea(), 4 * math.pi, 0.01 * 4 * math.pi, f"area of the .{ext} sphere")
        near(mass.GetVolume(), 4 / 3 * math.pi, 0.01 * 4 / 3 * math.pi, f"volume of the .{ext} sphere")
    if len(set(counts.values())) != 1 or counts["vtp"] < 1000:
        sys.exit(f"FAIL: triangle counts differ between formats: {counts}")
    # The .vtp carries the attributes, evaluated on the surface.
    path = os.path.join(work, "walnut.vtp")
    run(ictk, ["mesh", "walnut", "-o", path, "--resolution", "40"])
    material = read_polydata(path).GetPointData().GetArray("material")
    if material is None:
        sys.exit("FAIL: no material on the walnut surface")
    no_leftovers(work)


def check_model_files(ictk, work):
    """Model files (.hf, .xml) everywhere a model name goes; convert between them; a malformed
    file gives file:line:col diagnostics with a caret and exit code 2."""
    data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Data", "Models")
    sphere = os.path.join(data, "sphere.hf")
    # sphere.hf: 4 - (x - 1)^2 - y^2 - z^2.
    p = run(ictk, ["eval", sphere, "--at", "0,0,0", "--json"])
    out = json.loads(p.stdout)
    near(out["value"], 3.0, 1e-15, "value of sphere.hf at the origin")
    near(out["gradient"][0], 2.0, 1e-15, "d/dx of sphere.hf at the origin")
    # .hf -> .xml -> .hf: the same values.
    xml, hf = os.path.join(work, "bracket.xml"), os.path.join(work, "bracket.hf")
    run(ictk, ["convert", os.path.join(data, "bracket.hf"), xml])
    run(ictk, ["convert", xml, hf])
    for point in ("0.7,0,0", "0.5,0,1", "0,0,0", "1.3,-0.2,0.4"):
        values = [float(run(ictk, ["eval", path, "--at", point]).stdout)
                  for path in (os.path.join(data, "bracket.hf"), xml, hf)]
        if len(set(values)) != 1:
            sys.exit(f"FAIL: values at {point} differ across .hf/.xml/.hf: {values}")
    # A registered model exported as HyperFun reads back to the same field.
    walnut = os.path.join(work, "walnut.hf")
    run(ictk, ["convert", "walnut", walnut])
    for point in ("0.9,0,0", "0.2,0.3,-0.1"):
        a = float(run(ictk, ["eval", "walnut", "--at", point]).stdout)
        b = float(run(ictk, ["eval", walnut, "--at", point]).stdout)
        if a != b:
            sys.exit(f"FAIL: walnut {a} != walnut.hf {b} at {point}")
    # Meshing a file: bounds found by interval arithmetic; the ball of radius 2 has area 16 pi.
    stl = os.path.join(work, "sphere.stl")
    run(ictk, ["mesh", sphere, "-o", stl, "--resolution", "80"])
    import vtk
    reader = vtk.vtkSTLReader()
    reader.SetFileName(stl)
    mass = vtk.vtkMassProperties()
    mass.SetInputConnection(reader.GetOutputPort())
    mass.Update()
    near(mass.GetSurfaceArea(), 16 * math.pi, 0.01 * 16 * math.pi, "area of sphere.hf")
    # Diagnostics.
    bad = os.path.join(work, "bad.hf")
    with open(bad, "w") as f:
        f.write("m(x[3], a[1])\n{\n  m = 1 + ;\n  q = 2 *;\n}\n")
    p = run(ictk, ["eval", bad, "--at", "0,0,0"], check=False)
    if p.returncode != 2:
        sys.exit(f"FAIL: a malformed file exited {p.returncode}")
    lines = p.stderr.splitlines()
    if not lines or not re.match(re.escape(bad) + r":3:11: error: ", lines[0]) or lines[2] != " " * 10 + "^":
        sys.exit(f"FAIL: diagnostics:\n{p.stderr}")
    if not any(re.match(re.escape(bad) + r":4:10: error: ", l) for l in lines):
        sys.exit(f"FAIL: the second error is not reported:\n{p.stderr}")
    # A parameter where the library needs a number: specialised to --params.
    ring = os.path.join(data, "parametric_ring.hf")
    near(float(run(ictk, ["eval", ring, "--at", "0.8,0,0", "--params", "0.8,0.3"]).stdout), 0.09, 1e-15,
         "parametric_ring at (0.8, 0, 0)")
    p = run(ictk, ["eval", ring, "--at", "0.8,0,0"], check=False)
    if p.returncode != 2 or "give their values" not in p.stderr:
        sys.exit(f"FAIL: parametric_ring without --params:\n{p.stderr}")
    missing = os.path.join(work, "no-such.hf")
    p = run(ictk, ["eval", missing, "--at", "0,0,0"], check=False)
    if p.returncode != 2 or not p.stderr.startswith(missing + ": error: cannot open"):
        sys.exit(f"FAIL: a missing file: exit {p.returncode}\n{p.stderr}")
    no_leftovers(work)


def check_complex_flower(ictk, work, data):
    """The seed 001 flower: info, validate and mesh into .vtpc and .vtm, read back by VTK."""
    model = os.path.join(data, "Models", "flower", "flower.json")
    info = json.loads(run(ictk, ["info", model, "--json"]).stdout)
    if info["cells_per_dimension"] != [4, 3, 2, 3]:
        sys.exit(f"FAIL: cells per dimension {info['cells_per_dimension']}")
    if len(info["relations"]["boundary"]) != 17 or info["relations"]["containment"]:
        sys.exit(f"FAIL: relations {info['relations']}")
    report = json.loads(run(ictk, ["validate", model, "--json", "--feature-size", "0.03"]).stdout)
    if not report["ok"] or report["violated"] or len(report["satisfied"]) != 17:
        sys.exit(f"FAIL: validation {report}")
    vtpc = os.path.join(work, "flower.vtpc")
    run(ictk, ["mesh", model, "-o", vtpc, "--feature-size", "0.03"])
    import vtk
    r = vtk.vtkXMLPartitionedDataSetCollectionReader()
    r.SetFileName(vtpc)
    r.Update()
    pdc = r.GetOutput()
    if pdc.GetNumberOfPartitionedDataSets() != 12:
        sys.exit(f"FAIL: {pdc.GetNumberOfPartitionedDataSets()} partitioned datasets, not 12")
    names = set()
    for i in range(12):
        leaf = pdc.GetPartitionedDataSet(i).GetPartition(0)
        names.add(leaf.GetFieldData().GetAbstractArray("CellName").GetValue(0))
        if leaf.GetNumberOfPoints() == 0 or not leaf.GetPointData().GetArray("colour"):
            sys.exit(f"FAIL: partition {i} is empty or has no colour")
    if "t_1^2" not in names:
        sys.exit(f"FAIL: cell names {names}")
    assembly = pdc.GetDataAssembly()
    boundary = assembly.GetFirstNodeByPath("/flower/relations/boundary")
    if boundary < 0 or assembly.GetNumberOfChildren(boundary) != 8:
        sys.exit("FAIL: the assembly lacks /flower/relations/boundary with the 8 cells that have a boundary")
    # Another name than flower.vtpc's: both would keep their pieces in the folder 'flower'.
    vtm = os.path.join(work, "blocks.vtm")
    # --size is the edge length in every command; --feature-size its older spelling.
    run(ictk, ["mesh", model, "-o", vtm, "--size", "0.03"])
    m = vtk.vtkXMLMultiBlockDataReader()
    m.SetFileName(vtm)
    m.Update()
    blocks = m.GetOutput()
    counts = [blocks.GetBlock(p).GetNumberOfBlocks() for p in range(4)]
    if counts != [4, 3, 2, 3]:
        sys.exit(f"FAIL: .vtm blocks per dimension {counts}")
    # Writing again replaces the pieces; a same-named folder holding other files is left alone.
    run(ictk, ["mesh", model, "-o", vtpc, "--feature-size", "0.03"])
    mine = os.path.join(work, "mine")
    os.makedirs(mine)
    with open(os.path.join(mine, "notes.txt"), "w") as f:
        f.write("keep me")
    p = run(ictk, ["mesh", model, "-o", os.path.join(work, "mine.vtpc"), "--feature-size", "0.03"], check=False)
    if p.returncode != 2 or "holds other files" not in p.stderr or not os.path.exists(os.path.join(mine, "notes.txt")):
        sys.exit(f"FAIL: a folder of the user's was not protected: exit {p.returncode}, {p.stderr!r}")
    if os.path.exists(os.path.join(work, "mine.vtpc")):
        sys.exit("FAIL: mine.vtpc was written although its pieces could not be")
    # A bad relation: exit 2, a diagnostic with file, line and column, nothing written.
    bad = os.path.join(work, "bad.json")
    with open(bad, "w") as f:
        f.write('{"cells": [{"name": "p", "kind": "P", "dimension": 0, "points": [[0, 0, 0]]}],\n'
                ' "relations": {"boundary": [["p", "q"]]}}\n')
    p = run(ictk, ["mesh", bad, "-o", os.path.join(work, "bad.vtpc")], check=False)
    if p.returncode != 2 or not re.search(r"bad\.json:2:\d+: error: .*no cell named 'q'", p.stderr):
        sys.exit(f"FAIL: bad relation: exit {p.returncode}, stderr {p.stderr!r}")
    if os.path.exists(os.path.join(work, "bad.vtpc")):
        sys.exit("FAIL: an output was written for a bad complex")


def check_bench(ictk, work):
    # `ictk bench --quick`: small sizes, one run. Only the report's shape is checked, not timings.
    p = run(ictk, ["bench", "--json", "--quick", "--only", "csg3"])
    results = json.loads(p.stdout)
    if not isinstance(results, list) or len(results) != 1:
        sys.exit(f"FAIL: expected one workload, got {p.stdout}")
    r = results[0]
    for key in ("workload", "seconds", "threads", "throughput", "vtk_seconds", "ratio_vs_vtk"):
        if key not in r:
            sys.exit(f"FAIL: key {key!r} missing from {r}")
    if r["workload"] != "csg3-64" or not r["seconds"] > 0 or not r["vtk_seconds"] > 0:
        sys.exit(f"FAIL: bad values in {r}")
    near(r["ratio_vs_vtk"], r["vtk_seconds"] / r["seconds"], 1e-9 * r["ratio_vs_vtk"], "ratio_vs_vtk")
    if r["details"]["shape_check_agree"] != r["details"]["shape_check_points"]:
        sys.exit(f"FAIL: ICTK and VTK csg3 disagree: {r['details']}")
    # The plain report names the workload; an --only that matches nothing is a user error.
    if "csg3-64:" not in run(ictk, ["bench", "--quick", "--only", "csg3"]).stdout:
        sys.exit("FAIL: plain report")
    # The narrow band beside dense sampling of the same grid (issue 20): memory and counts.
    r = json.loads(run(ictk, ["bench", "--json", "--quick", "--only", "vdb-band-64"]).stdout)
    if [w["workload"] for w in r] != ["vdb-band-64"]:
        sys.exit(f"FAIL: vdb-band workloads: {r}")
    d = r[0]["details"]
    if not (0 < d["active_voxels"] < 64 ** 3 and d["grid_bytes"] > 0 and d["dense_cpu_seconds"] > 0
            and d["dense_float_bytes"] == 4 * 64 ** 3):
        sys.exit(f"FAIL: vdb-band-64 details: {d}")
    # The dynamic workload (issue 7): the coherent run and the full re-meshing mesh the same
    # frames (as many points), the coherent one reusing cells.
    d = {r["workload"]: r for r in json.loads(run(ictk, ["bench", "--json", "--quick", "--only", "andyhausen"]).stdout)}
    if sorted(d) != ["andyhausen-10", "andyhausen-10-full"]:
        sys.exit(f"FAIL: andyhausen workloads: {sorted(d)}")
    coherent, full = d["andyhausen-10"]["details"], d["andyhausen-10-full"]["details"]
    if coherent["frames"] != 11 or full["frames"] != 11 or coherent["points"] != full["points"]:
        sys.exit(f"FAIL: andyhausen frames/points: {coherent} vs {full}")
    if not (coherent["cells_reused"] > 0 and full["cells_reused"] == 0 and coherent["coherence_speedup"] > 0):
        sys.exit(f"FAIL: andyhausen coherence counters: {coherent} vs {full}")
    # The ray-casting workload (issue 14): its counters, not its time.
    g = json.loads(run(ictk, ["bench", "--json", "--quick", "--only", "render-sphere-gyroid"]).stdout)
    if [r["workload"] for r in g] != ["render-sphere-gyroid-128"]:
        sys.exit(f"FAIL: render workloads: {g}")
    details = g[0]["details"]
    if not (details["covered_pixels"] > 1000 and details["interval_evaluations_per_pixel"] > 0):
        sys.exit(f"FAIL: render-sphere-gyroid details: {details}")
    p = run(ictk, ["bench", "--only", "nothing-like-this"], check=False)
    if p.returncode != 2 or "ictk: error: --only" not in p.stderr:
        sys.exit(f"FAIL: --only without a match: exit {p.returncode}\n{p.stderr}")


# A stand-in for libfive's l5bench (../shared/bench/peers/libfive): the same command line and JSON
# lines, with times known in advance. Round k of a command reports BASE[command] * (1, 3, 2)[k % 3]
# seconds, so three rounds have the median 2 * BASE.
FAKE_L5BENCH = """#!/usr/bin/python3
import json, os, sys
BASE = {"brute": 0.5, "pruned": 0.125, "signonly": 0.0625, "gyroid": 2.0, "heightmap": 0.25}
cmd = sys.argv[1]
if os.environ.get("FAKE_L5BENCH_FAIL") == cmd:
    sys.exit(3)
state = os.path.join(os.path.dirname(os.path.abspath(__file__)), cmd + ".calls")
calls = int(open(state).read()) if os.path.exists(state) else 0
open(state, "w").write(str(calls + 1))
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "args.log"), "a") as log:
    log.write(" ".join(sys.argv[1:]) + "\\n")
s = BASE[cmd] * (1, 3, 2)[calls % 3]
print("libfive banner, not JSON")
print(json.dumps({"workload": cmd, "seconds": s, "cpu_seconds": s / 2, "all_seconds": [s]}))
if cmd == "gyroid":
    print(json.dumps({"workload": "mesh", "triangles": 20000, "vertices": 10000}))
elif cmd == "heightmap":  # N^2 float32 depths: empty everywhere, or z = 4.9 everywhere
    import struct
    n = int(sys.argv[4])
    if len(sys.argv) > 5:
        z = 4.9 if os.environ.get("FAKE_HEIGHTMAP_TOP") else float("-inf")
        open(sys.argv[5], "wb").write(struct.pack("<f", z) * (n * n))
    print(json.dumps({"covered_pixels": 0, "voxels": [n, n, n]}))
else:
    print(json.dumps({"inside_pixels": 1234}))
"""


def check_bench_peer(ictk, work):
    # `ictk bench --peer-libfive` (BenchPeer.h) against the stand-in above: what it reports for
    # libfive's side is the median of the stand-in's rounds, each ratio the quotient of the two
    # sides' medians, and the matched sphereGyroid side meshes within 10 % of libfive's triangles.
    fake = os.path.join(work, "l5bench")
    with open(fake, "w") as f:
        f.write(FAKE_L5BENCH)
    os.chmod(fake, 0o755)
    models = os.path.join(work, "models")
    os.makedirs(models)
    with open(os.path.join(models, "prospero.vm"), "w") as f:  # a disc of radius 0.5, Fidget's SSA
        f.write("_0 var-x\n_1 var-y\n_2 square _0\n_3 square _1\n_4 add _2 _3\n_5 sqrt _4\n"
                "_6 const 0.5\n_7 sub _5 _6\n")
    d = json.loads(run(ictk, ["bench", "--quick", "--json", "--rounds", "3", "--models", models,
                              "--peer-libfive", fake]).stdout)
    if d["rounds"] != 3 or d["peer_libfive"] != fake:
        sys.exit(f"FAIL: peer header: {d}")
    cases = {c["workload"]: c for c in d["cases"]}
    if sorted(cases) != ["csg3-64", "prospero-brute-128", "prospero-pruned-128",
                         "render-sphere-gyroid-128", "sphere-gyroid-0.1"]:
        sys.exit(f"FAIL: peer workloads: {sorted(cases)}")
    base = {"ArrayEvaluator": 0.5, "Heightmap (with normals)": 0.125,
            "Heightmap's recursion, no normals": 0.0625, "Mesh::render, min_feature 0.025": 2.0,
            "Heightmap::render (with normals), 128^3 voxels": 0.25}
    for c in d["cases"]:
        sides = {s["tool"] + " " + s["label"]: s for s in c["sides"]}
        for s in c["sides"]:
            if len(s["round_seconds"]) != 3:
                sys.exit(f"FAIL: {c['workload']} {s['label']}: not 3 rounds: {s}")
            near(s["seconds"], sorted(s["round_seconds"])[1], 0, f"{s['label']}: median of rounds")
            if s["tool"] == "libfive":
                b = base[s["label"]]
                if sorted(s["round_seconds"]) != [b, 2 * b, 3 * b]:
                    sys.exit(f"FAIL: {s['label']}: rounds {s['round_seconds']}")
                near(s["seconds"], 2 * b, 0, f"{s['label']} median")
                near(s["cpu_seconds"], b, 0, f"{s['label']} CPU median")
        for r in c["ratios"]:
            ictk_side = sides["ICTK " + r["ictk"]]
            peer = sides[r["peer"]]
            near(r["ratio"], peer["seconds"] / ictk_side["seconds"], 1e-12 * r["ratio"],
                 f"{c['workload']} ratio {r['peer']} / {r['ictk']}")
            for k in range(3):
                near(r["round_ratios"][k], peer["round_seconds"][k] / ictk_side["round_seconds"][k],
                     1e-12 * r["round_ratios"][k], "round ratio")
        if c["workload"].startswith("prospero"):
            ictk_inside = [s["details"]["inside_pixels"] for s in c["sides"] if s["tool"] == "ICTK"]
            # The disc of radius 0.5 covers pi / 16 of [-1, 1]^2: 3217 of 128^2 pixels, about.
            if not ictk_inside or any(abs(n - math.pi / 16 * 128 * 128) > 100 for n in ictk_inside):
                sys.exit(f"FAIL: {c['workload']}: ICTK inside pixels {ictk_inside}")
            libfive = [s for s in c["sides"] if s["tool"] == "libfive"]
            if any(s["details"].get("inside_pixels") != 1234 for s in libfive):
                sys.exit(f"FAIL: {c['workload']}: libfive details {libfive}")
    g = {s["label"]: s for s in cases["sphere-gyroid-0.1"]["sides"]}
    matched = g["dual contouring, libfive's triangle count"]["details"]
    plain = g["dual contouring, feature size 0.1"]["details"]
    if not abs(matched["triangles"] / 20000 - 1) <= 0.1 or plain["feature_size"] != 0.1:
        sys.exit(f"FAIL: matched sphereGyroid: {matched} (plain {plain})")
    near(matched["triangles_over_libfive"], matched["triangles"] / 20000, 1e-12, "triangles_over_libfive")
    if not 0 < matched["mean_distance_over_feature"] <= matched["max_distance_over_feature"] < 1:
        sys.exit(f"FAIL: sphereGyroid distances: {matched}")
    goals = [r for r in cases["sphere-gyroid-0.1"]["ratios"] if "goal_ratio" in r]
    if [(r["ictk"], r["goal_ratio"]) for r in goals] != [("dual contouring, libfive's triangle count", 12)]:
        sys.exit(f"FAIL: sphereGyroid goal: {goals}")
    # The ray caster against an empty heightmap: every pixel it covers disagrees, none is
    # libfive's alone; the goal is 3x.
    r = cases["render-sphere-gyroid-128"]
    ours, theirs = (next(s for s in r["sides"] if s["tool"] == t) for t in ("ICTK", "libfive"))
    covered = ours["details"]["covered_pixels"]
    # The sphere of radius 3 covers 9 pi / 100 of the square, less the gyroid's channels.
    if not 0.2 * 128 * 128 < covered < 9 * math.pi / 100 * 128 * 128 or \
            not ours["details"]["interval_evaluations_per_pixel"] > 0:
        sys.exit(f"FAIL: render-sphere-gyroid-128 ICTK details: {ours['details']}")
    t = theirs["details"]
    if (t["both_covered_pixels"], t["covered_by_ictk_only"], t["covered_by_libfive_only"],
            t["silhouette_disagreeing_pixels"]) != (0, covered, 0, covered) or \
            not 0 <= t["disagreeing_thinner_than_a_voxel"] <= covered or \
            t["disagreeing_unexplained"] != covered - t["disagreeing_thinner_than_a_voxel"]:
        sys.exit(f"FAIL: render-sphere-gyroid-128 comparison with an empty heightmap: {t}")
    near(t["mpixels_per_second"], 128 * 128 / 0.25 / 1e6, 1e-9, "libfive Mpixels/s")
    if [x["goal_ratio"] for x in r["ratios"]] != [3]:
        sys.exit(f"FAIL: render-sphere-gyroid-128 goal: {r['ratios']}")
    # A heightmap at z = 4.9 everywhere: every pixel covered by both where the ray caster covers
    # it, more than a voxel (10/128) above its surface (the sphere has radius 3).
    env = dict(os.environ, FAKE_HEIGHTMAP_TOP="1")
    p = subprocess.run([ictk, "bench", "--quick", "--json", "--rounds", "1", "--only",
                        "render-sphere-gyroid", "--peer-libfive", fake], capture_output=True,
                       text=True, timeout=100, env=env)
    t = json.loads(p.stdout)["cases"][0]["sides"][1]["details"]
    if (t["both_covered_pixels"], t["covered_by_libfive_only"], t["depth_beyond_a_voxel_pixels"],
            t["disagreeing_thinner_than_a_voxel"]) != (covered, 128 * 128 - covered, covered, 0):
        sys.exit(f"FAIL: render-sphere-gyroid-128 against a heightmap at z = 4.9: {t}")
    csg3 = cases["csg3-64"]
    if [s["tool"] for s in csg3["sides"]] != ["ICTK", "VTK"] or csg3["ratios"][0]["goal_ratio"] != 15:
        sys.exit(f"FAIL: csg3 sides: {csg3}")
    # l5bench was asked for the sizes of --quick and the rounds' runs, with the model given.
    calls = open(os.path.join(work, "args.log")).read().split("\n")
    model = os.path.join(models, "prospero.vm")
    for want in (f"brute {model} 1 128", f"pruned {model} 2 1 128", f"signonly {model} 2 1 128", "gyroid 2 1"):
        if calls.count(want) != 3:
            sys.exit(f"FAIL: l5bench calls: {want!r} {calls.count(want)} times in {calls}")
    # The heightmap: probed once per run (8^3), then 1 run per round into a depth file.
    heightmaps = [c for c in calls if c.startswith("heightmap 2 1 128 ")]
    if calls.count("heightmap 1 1 8") != 2 or len(heightmaps) != 4:
        sys.exit(f"FAIL: l5bench heightmap calls: {calls}")
    # The Markdown tables of the plain report.
    out = run(ictk, ["bench", "--quick", "--rounds", "1", "--only", "pruned", "--models", models,
                     "--peer-libfive", fake]).stdout
    if "| prospero-pruned-128 | 2 | libfive | Heightmap (with normals) | 125 ms |" not in out \
            or "Ratios (peer time / ICTK time" not in out:
        sys.exit(f"FAIL: plain peer report:\n{out}")
    # A peer that fails, and one that is not there, are errors that name it.
    env = dict(os.environ, FAKE_L5BENCH_FAIL="brute")
    p = subprocess.run([ictk, "bench", "--quick", "--only", "brute", "--models", models,
                        "--peer-libfive", fake], capture_output=True, text=True, timeout=100, env=env)
    if p.returncode != 2 or f"'{fake} brute {model} 1 128' failed (exit status 3)" not in p.stderr:
        sys.exit(f"FAIL: failing peer: exit {p.returncode}\n{p.stderr}")
    p = run(ictk, ["bench", "--quick", "--peer-libfive", os.path.join(work, "nope")], check=False)
    if p.returncode != 2 or "is not an executable file" not in p.stderr:
        sys.exit(f"FAIL: missing peer: exit {p.returncode}\n{p.stderr}")


def check_bench_scaling(ictk, work):
    # `ictk bench --scaling --quick` (BenchScaling.cxx): the tables' shape and the counters, not
    # the timings.
    d = json.loads(run(ictk, ["bench", "--scaling", "--quick", "--json"]).stdout)
    for key in ("models", "size_sampling", "size_render2d", "size_contour", "resolution_sampling",
                "resolution_occupancy3d", "resolution_render2d", "resolution_contour"):
        if not isinstance(d.get(key), list) or len(d[key]) != 2:
            sys.exit(f"FAIL: {key} should list 2 rows: {d.get(key)}")
    if [m["tape_instructions"] for m in d["models"]] != [99, 1016]:
        sys.exit(f"FAIL: randomCsgRecipe(6 / 62) tape sizes: {d['models']}")
    for row in d["resolution_sampling"]:
        if not 0 < row["pruned_instruction_evaluations"] <= row["full_instruction_evaluations"]:
            sys.exit(f"FAIL: pruned sampling counters: {row}")
    if "| r | voxels (r^3) |" not in run(ictk, ["bench", "--scaling", "--quick"]).stdout:
        sys.exit("FAIL: plain scaling report")


def check_tetra_bar(ictk, work, data):
    """ictk tetra on the two-material bar: labelled .vtu read back by VTK, .inp read by meshio,
    and a CalculiX solve of the .inp whose tip displacement matches springs in series."""
    model = os.path.join(data, "Models", "bar", "two_material_bar.json")
    vtu = os.path.join(work, "bar.vtu")
    report = json.loads(run(ictk, ["tetra", model, "-o", vtu, "--backend", "tetgen", "--size", "0.05", "--json"]).stdout)
    if [m["name"] for m in report["materials"]] != ["steel", "alu"]:
        sys.exit(f"FAIL: materials {report['materials']}")
    for m in report["materials"]:
        near(m["mesh_volume"], 0.04, 1e-9, f"mesh volume of {m['name']}")
    import vtk
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(vtu)
    r.Update()
    grid = r.GetOutput()
    if grid.GetNumberOfCells() != report["tetrahedra"]:
        sys.exit("FAIL: .vtu tetrahedron count differs from the report")
    material = grid.GetCellData().GetArray("MaterialId")
    modulus = grid.GetCellData().GetArray("youngs_modulus")
    volume = {1: 0.0, 2: 0.0}
    for c in range(grid.GetNumberOfCells()):
        ids = grid.GetCell(c).GetPointIds()
        p = [grid.GetPoint(ids.GetId(k)) for k in range(4)]
        e = [[p[k][i] - p[0][i] for i in range(3)] for k in (1, 2, 3)]
        v = (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0])
             + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6
        m = int(material.GetTuple1(c))
        volume[m] += v
        expected = 210000 if m == 1 else 70000
        if modulus.GetTuple1(c) != expected:
            sys.exit(f"FAIL: tetrahedron {c} of material {m} has modulus {modulus.GetTuple1(c)}")
        xs = [q[0] for q in p]
        if (m == 1 and max(xs) > 1 + 1e-9) or (m == 2 and min(xs) < 1 - 1e-9):
            sys.exit(f"FAIL: tetrahedron {c} of material {m} straddles x = 1")
    near(volume[1], 0.04, 1e-9, "VTK volume of steel")
    near(volume[2], 0.04, 1e-9, "VTK volume of alu")

    inp = os.path.join(work, "bar.inp")
    run(ictk, ["tetra", model, "-o", inp, "--backend", "tetgen", "--size", "0.05", "--deterministic"])
    # Scripts/setup installs meshio and ccx: without them the install is broken, not the test.
    try:
        import meshio
    except ImportError as e:
        sys.exit(f"FAIL: {e}: install python3-meshio (Scripts/setup)")
    if not shutil.which("ccx"):
        sys.exit("FAIL: ccx not found: install calculix-ccx (Scripts/setup)")
    mesh = meshio.read(inp)
    if sum(len(b.data) for b in mesh.cells if b.type == "tetra") != report["tetrahedra"]:
        sys.exit("FAIL: meshio reads another tetrahedron count")
    for version in ("2.2", "4.1"):
        msh = os.path.join(work, f"bar-{version}.msh")
        run(ictk, ["tetra", model, "-o", msh, "--backend", "tetgen", "--size", "0.05", "--deterministic",
                   "--msh-version", version])
        m = meshio.read(msh)
        tags = set()
        for block, data in zip(m.cells, m.cell_data.get("gmsh:physical", [])):
            if block.type == "tetra":
                tags.update(int(t) for t in data)
        if tags != {1, 2}:
            sys.exit(f"FAIL: Gmsh {version} physical groups {tags}, not {{1, 2}}")
    # Issue 21: the deck of every built backend, in both modes, solved by CalculiX.
    for backend in ("tetgen", "cgal"):
        for mode in ([], ["--deterministic"]):
            inp = os.path.join(work, f"bar-{backend}.inp")
            p = subprocess.run([ictk, "tetra", model, "-o", inp, "--backend", backend, "--size", "0.05"] + mode,
                               capture_output=True, text=True, timeout=300)
            if p.returncode != 0 and "was not built" in p.stderr:
                print(f"the {backend} backend is not built")
                break
            if p.returncode != 0:
                sys.exit(f"FAIL: ictk tetra --backend {backend} {mode}: {p.stderr}")
            solve_bar(inp, work, f"{backend} {' '.join(mode) or 'default'}")


def solve_bar(inp, work, what):
    """The bar of `inp` pulled by F = 100 at x = 2, held at x = 0 (free to contract), solved by
    ccx: the tip moves as springs in series, within 1 % with nu = 0.3."""
    # The deck: the mesh (nodes, elements, materials, sections) plus supports and a pull of
    # F = 100 as a face pressure on x = 2 (platform.md: minimal supports, *DLOAD on faces).
    nodes, elements, section = {}, [], None
    for line in open(inp):
        t = line.strip()
        if t.startswith("*"):
            section = t.split(",")[0].upper()
            continue
        if not t or t.startswith("**"):
            continue
        f = [v.strip() for v in t.split(",")]
        if section == "*NODE":
            nodes[int(f[0])] = tuple(float(v) for v in f[1:4])
        elif section == "*ELEMENT":
            elements.append([int(v) for v in f[:5]])
    at = lambda x: [n for n, p in nodes.items() if abs(p[0] - x) < 1e-9]
    nearest = lambda q: min(nodes, key=lambda n: sum((nodes[n][i] - q[i]) ** 2 for i in range(3)))
    faces = {"S1": (1, 2, 3), "S2": (1, 4, 2), "S3": (2, 4, 3), "S4": (3, 4, 1)}
    tip = set(at(2.0))
    loaded = [(e[0], s) for e in elements for s, f in faces.items() if all(e[k] in tip for k in f)]
    deck = os.path.join(work, "solve.inp")
    with open(deck, "w") as out:
        out.write(open(inp).read())
        out.write("*NSET, NSET=FIXX\n" + "\n".join(str(n) for n in at(0.0)) + "\n")
        out.write("*NSET, NSET=TIP\n" + "\n".join(str(n) for n in sorted(tip)) + "\n")
        out.write("*SURFACE, NAME=PULL, TYPE=ELEMENT\n" + "\n".join(f"{e}, {s}" for e, s in loaded) + "\n")
        out.write(f"*BOUNDARY\nFIXX, 1, 1\n{nearest((0, 0, 0))}, 2, 3\n{nearest((0, 0.2, 0))}, 3, 3\n")
        out.write("*STEP\n*STATIC\n*DSLOAD\nPULL, P, -2500.0\n*NODE PRINT, NSET=TIP\nU\n*END STEP\n")
    p = subprocess.run(["ccx", "solve"], cwd=work, capture_output=True, text=True, timeout=100)
    if "Job finished" not in p.stdout or "*ERROR" in p.stdout + p.stderr:
        sys.exit(f"FAIL: ccx did not finish cleanly:\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    ux = []
    for line in open(os.path.join(work, "solve.dat")):
        f = line.split()
        if len(f) == 4 and f[0].isdigit():
            ux.append(float(f[1]))
    if not ux:
        sys.exit("FAIL: no displacements in solve.dat")
    # Springs in series: u = F L1 / (E1 A) + F L2 / (E2 A), F = 100, A = 0.04, L1 = L2 = 1.
    expected = 100 / (210000 * 0.04) + 100 / (70000 * 0.04)
    mean = sum(ux) / len(ux)
    print(f"{what}: CalculiX tip displacement {mean:.6e}, springs in series {expected:.6e}, "
          f"difference {100 * (mean - expected) / expected:+.2f}%")
    near(mean, expected, 0.01 * expected, f"tip displacement ({what})")


def check_solve_bar(ictk, work, data):
    """ictk solve on the bar's .vtu (E 210000 | 70000 side by side along x, nu 0.3) compressed by
    d = 0.001 along z (H = 0.2): iso-strain, so the apparent modulus is the Voigt bound 140000 and
    each block carries sigma_zz = -E d / H; the top platen's nodes move by -d."""
    model = os.path.join(data, "Models", "bar", "two_material_bar.json")
    mesh = os.path.join(work, "bar.vtu")
    run(ictk, ["tetra", model, "-o", mesh, "--backend", "tetgen", "--size", "0.05"])
    out = os.path.join(work, "solved.vtu")
    # Scripts/setup installs ccx: without it the install is broken, not the test.
    if not shutil.which("ccx"):
        sys.exit("FAIL: ccx not found: install calculix-ccx (Scripts/setup)")
    report = json.loads(run(ictk, ["solve", mesh, "--compression", "0.001", "-o", out, "--json"]).stdout)
    near(report["voigt_modulus"], 140000, 1e-6, "Voigt bound")
    near(report["reuss_modulus"], 1 / (0.5 / 210000 + 0.5 / 70000), 1e-6, "Reuss bound")
    near(report["apparent_modulus"], 140000, 1e-4 * 140000, "apparent modulus")
    near(report["force"], 140000 * 0.4 * 0.001 / 0.2, 1e-2, "platen force")
    if report["materials"] != 2:
        sys.exit(f"FAIL: {report['materials']} deck materials, not 2")
    for f in ("compression.inp", "compression.frd", "compression.dat", "compression.log"):
        if not os.path.exists(os.path.join(work, "solved-ccx", f)):
            sys.exit(f"FAIL: solved-ccx/{f} missing")
    import vtk
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(out)
    r.Update()
    grid = r.GetOutput()
    pd, cd = grid.GetPointData(), grid.GetCellData()
    for name, components in (("displacement", 3), ("stress", 6), ("von_mises", 1), ("reaction_force", 3)):
        a = pd.GetArray(name)
        if a is None or a.GetNumberOfComponents() != components:
            sys.exit(f"FAIL: point array {name} ({components} components) missing")
    for name in ("MaterialId", "youngs_modulus", "deck_youngs_modulus", "deck_material"):
        if cd.GetArray(name) is None:
            sys.exit(f"FAIL: cell array {name} missing")
    u, s, vm = pd.GetArray("displacement"), pd.GetArray("stress"), pd.GetArray("von_mises")
    top = 0
    for i in range(grid.GetNumberOfPoints()):
        x, _, z = grid.GetPoint(i)
        if abs(z - 0.2) < 1e-9:
            near(u.GetComponent(i, 2), -0.001, 1e-9, f"u_z of top node {i}")
            top += 1
        # Away from the interface each block is in uniaxial stress E d / H.
        if x < 0.9 or x > 1.1:
            e = 210000 if x < 1 else 70000
            near(s.GetComponent(i, 2), -e * 0.001 / 0.2, 1e-3 * e * 0.005, f"sigma_zz at node {i}")
            near(vm.GetTuple1(i), e * 0.001 / 0.2, 1e-3 * e * 0.005, f"von Mises at node {i}")
    if top < 10:
        sys.exit(f"FAIL: {top} nodes on the top platen")
    print(f"ictk solve bar: {grid.GetNumberOfCells()} tetrahedra, apparent modulus "
          f"{report['apparent_modulus']:.2f} (Voigt 140000), ccx {report['ccx_seconds']:.3f} s")
    # A solver that is not there: a clear error, no output.
    p = run(ictk, ["solve", mesh, "--compression", "0.001", "-o", os.path.join(work, "none.vtu"),
                   "--ccx", "ictk-no-such-ccx"], check=False)
    if p.returncode != 2 or "'ictk-no-such-ccx' was not found" not in p.stderr or "calculix-ccx" not in p.stderr:
        sys.exit(f"FAIL: missing ccx: exit {p.returncode}, {p.stderr}")
    if os.path.exists(os.path.join(work, "none.vtu")):
        sys.exit("FAIL: none.vtu written without a solver")


def read_frame(path):
    """A .vtpc frame of `ictk run`: {cell name: (leaf, instance)}."""
    import vtk
    r = vtk.vtkXMLPartitionedDataSetCollectionReader()
    r.SetFileName(path)
    r.Update()
    pdc = r.GetOutput()
    cells = {}
    for i in range(pdc.GetNumberOfPartitionedDataSets()):
        leaf = pdc.GetPartitionedDataSet(i).GetPartition(0)
        fd = leaf.GetFieldData()
        name = fd.GetAbstractArray("CellName").GetValue(0)
        cells[name] = (leaf, fd.GetAbstractArray("Instance").GetValue(0))
    return cells


def pvd_frames(pvd, count, dt):
    """The <DataSet>s of a .pvd written by ictk run, checked: `count` of them at 0, dt, 2 dt, ..."""
    import xml.etree.ElementTree as ET
    datasets = ET.parse(pvd).getroot().findall("./Collection/DataSet")
    if len(datasets) != count:
        sys.exit(f"FAIL: {len(datasets)} datasets in the .pvd, not {count}")
    for k, d in enumerate(datasets):
        near(float(d.get("timestep")), dt * k, 1e-12, f"time of dataset {k}")
    return datasets


def check_run_disk(ictk, work, data):
    """ictk run on thesis 5.1 (ch5_1_disk_rectangle.icm): the disk's centre is at x = -2 + t and
    touches the rectangle (left side x = 2) at t = 3: K1 before, K2 at the tangency, K3 after."""
    model = os.path.join(data, "Models", "icm", "ch5_1_disk_rectangle.icm")
    pvd = os.path.join(work, "disk.pvd")
    trace = os.path.join(work, "disk.jsonl")
    args = ["run", model, "--frames", "0:6:0.5", "-o", pvd, "--trace", trace, "--feature-size", "0.1"]
    summary = json.loads(run(ictk, args + ["--json"]).stdout)
    if summary["frames"] != 13 or summary["final_instance"] != "K3":
        sys.exit(f"FAIL: summary {summary}")
    if [t["to"] for t in summary["transitions"]] != ["K2", "K3"]:
        sys.exit(f"FAIL: transitions {summary['transitions']}")
    near(summary["transitions"][0]["time"], 3.0, 1e-6, "time of the tangency")
    coherence = summary["coherence"]
    if coherence["moved"] + coherence["reused"] == 0:
        sys.exit(f"FAIL: nothing reused across frames: {coherence}")

    datasets = pvd_frames(pvd, 13, 0.5)
    for d in datasets:
        if not os.path.isfile(os.path.join(work, d.get("file"))):
            sys.exit(f"FAIL: {d.get('file')} listed but not written")
    # t = 1 (K1: the rectangle and the disk) and t = 5 (K3: 7 cells), read back by VTK.
    for k, instance, count in ((2, "K1", 2), (10, "K3", 7)):
        cells = read_frame(os.path.join(work, datasets[k].get("file")))
        if len(cells) != count or {i for _, i in cells.values()} != {instance}:
            sys.exit(f"FAIL: frame {k}: {sorted(cells)} {[i for _, i in cells.values()]}")
        b = cells["LHKF"][0].GetBounds()
        t = 0.5 * k
        near(0.5 * (b[0] + b[1]), -2 + t, 0.01, f"disk centre at t = {t}")
        near(b[1] - b[0], 2.0, 0.02, f"disk diameter at t = {t}")

    with open(trace) as f:
        records = [json.loads(line) for line in f if line.strip()]
    if len(records) != summary["records"] or not all("state" in r and "events" in r for r in records):
        sys.exit(f"FAIL: trace records {len(records)} vs summary {summary['records']}")
    # Every frame is an evaluated time (the first one is also the choice of the initial instance).
    for t in [0.5 * k for k in range(13)]:
        if not any(abs(r["time"] - t) < 1e-12 for r in records):
            sys.exit(f"FAIL: no trace record of the frame t = {t}")
    for r in records:
        if r["time"] < 3 - 1e-6 and r["instance"] != "K1":
            sys.exit(f"FAIL: {r} before the tangency")
        if r["time"] > 3 + 1e-6 and r["instance"] != "K3":
            sys.exit(f"FAIL: {r} after the tangency")
    # K2 holds only at the tangency: its records (the located transition, and the frame t = 3
    # if the engine evaluates it there) are all at t = 3.
    tangent = [i for i, r in enumerate(records) if r["instance"] == "K2"]
    if not tangent or not any(records[i]["transition"] for i in tangent):
        sys.exit(f"FAIL: no transition record to K2: {records}")
    if any(abs(records[i]["time"] - 3) > 1e-6 for i in tangent) or tangent != list(range(tangent[0], tangent[-1] + 1)):
        sys.exit(f"FAIL: K2 away from t = 3: {[records[i] for i in tangent]}")
    if records[tangent[0]]["state"].get("isIntersection") is not True:
        sys.exit(f"FAIL: K2's state {records[tangent[0]]['state']}")
    later = [r["instance"] for r in records[tangent[-1] + 1:]]
    if not later or later[0] != "K3" or set(later) != {"K3"}:
        sys.exit(f"FAIL: after K2: {later}")

    # A second run replaces the first (frames folder included); without coherence every cell is
    # meshed in every frame, to the same frames.
    full = json.loads(run(ictk, args + ["--json", "--no-coherence"]).stdout)
    c = full["coherence"]
    if c["moved"] + c["reused"] != 0 or c["computed"] != coherence["computed"] + coherence["moved"] + coherence["reused"]:
        sys.exit(f"FAIL: --no-coherence {c} vs {coherence}")
    b_full = read_frame(os.path.join(work, datasets[10].get("file")))["LHKF"][0].GetBounds()
    near(0.5 * (b_full[0] + b_full[1]), 3.0, 0.01, "disk centre without coherence")
    if sorted(os.listdir(work)) != ["disk", "disk.jsonl", "disk.pvd"]:
        sys.exit(f"FAIL: files left in the work folder: {sorted(os.listdir(work))}")
    text = run(ictk, args).stdout
    if "13 frames" not in text or "2 transitions" not in text:
        sys.exit(f"FAIL: summary text:\n{text}")


def check_run_default(ictk, work, data):
    """ictk run without --frames runs the model's time range (the union of its time spans) in
    100 steps: Andyhausen's film : TIMESPAN(0, 20) is 101 frames 0, 0.2, ..., 20, through its
    three instances (issue 16: it stopped at t = 10.346875). A model without a finite time span
    asks for --frames."""
    model = os.path.join(data, "Models", "icm", "andyhausen.icm")
    pvd = os.path.join(work, "andy.pvd")
    summary = json.loads(run(ictk, ["run", model, "-o", pvd, "--json"]).stdout)
    if summary["frames"] != 101 or summary["t0"] != 0 or summary["t1"] != 20:
        sys.exit(f"FAIL: default frames {summary}")
    near(summary["max_step"], 0.2, 1e-12, "default engine step")
    if [t["to"] for t in summary["transitions"]] != ["EGG_ERODING", "ANDY_OUT"]:
        sys.exit(f"FAIL: transitions {summary['transitions']}")
    near(summary["transitions"][0]["time"], 3.0, 1e-6, "egg touches the liquid")
    near(summary["transitions"][1]["time"], 6.346875, 1e-5, "egg under the surface")
    if summary["final_instance"] != "ANDY_OUT":
        sys.exit(f"FAIL: final instance {summary['final_instance']}")
    datasets = pvd_frames(pvd, 101, 0.2)
    last = read_frame(os.path.join(work, datasets[-1].get("file")))
    if "Skeleton" not in last or {i for _, i in last.values()} != {"ANDY_OUT"}:
        sys.exit(f"FAIL: the frame t = 20: {sorted(last)}")

    forever = os.path.join(work, "forever.icm")
    with open(forever, "w") as f:
        f.write("name = FOREVER;\nTIMESPANS { always : TIMESPAN; }\n"
                "CELLS { A { type = F-CELL; shape = disk(1); dim = 2D; } }\nK { CELLS { A; } }\n")
    p = run(ictk, ["run", forever, "-o", os.path.join(work, "x.pvd")], check=False)
    if p.returncode != 2 or "give --frames T0:T1:DT" not in p.stderr:
        sys.exit(f"FAIL: no finite time span: exit {p.returncode}, stderr:\n{p.stderr}")


def check_run_standin(ictk, work, data):
    """ictk run on Appendix B's stand-in model (standin.icm): assimp-testmodels' BCN_Epileptic
    carried out of the liquid box; ANDY_WITHIN_BOX switches to ANDY_OUT_OF_BOX once, at the time
    the engine test finds (2.6468 s), and every frame holds the character (3,938 vertices: the
    file's 3,613 and a copy per extra fan at its 266 split corners), its stand-in and the blend."""
    import subprocess
    if not os.path.isfile("/usr/share/assimp/models/X/BCN_Epileptic.X"):
        print("SKIP: assimp-testmodels is not installed")
        return
    model = os.path.join(data, "Models", "icm", "standin.icm")
    pvd = os.path.join(work, "standin.pvd")
    args = ["run", model, "--frames", "0:4:2", "--size", "0.15", "-o", pvd, "--json"]
    # Slower than run()'s limit under load: the distance queries on a 51-segment stand-in.
    p = subprocess.run([ictk] + args, capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        sys.exit(f"FAIL: ictk {' '.join(args)} exited {p.returncode}\n{p.stderr}")
    summary = json.loads(p.stdout)
    if summary["frames"] != 3 or summary["final_instance"] != "ANDY_OUT_OF_BOX":
        sys.exit(f"FAIL: summary {summary}")
    if [t["to"] for t in summary["transitions"]] != ["ANDY_OUT_OF_BOX"]:
        sys.exit(f"FAIL: transitions {summary['transitions']}")
    near(summary["transitions"][0]["time"], 2.6468, 2e-3, "time the character leaves the box")
    datasets = pvd_frames(pvd, 3, 2.0)
    for k, instance in ((0, "ANDY_WITHIN_BOX"), (2, "ANDY_OUT_OF_BOX")):
        cells = read_frame(os.path.join(work, datasets[k].get("file")))
        if set(cells) != {"Box", "Skeleton", "Andy", "Liquid_Andy", "Liquid_on_Andy"}:
            sys.exit(f"FAIL: frame {k} cells {sorted(cells)}")
        if {i for _, i in cells.values()} != {instance}:
            sys.exit(f"FAIL: frame {k} instances {[i for _, i in cells.values()]}")
        andy = cells["Andy"][0]
        if andy.GetNumberOfPoints() != 3938 or andy.GetNumberOfCells() != 5126:
            sys.exit(f"FAIL: frame {k}: Andy has {andy.GetNumberOfPoints()} points, "
                     f"{andy.GetNumberOfCells()} triangles")
        for name in ("Liquid_Andy", "Liquid_on_Andy"):
            if cells[name][0].GetNumberOfPoints() == 0:
                sys.exit(f"FAIL: frame {k}: {name} is empty")
        # The character is carried along +x at 0.5 a second from -0.3.
        b = andy.GetBounds()
        if not (b[0] < -0.3 + k + 0.1 < b[1]):
            sys.exit(f"FAIL: frame {k}: Andy's x range {b[0]}..{b[1]}")


def check_run_characters(ictk, work, data):
    """ictk run on thesis 5.5 between two characters of assimp-testmodels (metamorphosis_characters
    .icm): the humanoid BCN_Epileptic becomes the quadruped Testwuson. The instances come in order,
    K2 -> K3 switches when every vertex of the humanoid is within 1e-6 of its stand-in and every
    normal within a degree (before alpha reaches 1 at t = 1.5), and the frames hold the humanoid
    (3,938 vertices) in K1 and K2, only F-cells in K3 and the quadruped (5,020 vertices: the file's
    and the copies at its split corners) in K4 and K5."""
    import subprocess
    for f in ("BCN_Epileptic.X", "Testwuson.X"):
        if not os.path.isfile("/usr/share/assimp/models/X/" + f):
            print("SKIP: assimp-testmodels is not installed")
            return
    model = os.path.join(data, "Models", "icm", "metamorphosis_characters.icm")
    pvd, trace = os.path.join(work, "characters.pvd"), os.path.join(work, "characters.jsonl")
    args = ["run", model, "--frames", "0:6:0.6", "--size", "0.4", "-o", pvd, "--json",
            "--trace", trace, "--threads", "2"]
    p = subprocess.run([ictk] + args, capture_output=True, text=True, timeout=900)
    if p.returncode != 0:
        sys.exit(f"FAIL: ictk {' '.join(args)} exited {p.returncode}\n{p.stderr}")
    summary = json.loads(p.stdout)
    moves = [(t["to"], t["time"]) for t in summary["transitions"]]
    if [m for m, _ in moves] != ["K2", "K3", "K4", "K5"]:
        sys.exit(f"FAIL: transitions {moves}")
    near(moves[0][1], 1, 1e-6, "K1 -> K2")
    if not 1.4 < moves[1][1] <= 1.5:
        sys.exit(f"FAIL: K2 -> K3 at {moves[1][1]}, not as alpha nears 1 (t = 1.5)")
    near(moves[2][1], 4, 1e-6, "K3 -> K4")
    near(moves[3][1], 5, 1e-6, "K4 -> K5")
    states = [json.loads(line)["state"] for line in open(trace)]
    residual, angle = states[-1]["residualAtSwitch"], states[-1]["angleAtSwitch"]
    if not (0 <= residual < 1e-6 and 0 <= angle < 1):
        sys.exit(f"FAIL: at the switch the residual is {residual}, the angle {angle} degrees")
    datasets = pvd_frames(pvd, 11, 0.6)
    for k, instance, cell, points in ((0, "K1", "Source", 3938), (2, "K2", "Source", 3938),
                                      (4, "K3", None, 0), (7, "K4", "Target", 5020),
                                      (10, "K5", "Target", 5020)):
        cells = read_frame(os.path.join(work, datasets[k].get("file")))
        if {i for _, i in cells.values()} != {instance}:
            sys.exit(f"FAIL: frame {k} instances {[i for _, i in cells.values()]}")
        if cell is None:
            if set(cells) != {"Morph"} or cells["Morph"][0].GetNumberOfPoints() == 0:
                sys.exit(f"FAIL: frame {k} (K3) holds {sorted(cells)}")
        elif cells[cell][0].GetNumberOfPoints() != points:
            sys.exit(f"FAIL: frame {k}: {cell} has {cells[cell][0].GetNumberOfPoints()} points")
    print(f"K2 -> K3 at t = {moves[1][1]}: residual {residual}, angle {angle} degrees")


def check_run_space_time(ictk, work):
    """A 4D cell through ictk run: a sphere of radius 0.5 + 0.5 t (hyperfun x[4]), whose frames
    at t = 0, 0.5, 1 are its cross-sections: spheres of diameter 1, 1.5 and 2 (issue 16: every
    frame was the t = 0 sphere)."""
    import vtk
    model = os.path.join(work, "growing.icm")
    with open(model, "w") as f:
        f.write("""name = GROWING;
TIMESPANS { film : TIMESPAN(0, 1); }
CELLS {
  Ball {
    type = F-CELL;
    shape = hyperfun { ball(x[4], a[1]) { ball = (0.5 + 0.5 * x[4])^2 - x[1]^2 - x[2]^2 - x[3]^2; } }
    dim = 4D;
    domain = { -1.2, -1.2, -1.2, 1.2, 1.2, 1.2 };
  }
}
K { CELLS { Ball; } }
""")
    pvd = os.path.join(work, "growing.pvd")
    run(ictk, ["run", model, "--frames", "0:1:0.5", "--size", "0.03", "-o", pvd])
    datasets = pvd_frames(pvd, 3, 0.5)
    for d in datasets:
        t = float(d.get("timestep"))
        r = 0.5 + 0.5 * t
        leaf = read_frame(os.path.join(work, d.get("file")))["Ball"][0]
        b = leaf.GetBounds()
        for axis in range(3):
            near(b[2 * axis + 1] - b[2 * axis], 2 * r, 0.03, f"diameter along axis {axis} at t = {t}")
        mass = vtk.vtkMassProperties()
        tri = vtk.vtkTriangleFilter()
        tri.SetInputData(leaf)
        mass.SetInputConnection(tri.GetOutputPort())
        mass.Update()
        near(mass.GetSurfaceArea(), 4 * math.pi * r * r, 0.02 * 4 * math.pi * r * r, f"area at t = {t}")
        near(mass.GetVolume(), 4 / 3 * math.pi * r ** 3, 0.02 * 4 / 3 * math.pi * r ** 3, f"volume at t = {t}")


def check_sample_frames(ictk, work, data):
    """An XYZT model sampled as a whole (issue 16): --frames writes one .vti a time, each the
    field with t bound to that frame's time, f = (0.5 + t)^2 - (x - t)^2 - y^2 - z^2 for
    Data/Models/growing_ball.hf; a model without time and a .vti output are refused."""
    model = os.path.join(data, "Models", "growing_ball.hf")
    pvd = os.path.join(work, "ball.pvd")
    run(ictk, ["sample", model, "--frames", "0:1:0.25", "--dims", "21,9,9",
               "--bounds", "-1,2,-1,1,-1,1", "-o", pvd])
    datasets = pvd_frames(pvd, 5, 0.25)
    for d in datasets:
        t = float(d.get("timestep"))
        image = read_image(os.path.join(work, d.get("file")))
        if image.GetDimensions() != (21, 9, 9):
            sys.exit(f"FAIL: frame at t = {t} has dimensions {image.GetDimensions()}")
        f = image.GetPointData().GetArray("f")
        for i in range(0, image.GetNumberOfPoints(), 37):
            x, y, z = image.GetPoint(i)
            want = (0.5 + t) ** 2 - (x - t) ** 2 - y * y - z * z
            near(f.GetValue(i), want, 1e-5, f"f at point {i}, t = {t}")
    p = run(ictk, ["sample", "sphere", "--frames", "0:1:0.5", "-o", pvd], check=False)
    if p.returncode != 2 or "does not depend on time" not in p.stderr:
        sys.exit(f"FAIL: a model without time: exit {p.returncode}, stderr:\n{p.stderr}")
    p = run(ictk, ["sample", model, "--frames", "0:1:0.5", "-o", os.path.join(work, "x.vti")],
            check=False)
    if p.returncode != 2 or "is a .pvd series" not in p.stderr:
        sys.exit(f"FAIL: --frames into a .vti: exit {p.returncode}, stderr:\n{p.stderr}")
    no_leftovers(work)


def slice_components(inside, nx, ny):
    """The 4-connected components of the True cells of an nx x ny slice (row-major, x fastest)."""
    seen = [False] * (nx * ny)
    count = 0
    for start in range(nx * ny):
        if not inside[start] or seen[start]:
            continue
        count += 1
        seen[start] = True
        stack = [start]
        while stack:
            p = stack.pop()
            i, j = p % nx, p // nx
            for q, ok in ((p - 1, i > 0), (p + 1, i < nx - 1), (p - nx, j > 0), (p + nx, j < ny - 1)):
                if ok and inside[q] and not seen[q]:
                    seen[q] = True
                    stack.append(q)
    return count


def check_sample_icm(ictk, work, data):
    """A .icm model sampled (issue 16): thesis fig. 93's cross into two disks
    (Data/Models/icm/ch5_3_space_time_blend.icm, MORPH = spaceTimeBlendCells(CROSS, DISKS, 1, 2,
    ...)). At --time 0.5 the cell MORPH is the cross in sign, at 2.5 the two disks; --space-time
    writes its XYT volume, z = t, whose slices before t0 = 1 and after t1 = 2 equal the operands in
    sign and have 1 and 2 components; bad options and a bad model exit 2 with their message."""
    model = os.path.join(data, "Models", "icm", "ch5_3_space_time_blend.icm")

    def cross(x, y):
        return max(min(1 - abs(x), 0.25 - abs(y)), min(0.25 - abs(x), 1 - abs(y)))

    def disks(x, y):
        return max(0.16 - (x + 0.7) ** 2 - y * y, 0.16 - (x - 0.7) ** 2 - y * y)

    def same_sign(values, operand, t, what):
        """values[i] at the slice's points against the operand; points within 0.02 of the
        operand's boundary (the sampled field is not the operand's) are skipped."""
        compared = 0
        for (x, y), v in values:
            w = operand(x, y)
            if abs(w) < 0.02:
                continue
            compared += 1
            if (v > 0) != (w > 0):
                sys.exit(f"FAIL: {what} at t = {t}: f({x:.3f}, {y:.3f}) = {v}, the operand {w}")
        if compared < 1000:
            sys.exit(f"FAIL: {what} at t = {t}: only {compared} points compared")

    # One time: the cell's cross-section there, array MORPH and the union f (the only cell).
    for t, operand in ((0.5, cross), (2.5, disks)):
        out = os.path.join(work, f"at{t}.vti")
        p = run(ictk, ["sample", model, "--time", str(t), "--dims", "61,61,1",
                       "--bounds", "-1.5,1.5,-1.5,1.5,0,0", "-o", out])
        if "instance K" not in p.stdout or "arrays: f, MORPH" not in p.stdout:
            sys.exit(f"FAIL: summary: {p.stdout}")
        image = read_image(out)
        if image.GetDimensions() != (61, 61, 1):
            sys.exit(f"FAIL: dimensions {image.GetDimensions()}")
        morph = image.GetPointData().GetArray("MORPH")
        f = image.GetPointData().GetArray("f")
        values = []
        for i in range(image.GetNumberOfPoints()):
            x, y, _ = image.GetPoint(i)
            if f.GetValue(i) != morph.GetValue(i):
                sys.exit(f"FAIL: f != MORPH at point {i}")
            values.append(((x, y), morph.GetValue(i)))
        same_sign(values, operand, t, "--time")
        near(image.GetFieldData().GetArray("Time").GetValue(0), t, 0, "the Time field data")

    # --frames: the same at every time, a .pvd series of .vti frames on one grid.
    pvd = os.path.join(work, "frames.pvd")
    run(ictk, ["sample", model, "--frames", "0:3:1.5", "--dims", "61,61,1",
               "--bounds", "-1.5,1.5,-1.5,1.5,0,0", "-o", pvd])
    for d, operand in zip(pvd_frames(pvd, 3, 1.5), (cross, None, disks)):
        t = float(d.get("timestep"))
        image = read_image(os.path.join(work, d.get("file")))
        if image.GetDimensions() != (61, 61, 1):
            sys.exit(f"FAIL: frame at t = {t}: dimensions {image.GetDimensions()}")
        near(image.GetFieldData().GetArray("Time").GetValue(0), t, 0, "a frame's Time")
        morph = image.GetPointData().GetArray("MORPH")
        if operand:
            same_sign([((image.GetPoint(i)[0], image.GetPoint(i)[1]), morph.GetValue(i))
                       for i in range(image.GetNumberOfPoints())], operand, t, "--frames")

    # Without --bounds: the cell's box at t, one layer (a 2D cell lies in z = 0).
    out = os.path.join(work, "box.vti")
    run(ictk, ["sample", model, "--time", "1.5", "--resolution", "16", "-o", out])
    if read_image(out).GetDimensions() != (16, 16, 1):
        sys.exit(f"FAIL: a 2D cell's grid: {read_image(out).GetDimensions()}")

    # The space-time volume: 61 x 61 points, 31 times 0, 0.1, ..., 3.
    out = os.path.join(work, "morph.vti")
    p = run(ictk, ["sample", model, "--space-time", "--cell", "MORPH", "--dims", "61,61,31",
                   "--bounds", "-1.5,1.5,-1.5,1.5,0,3", "-o", out])
    image = read_image(out)
    if image.GetDimensions() != (61, 61, 31):
        sys.exit(f"FAIL: space-time dimensions {image.GetDimensions()}")
    near(image.GetSpacing()[2], 0.1, 1e-12, "the time spacing")
    f = image.GetPointData().GetArray("f")
    layer = 61 * 61
    components = []
    for k in range(31):
        t = image.GetPoint(k * layer)[2]
        near(t, 0.1 * k, 1e-9, f"z of slice {k}")
        values = [((image.GetPoint(k * layer + i)[0], image.GetPoint(k * layer + i)[1]),
                   f.GetValue(k * layer + i)) for i in range(layer)]
        if t <= 1 + 1e-9:
            same_sign(values, cross, t, "--space-time before t0")
        if t >= 2 - 1e-9:
            same_sign(values, disks, t, "--space-time after t1")
        components.append(slice_components([v > 0 for _, v in values], 61, 61))
    if components[0] != 1 or components[-1] != 2 or any(c != 1 for c in components[:11]) \
            or any(c != 2 for c in components[20:]):
        sys.exit(f"FAIL: components per slice {components}")
    # The model's only space-time 2D cell is the default; its time range (0, 3) the default z.
    out2 = os.path.join(work, "default.vti")
    p = run(ictk, ["sample", model, "--space-time", "--resolution", "16", "-o", out2])
    if "the space-time of MORPH, z = t from 0 to 3" not in p.stdout:
        sys.exit(f"FAIL: default space-time summary: {p.stdout}")

    def refused(args, pattern):
        p = run(ictk, ["sample", model] + args, check=False)
        if p.returncode != 2 or not re.search(pattern, p.stderr):
            sys.exit(f"FAIL: {args}: exit {p.returncode}, stderr:\n{p.stderr}")

    x = os.path.join(work, "x.vti")
    refused(["--cell", "NOPE", "-o", x], r"--cell: no cell 'NOPE' in the instance K at t = 0 \(its cells: MORPH\)")
    refused(["--surface", os.path.join(work, "x.vtp"), "-o", x], r"--surface is not for a dynamic model")
    refused(["--frames", "0:1:0.5", "-o", x], r"-o: with --frames the output is a .pvd series")
    refused(["--frames=-1:1:0.5", "-o", os.path.join(work, "x.pvd")],
            r"--frames: T0 = -1 is before the model's start \(0\)")
    refused(["--space-time", "--time", "1", "-o", x], r"--time is one cross-section")
    refused(["--time", "-1", "-o", x], r"--time: t = -1 is before the model's start \(0\)")
    refused(["-o", os.path.join(work, "x.vdb")], r"-o: a .icm model is sampled into a .vti image")
    p = run(ictk, ["sample", "sphere", "--cell", "A", "-o", x], check=False)
    if p.returncode != 2 or "--cell is for a dynamic model (.icm)" not in p.stderr:
        sys.exit(f"FAIL: --cell on a registered model: exit {p.returncode}, stderr:\n{p.stderr}")
    # A 3D cell has a 4D space-time.
    ball = os.path.join(work, "ball.icm")
    with open(ball, "w") as fh:
        fh.write("""name = BALL;
TIMESPANS { film : TIMESPAN(0, 1); }
CELLS { B { type = F-CELL; shape = sphere(0.5); dim = 3D; } }
K { CELLS { B; } }
""")
    p = run(ictk, ["sample", ball, "--space-time", "--cell", "B", "-o", x], check=False)
    if p.returncode != 2 or "its space-time is 4D" not in p.stderr:
        sys.exit(f"FAIL: a 3D cell's space-time: exit {p.returncode}, stderr:\n{p.stderr}")
    # A bad blend scale, at its place.
    bad = os.path.join(work, "bad.icm")
    with open(bad, "w") as fh:
        fh.write("""name = BAD;
TIMESPANS { film : TIMESPAN(0, 1); }
CELLS {
  A { type = F-CELL; shape = disk(1); dim = 2D; }
  B { type = F-CELL; shape = disk(0.5); dim = 2D; parameters { translation(1.5, 0, 0); } }
  C { type = T-CELL; shape = blend(A, B, 0.5, 1, 0); dim = 2D; }
}
K { CELLS { A; B; C; } }
""")
    p = run(ictk, ["sample", bad, "-o", x], check=False)
    if p.returncode != 2 or "bad.icm:6:50: error: the blend scale a2 must be positive" not in p.stderr:
        sys.exit(f"FAIL: a bad blend scale: exit {p.returncode}, stderr:\n{p.stderr}")
    no_leftovers(work)


def check_run_errors(ictk, work, data):
    """ictk run on bad input: exit 2, a clear message, and nothing written or lost."""
    model = os.path.join(data, "Models", "icm", "ch5_1_disk_rectangle.icm")
    broken = os.path.join(work, "broken.icm")
    with open(broken, "w") as f:
        f.write("name = BROKEN;\nCELLS {\n  A { type = F-CELL; shape = ; }\n}\n")
    keep = os.path.join(work, "keep.pvd")
    with open(keep, "w") as f:
        f.write("the user's file")
    os.makedirs(os.path.join(work, "keep"))
    with open(os.path.join(work, "keep", "keep_0000.vtpc"), "w") as f:
        f.write("an earlier frame")
    p = run(ictk, ["run", broken, "--frames", "0:1:0.5", "-o", keep], check=False)
    if p.returncode != 2 or not re.match(re.escape(broken) + r":3:\d+: error: ", p.stderr):
        sys.exit(f"FAIL: malformed model: exit {p.returncode}, stderr:\n{p.stderr}")
    # T0 before the model's start (its TIMESPAN starts at 0), given in the older spelling --time.
    p = run(ictk, ["run", model, "--time=-1:1:0.5", "-o", keep], check=False)
    if p.returncode != 2 or "--time: T0 = -1 is before the model's start" not in p.stderr:
        sys.exit(f"FAIL: T0 before the start: exit {p.returncode}, stderr:\n{p.stderr}")
    # The frames folder holds something else: refused before any work.
    with open(os.path.join(work, "keep", "notes.txt"), "w") as f:
        f.write("mine")
    p = run(ictk, ["run", model, "--frames", "0:1:0.5", "-o", keep], check=False)
    if p.returncode != 2 or "holds other files ('notes.txt')" not in p.stderr:
        sys.exit(f"FAIL: foreign files: exit {p.returncode}, stderr:\n{p.stderr}")
    with open(keep) as f:
        if f.read() != "the user's file":
            sys.exit("FAIL: the existing .pvd was changed by a failed run")
    if sorted(os.listdir(os.path.join(work, "keep"))) != ["keep_0000.vtpc", "notes.txt"]:
        sys.exit(f"FAIL: the frames folder was changed: {os.listdir(os.path.join(work, 'keep'))}")
    if sorted(os.listdir(work)) != ["broken.icm", "keep", "keep.pvd"]:
        sys.exit(f"FAIL: files left behind: {sorted(os.listdir(work))}")


CRANIUM = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3"


def check_study(ictk, work, data):
    """ictk study (issue 15): the CT-implant study writes a labelled .vtu with the material arrays
    and an .inp; a missing, truncated or wrongly sized scan and an implant outside the specimen
    are refused with one error line naming the problem and nothing written."""
    import gzip
    import io
    import tarfile
    if not os.path.exists(CRANIUM):
        sys.exit(f"FAIL: {CRANIUM} is missing: install invesalius-examples (Scripts/setup does)")
    model = os.path.join(data, "Studies", "ct-implant", "ct-implant.json")
    vtu = os.path.join(work, "ct.vtu")
    if not shutil.which("ccx"):
        sys.exit("FAIL: ccx is missing: install calculix-ccx (Scripts/setup does)")
    # The study also solves the compression case (--solve): E_app between the Reuss and Voigt
    # bounds of its deck (the number), the results beside the mesh.
    report = json.loads(run(ictk, ["study", model, "-o", vtu, "--deterministic", "--json", "--solve", "0.06"]).stdout)
    if not os.path.exists(os.path.join(work, "ct.inp")):
        sys.exit("FAIL: no ct.inp beside ct.vtu")
    if not report["reuss_modulus"] <= report["apparent_modulus"] <= report["voigt_modulus"]:
        sys.exit(f"FAIL: E_app {report['apparent_modulus']} outside [Reuss, Voigt] = "
                 f"[{report['reuss_modulus']}, {report['voigt_modulus']}]")
    print(f"study: E_app {report['apparent_modulus']:.1f} MPa, Reuss {report['reuss_modulus']:.1f}, "
          f"Voigt {report['voigt_modulus']:.1f}")
    if not os.path.exists(os.path.join(work, "ct-solved.vtu")):
        sys.exit("FAIL: no ct-solved.vtu beside ct.vtu")
    no_leftovers(work)
    import vtk
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(vtu)
    r.Update()
    grid = r.GetOutput()
    # The same specimen made homogeneous (every element E = 1000 MPa, nu = 0.3): between
    # frictionless platens its apparent modulus is E itself, the Voigt bound (the issue: within
    # 0.5 %). The mesh's own arrays are overwritten, so this is the study's mesh, solved apart.
    homogeneous = vtk.vtkUnstructuredGrid()
    homogeneous.DeepCopy(grid)
    for name, v in (("youngs_modulus", 1000.0), ("poisson_ratio", 0.3), ("density", 1.0)):
        a = homogeneous.GetCellData().GetArray(name)
        for c in range(homogeneous.GetNumberOfCells()):
            a.SetTuple1(c, v)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(os.path.join(work, "homogeneous.vtu"))
    w.SetInputData(homogeneous)
    w.Write()
    solved = json.loads(run(ictk, ["solve", os.path.join(work, "homogeneous.vtu"), "--compression", "0.06",
                                   "-o", os.path.join(work, "homogeneous-solved.vtu"), "--json"]).stdout)
    print(f"homogeneous specimen: E_app {solved['apparent_modulus']:.3f} MPa, Voigt {solved['voigt_modulus']:.3f}")
    near(solved["voigt_modulus"], 1000, 1e-6, "homogeneous Voigt bound")
    near(solved["apparent_modulus"] / solved["voigt_modulus"], 1, 0.005, "homogeneous E_app / Voigt")
    if grid.GetNumberOfCells() != report["tetrahedra"] or report["tetrahedra"] < 10000:
        sys.exit(f"FAIL: {grid.GetNumberOfCells()} tetrahedra in the .vtu, {report['tetrahedra']} reported")
    for name in ("label", "density", "youngs_modulus", "poisson_ratio"):
        if not grid.GetCellData().GetArray(name):
            sys.exit(f"FAIL: the .vtu has no cell array {name!r}")
    labels = grid.GetCellData().GetArray("label")
    modulus = grid.GetCellData().GetArray("youngs_modulus")
    for c in range(0, grid.GetNumberOfCells(), 101):
        if labels.GetTuple1(c) == 4 and modulus.GetTuple1(c) != 110000:
            sys.exit(f"FAIL: implant tetrahedron {c} has modulus {modulus.GetTuple1(c)}")
    if report["deck_materials"] < 10:
        sys.exit(f"FAIL: only {report['deck_materials']} deck materials from the scan's moduli")

    study = json.load(open(model))
    check_study_stamp(ictk, work, study)

    def refused(name, pattern, scan=None, implant_z0=None, shell_radius=None):
        doc = json.loads(json.dumps(study))
        for cell in doc["cells"]:
            if cell["name"] == "shell" and shell_radius is not None:
                cell["inside"][0] = cell["inside"][0].replace("3.0 - ", f"{shell_radius} - ")
            if cell["name"] == "bone" and scan is not None:
                cell["file"] = scan
            if cell["name"] == "implant" and implant_z0 is not None:
                cell["bounds"][0][2] = implant_z0
        folder = os.path.join(work, name)
        os.makedirs(folder)
        path = os.path.join(folder, "study.json")
        json.dump(doc, open(path, "w"), indent=2)
        p = run(ictk, ["study", path, "-o", os.path.join(folder, "x.vtu")], check=False)
        # A scan the complex file cannot read is the file's diagnostic (file:line:col: error:
        # with the line and a caret); the study's own checks are one "ictk: error:" line.
        first = p.stderr.splitlines()[0] if p.stderr else ""
        if p.returncode != 2 or not re.search(pattern, first) or "error: " not in first:
            sys.exit(f"FAIL: {name}: exit {p.returncode}, stderr:\n{p.stderr}")
        written = [f for f in os.listdir(folder) if f.startswith("x.")]
        if written:
            sys.exit(f"FAIL: {name}: output written despite the error: {written}")
        no_leftovers(folder)

    refused("missing", r"missing\.inv3': no such file", scan=os.path.join(work, "missing.inv3"))
    cut = os.path.join(work, "cut.inv3")
    with open(CRANIUM, "rb") as f, open(cut, "wb") as out:
        out.write(f.read(4 << 20))
    refused("truncated", r"cut\.inv3': the gzip data is truncated", scan=cut)
    # A project whose header says 256 x 256 x 108 but whose matrix holds one slice less.
    plist = (b'<?xml version="1.0"?><plist version="1.0"><dict><key>matrix</key><dict>'
             b'<key>dtype</key><string>int16</string><key>filename</key><string>matrix.dat</string>'
             b'<key>shape</key><array><integer>108</integer><integer>256</integer><integer>256</integer>'
             b'</array></dict><key>spacing</key><array><real>0.957</real><real>0.957</real><real>1.5</real>'
             b'</array></dict></plist>')
    short = os.path.join(work, "short.inv3")
    with tarfile.open(short, "w:gz") as t:
        for member, payload in (("p/main.plist", plist), ("p/matrix.dat", bytes(256 * 256 * 107 * 2))):
            info = tarfile.TarInfo(member)
            info.size = len(payload)
            t.addfile(info, io.BytesIO(payload))
    refused("short", r"'matrix\.dat' holds 14024704 bytes; its shape 108 x 256 x 256 of int16 needs 14155776",
            scan=short)
    # The same through VTK's readers: a MetaImage and a NRRD header of 10^3 int16 values whose
    # raw file holds 9 slices (vtkmetaio only prints this on stderr and VTK hands on zeros).
    open(os.path.join(work, "short.raw"), "wb").write(bytes(10 * 10 * 9 * 2))
    with open(os.path.join(work, "short.mhd"), "w") as f:
        f.write("ObjectType = Image\nNDims = 3\nDimSize = 10 10 10\nElementType = MET_SHORT\n"
                "ElementSpacing = 1 1 1\nOffset = 0 0 0\nElementDataFile = short.raw\n")
    refused("short-mhd", r"short\.mhd': its data holds fewer values than its header's size says "
            r"\(ideal = 2000 : actual = 1800 bytes\)", scan=os.path.join(work, "short.mhd"))
    with open(os.path.join(work, "short.nhdr"), "w") as f:
        f.write("NRRD0004\ntype: short\ndimension: 3\nsizes: 10 10 10\nspacings: 1 1 1\n"
                "encoding: raw\nendian: little\ndata file: short.raw\n")
    refused("short-nrrd", r"short\.nhdr': its data holds fewer values than its header's size says",
            scan=os.path.join(work, "short.nhdr"))
    refused("outside", r"implant 'implant' reaches outside the specimen on axis z: \[140, 152\.25\]",
            implant_z0=140)
    # A 0.1 mm shell at size 1: CGAL would lose it (or never finish); refused before meshing.
    refused("thin", r"the implants' protected curves come 0\.0\d+ apart .* use --size 0\.3\d+ or less",
            shell_radius=2.6)
    # The study object itself: every key is one docs/medical.md lists, of the type it lists, and
    # every cell it names is a cell of the complex (a misspelt law or material would otherwise
    # leave a default in force without a word).
    def settings_refused(name, edit, pattern):
        doc = json.loads(json.dumps(study))
        edit(doc["study"])
        folder = os.path.join(work, name)
        os.makedirs(folder)
        path = os.path.join(folder, "study.json")
        json.dump(doc, open(path, "w"), indent=2)
        p = run(ictk, ["study", path, "-o", os.path.join(folder, "x.vtu")], check=False)
        first = p.stderr.splitlines()[0] if p.stderr else ""
        if p.returncode != 2 or not re.search(pattern, first) or not first.startswith("ictk: error: "):
            sys.exit(f"FAIL: {name}: exit {p.returncode}, stderr:\n{p.stderr}")
        if [f for f in os.listdir(folder) if f.startswith("x.")]:
            sys.exit(f"FAIL: {name}: output written despite the error")

    settings_refused("misspelt-key", lambda s: s.update({"modulus_lwa": {"a": 1}}),
                     r"study: unknown key \"modulus_lwa\" \(known: \"size\", ")
    settings_refused("law-not-object", lambda s: s.update({"density_law": 5}),
                     r"study\.density_law must be a JSON object")
    settings_refused("law-key", lambda s: s["modulus_law"].update({"d": 2}),
                     r"study\.modulus_law: unknown key \"d\" \(known: \"a\", \"b\", \"c\"\)")
    settings_refused("fixed-unknown-cell", lambda s: s["fixed"].update({"shel": {"youngs_modulus": 1}}),
                     r"study\.fixed\.shel: 'shel' is not a cell of the complex")
    settings_refused("fixed-not-object", lambda s: s["fixed"].update({"shell": 3}),
                     r"study\.fixed\.shell must be a JSON object")
    settings_refused("implant-unknown-cell", lambda s: s.update({"implants": ["implant", "pin"]}),
                     r"study: \"implants\" names 'pin', which is not a cell of the complex")
    settings_refused("scan-not-string", lambda s: s.update({"scan": 3}),
                     r"study: \"scan\" must be a string")
    settings_refused("size-negative", lambda s: s.update({"size": -1}),
                     r"study: \"size\" must be a positive element size")
    # The implant library's parameters are checked where the study file gives them: a screw of
    # negative pitch is the complex file's diagnostic naming the function and the parameter.
    folder = os.path.join(work, "pitch")
    os.makedirs(folder)
    implants = os.path.join(data, "Studies", "ct-implant", "implants.hf")
    text = open(implants).read().replace("hfScrew(x, o, d, 1.5, 2.5, 3, 6)", "hfScrew(x, o, d, 1.5, 2.5, -3, 6)")
    if "-3, 6)" not in text:
        sys.exit("FAIL: implants.hf no longer has the screw this check edits")
    open(os.path.join(folder, "implants.hf"), "w").write(text)
    doc = json.load(open(os.path.join(data, "Studies", "ct-implant", "ct-implants.json")))
    for cell in doc["cells"]:
        if cell["kind"] == "V":
            cell["file"] = CRANIUM
    json.dump(doc, open(os.path.join(folder, "study.json"), "w"), indent=2)
    p = run(ictk, ["study", os.path.join(folder, "study.json"), "-o", os.path.join(folder, "x.vtu")], check=False)
    if p.returncode != 2 or "hfScrew: screw: pitch must be positive (got -3)" not in p.stderr:
        sys.exit(f"FAIL: negative pitch: exit {p.returncode}, stderr:\n{p.stderr}")
    if [f for f in os.listdir(folder) if f.startswith("x.")]:
        sys.exit("FAIL: negative pitch: output written despite the error")


def check_study_stamp(ictk, work, study):
    """The study file's "stamp" (voxel::stamp on the scan cell): a bone graft of 1500 HU packed
    about the pin (r < 5 mm) is written into the scan before it is meshed, so every tetrahedron
    whose trilinear support lies inside the graft (r < 5 - 0.957 sqrt 2 = 3.646 mm) is bone with
    E = 6850 (1 + 0.001 1500)^1.49 (the study's laws) and none there is soft tissue."""
    import vtk
    doc = json.loads(json.dumps(study))
    for cell in doc["cells"]:
        if cell["name"] == "bone":
            cell["stamp"] = [{"inside": "5 - sqrt((x[1] - 122.5)^2 + (x[2] - 122.5)^2)", "value": 1500}]
    folder = os.path.join(work, "stamp")
    os.makedirs(folder)
    path = os.path.join(folder, "study.json")
    json.dump(doc, open(path, "w"), indent=2)
    vtu = os.path.join(folder, "stamped.vtu")
    run(ictk, ["study", path, "-o", vtu, "--deterministic", "--json"])
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(vtu)
    r.Update()
    grid = r.GetOutput()
    labels = grid.GetCellData().GetArray("label")
    modulus = grid.GetCellData().GetArray("youngs_modulus")
    graft = 6850 * (1 + 0.001 * 1500) ** 1.49
    checked = 0
    for c in range(grid.GetNumberOfCells()):
        ids = grid.GetCell(c).GetPointIds()
        radii = []
        for k in range(4):
            x, y, _ = grid.GetPoint(ids.GetId(k))
            radii.append(math.hypot(x - 122.5, y - 122.5))
        # Outside the shell (r >= 3; its vertices lie on the shell's cylinder up to the
        # tracer's error) and inside the support radius: r is convex, so the whole tetrahedron
        # and all its sampling points are.
        if not (min(radii) > 2.999 and max(radii) < 3.64):
            continue
        if labels.GetTuple1(c) != 2:
            sys.exit(f"FAIL: stamp: tetrahedron {c} at r {min(radii):.3f}..{max(radii):.3f} has label "
                     f"{labels.GetTuple1(c)}, not bone (2)")
        if abs(modulus.GetTuple1(c) / graft - 1) > 1e-6:
            sys.exit(f"FAIL: stamp: tetrahedron {c} has E {modulus.GetTuple1(c)}, the graft's {graft}")
        checked += 1
    print(f"stamp: {checked} tetrahedra in the graft ring, all bone with E = {graft:.2f} MPa")
    if checked < 100:
        sys.exit(f"FAIL: stamp: only {checked} tetrahedra in 3 < r < 3.64")


def check_study_implants(ictk, work, data):
    """ictk study on ct-implants.json (issue 15): the screw, the plate and the scaffold mesh into
    their labels with the volumes of their formulas, and the study file's own "solve" runs
    CalculiX: E_app between the deck's Reuss and Voigt bounds."""
    if not os.path.exists(CRANIUM):
        sys.exit(f"FAIL: {CRANIUM} is missing: install invesalius-examples (Scripts/setup does)")
    if not shutil.which("ccx"):
        sys.exit("FAIL: ccx is missing: install calculix-ccx (Scripts/setup does)")
    model = os.path.join(data, "Studies", "ct-implant", "ct-implants.json")
    report = json.loads(run(ictk, ["study", model, "-o", os.path.join(work, "imp.vtu"), "--deterministic",
                                   "--threads", "2", "--json"]).stdout)
    volumes = {m["name"]: m["volume"] for m in report["materials"]}
    if sorted(volumes) != sorted(["soft", "bone", "screw", "screw_shell", "plate", "plate_shell", "scaffold",
                                  "scaffold_shell"]):
        sys.exit(f"FAIL: labels {sorted(volumes)}")
    # The screw: pi E[r^2] L with r uniform in [1.5, 2.5] along the thread: 6 pi (2.25 + 1.5 + 1/3).
    screw = 6 * math.pi * (2.25 + 1.5 + 1 / 3)
    plate = 12 * 6 * 1.5 - 2 * math.pi * 1.25 ** 2 * 1.5
    plate_shell = 13 * 7 * 2.5 - 2 * math.pi * 0.75 ** 2 * 2.5 - plate
    for name, expected, tolerance in (("screw", screw, 0.02), ("plate", plate, 0.01),
                                      ("plate_shell", plate_shell, 0.01)):
        if abs(volumes[name] / expected - 1) > tolerance:
            sys.exit(f"FAIL: {name} volume {volumes[name]} against {expected} (tolerance {tolerance})")
    near(sum(volumes.values()), 24 * 24 * 6, 0.001 * 24 * 24 * 6, "total volume")
    # At size 1 (the study's): measured worst dihedral 1.00 deg, first percentile 11.1-11.6 deg.
    if report["size"] != 1 or report["min_dihedral_degrees"] < 0.5 or report["min_dihedral_percentile1_degrees"] < 10:
        sys.exit(f"FAIL: size {report['size']}, dihedrals {report['min_dihedral_degrees']} (worst), "
                 f"{report['min_dihedral_percentile1_degrees']} (1st percentile)")
    if not report["reuss_modulus"] <= report["apparent_modulus"] <= report["voigt_modulus"]:
        sys.exit(f"FAIL: E_app {report['apparent_modulus']} outside [Reuss, Voigt] = "
                 f"[{report['reuss_modulus']}, {report['voigt_modulus']}]")
    if not os.path.exists(os.path.join(work, "imp-solved.vtu")):
        sys.exit("FAIL: no imp-solved.vtu")


def parse_arguments(usage):
    """--ictk PATH --work DIR CHECK [ARGS...] -> (ictk, work, check, args), with an empty work
    folder. Parsed by hand: the patterns and ictk arguments start with "--" themselves."""
    argv = sys.argv[1:]
    if len(argv) < 5 or argv[0] != "--ictk" or argv[2] != "--work":
        sys.exit(usage)
    ictk, work, check, rest = argv[1], argv[3], argv[4], argv[5:]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    return ictk, work, check, rest


def main():
    ictk, work, check, rest = parse_arguments(__doc__)
    checks = {
        "models": check_models,
        "eval-json": check_eval_json,
        "eval-plain": check_eval_plain,
        "sample-sphere": check_sample_sphere,
        "sample-band": check_sample_band,
        "sample-walnut": check_sample_walnut,
        "sample-disk2d": check_sample_disk2d,
        "mesh-formats": check_mesh_formats,
        "model-files": check_model_files,
        "bench": check_bench,
        "bench-scaling": check_bench_scaling,
        "bench-peer": check_bench_peer,
        "run-space-time": check_run_space_time,
        "render": check_render,
    }
    if check == "study":
        check_study(ictk, work, rest[0])
        print("OK")
        return
    if check == "study-implants":
        check_study_implants(ictk, work, rest[0])
        print("OK")
        return
    if check == "scale-plots":
        check_scale_plots(ictk, work, rest[0])
        print("OK")
        return
    if check == "tetra-bar":
        check_tetra_bar(ictk, work, rest[0])
        print("OK")
        return
    if check == "solve-bar":
        check_solve_bar(ictk, work, rest[0])
        print("OK")
        return
    if check in ("run-disk", "run-errors", "run-default", "sample-frames", "run-standin",
                 "sample-icm", "run-characters"):
        {"run-disk": check_run_disk, "run-errors": check_run_errors,
         "run-default": check_run_default, "sample-frames": check_sample_frames,
         "sample-icm": check_sample_icm,
         "run-standin": check_run_standin, "run-characters": check_run_characters}[check](
            ictk, work, rest[0])
        print("OK")
        return
    if check == "complex-flower":
        check_complex_flower(ictk, work, rest[0])
        print("OK")
        return
    if check == "expect-error":
        if len(rest) < 2 or rest[1] != "--":
            sys.exit("usage: expect-error REGEX -- ICTK-ARGS...")
        check_error(ictk, work, rest[0], rest[2:])
    elif check in checks:
        checks[check](ictk, work)
    else:
        sys.exit(f"unknown check {check!r}")
    print("OK")


if __name__ == "__main__":
    main()
