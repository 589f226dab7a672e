#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Runs `ictk render` on complexes, dynamic models and frame ranges as a user would and checks
what it prints and writes (the FRep model pictures are ictk_cli_check.py's `render`).

Usage: render_check.py --ictk PATH --work DIR --data DATA CHECK
  flower | icm | frames | film | interrupt | inside | camera | baselines | pictures | mesh |
  tetcut
baselines compares pictures with Testing/Data/Baseline/Render*.png; with the environment variable
ICTK_REGENERATE_BASELINES=1 it writes them instead.
mesh needs an X display (run it under Testing/ParaView/run_checked.py --xvfb).
"""
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ictk_cli_check import no_leftovers, run  # noqa: E402


def read_png(path):
    import vtk
    r = vtk.vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    image = r.GetOutput()
    scalars = image.GetPointData().GetScalars()
    w, h, _ = image.GetDimensions()
    pixels = [tuple(int(scalars.GetComponent(i, c)) for c in range(4)) for i in range(w * h)]
    return w, h, pixels


def by_dimension(stdout):
    m = re.search(r"(\d+) pixels covered: (\d+) by 0D cells, (\d+) 1D, (\d+) 2D, (\d+) 3D", stdout)
    if not m:
        sys.exit(f"FAIL: no pixel counts by dimension in:\n{stdout}")
    covered, *dims = (int(g) for g in m.groups())
    if covered != sum(dims):
        sys.exit(f"FAIL: {covered} covered but {dims} by dimension")
    return covered, dims


def check_flower(ictk, work, data):
    """The flower with every cell dimension in view, its colours from the complex's attribute."""
    png = os.path.join(work, "flower.png")
    p = run(ictk, ["render", os.path.join(data, "Models/flower/flower.json"), "-o", png,
                   "--size", "96,72", "--view", "-70,25", "--threads", "2"])
    covered, dims = by_dimension(p.stdout)
    if min(dims) <= 0:
        sys.exit(f"FAIL: a cell dimension is not in view: {dims}")
    w, h, pixels = read_png(png)
    opaque = [q for q in pixels if q[3] == 255]
    if (w, h) != (96, 72) or len(opaque) != covered:
        sys.exit(f"FAIL: {w} x {h} with {len(opaque)} opaque pixels, {covered} reported")
    # The receptacle is green (S2: 0.3, 0.55 + 0.3 z, 0.25) and the pistil yellow: both show.
    green = sum(1 for r, g, b, a in opaque if g > r and g > b)
    yellow = sum(1 for r, g, b, a in opaque if r > b and g > b and r >= g)
    if green < 100 or yellow < 100:
        sys.exit(f"FAIL: {green} green and {yellow} yellow pixels")
    # The attribute by name gives the same picture; an undeclared one is refused.
    again = os.path.join(work, "again.png")
    run(ictk, ["render", os.path.join(data, "Models/flower/flower.json"), "-o", again,
               "--size", "96,72", "--view", "-70,25", "--threads", "1", "--colour-by", "colour"])
    if read_png(again)[2] != pixels:
        sys.exit("FAIL: --colour-by colour (or one thread) changed the picture")
    no_leftovers(work)


def check_icm(ictk, work, data):
    """A .icm model at --time: its curves, points and patches at that time."""
    png = os.path.join(work, "dependency.png")
    p = run(ictk, ["render", os.path.join(data, "Models/icm/ch5_2_dependency.icm"), "-o", png,
                   "--size", "120,90", "--time", "2"])
    covered, dims = by_dimension(p.stdout)
    if dims[0] <= 0 or dims[1] <= 0 or dims[2] <= 0:
        sys.exit(f"FAIL: the points, the curve and the patches are not all in view: {dims}")
    # Without --time: the model's start, a different picture (the cells move).
    start = os.path.join(work, "start.png")
    run(ictk, ["render", os.path.join(data, "Models/icm/ch5_2_dependency.icm"), "-o", start,
               "--size", "120,90"])
    if read_png(start)[2] == read_png(png)[2]:
        sys.exit("FAIL: the picture at t = 2 is the one at the start")
    no_leftovers(work)


def check_frames(ictk, work, data):
    """--frames to numbered PNGs: one per frame, the pattern's folder made, nothing else left."""
    icm = os.path.join(data, "Models/icm/ch5_1_disk_rectangle.icm")
    pattern = os.path.join(work, "frames", "%02d.png")
    p = run(ictk, ["render", icm, "--frames", "0:1:0.5", "-o", pattern, "--size", "40,30"])
    names = sorted(os.listdir(os.path.join(work, "frames")))
    if names != ["00.png", "01.png", "02.png"]:
        sys.exit(f"FAIL: frames {names}")
    if "3 frame(s)" not in p.stdout:
        sys.exit(f"FAIL: the summary:\n{p.stdout}")
    pictures = [read_png(os.path.join(work, "frames", n)) for n in names]
    if any(w != 40 or h != 30 for w, h, _ in pictures) or pictures[0][2] == pictures[2][2]:
        sys.exit("FAIL: the frames are not 40 x 30, or the disk did not move")
    # An XYZT model's frames.
    run(ictk, ["render", "morph", "--frames", "0:1:0.5", "-o", os.path.join(work, "m%d.png"),
               "--size", "20,20"])
    for k in range(3):
        if not os.path.exists(os.path.join(work, f"m{k}.png")):
            sys.exit(f"FAIL: no frame m{k}.png")
    no_leftovers(work)
    no_leftovers(os.path.join(work, "frames"))


def check_film(ictk, work, data):
    """--frames to an .mp4 film through ffmpeg: the frames and an even size, nothing left."""
    if shutil.which("ffmpeg") is None or shutil.which("ffprobe") is None:
        print("SKIP: ffmpeg is not installed")
        return
    icm = os.path.join(data, "Models/icm/ch5_1_disk_rectangle.icm")
    film = os.path.join(work, "disk.mp4")
    run(ictk, ["render", icm, "--frames", "0:2:0.5", "-o", film, "--size", "41,31", "--fps", "4"])
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                            "-show_entries", "stream=nb_read_frames,width,height,r_frame_rate",
                            "-of", "csv=p=0", film], capture_output=True, text=True, check=True)
    if probe.stdout.strip() != "42,32,4/1,5":
        sys.exit(f"FAIL: the film is {probe.stdout.strip()!r}, not 42 x 32 at 4/1 with 5 frames")
    if sorted(os.listdir(work)) != ["disk.mp4"]:
        sys.exit(f"FAIL: left behind: {os.listdir(work)}")


def check_interrupt(ictk, work, data):
    """Ctrl-C during a range of frames: exit code 130 and nothing written, not even the folder."""
    pattern = os.path.join(work, "frames", "%03d.png")
    p = subprocess.Popen([ictk, "render", "morph", "--frames", "0:1:0.002", "-o", pattern,
                          "--size", "200,150", "--threads", "1"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # The progress lines come at every quarter (stderr is not a terminal): stop after the first.
    line = p.stderr.readline()
    if "%" not in line:
        p.kill()
        sys.exit(f"FAIL: no progress line, got {line!r}")
    p.send_signal(signal.SIGINT)
    try:
        _, err = p.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        p.kill()
        sys.exit("FAIL: Ctrl-C did not stop the render")
    if p.returncode != 130 or "interrupted; nothing written" not in err:
        sys.exit(f"FAIL: exit {p.returncode}\n{err}")
    if os.listdir(work):
        sys.exit(f"FAIL: left behind: {os.listdir(work)}")


def check_inside(ictk, work, data):
    """A camera inside a 3D cell: the picture of its solid from inside, with a warning."""
    ball = os.path.join(work, "ball.json")
    with open(ball, "w") as f:
        f.write('{"ictk_complex": 1, "name": "ball", "cells": [{"name": "ball", "kind": "F", '
                '"dimension": 3, "inside": ["1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3]"], '
                '"bounds": [[-1, -1, -1], [1, 1, 1]]}]}')
    p = run(ictk, ["render", ball, "-o", os.path.join(work, "inside.png"), "--size", "8,8",
                   "--view", "0,0,0.1"])
    if "ictk: warning: 64 pixel(s) see" not in p.stderr or "inside" not in p.stderr:
        sys.exit(f"FAIL: no warning for a camera inside a cell:\n{p.stderr}")
    no_leftovers(work)


def check_camera(ictk, work, data):
    """A camera file that restates --view's camera gives the same picture, bit for bit; the
    orthographic one with the orbit's parallel scale too; bad files are refused by name."""
    import json
    models = json.loads(run(ictk, ["models", "--json"]).stdout)
    b = [m for m in models if m["name"] == "walnut"][0]["bounds"]
    centre = [0.5 * (b[2 * a] + b[2 * a + 1]) for a in range(3)]
    half = 0.5 * math.sqrt(sum((b[2 * a + 1] - b[2 * a]) ** 2 for a in range(3)))
    for projection, extra in (("perspective", {"view_angle": 30}),
                              ("orthographic", {"parallel_scale": 1.1 * half})):
        camera = dict(position=[centre[0] + 4, centre[1], centre[2]], focal_point=centre,
                      up=[0, 0, 1], projection=projection, **extra)
        path = os.path.join(work, projection + ".json")
        with open(path, "w") as f:
            json.dump(camera, f)
        a, c = os.path.join(work, "view.png"), os.path.join(work, "camera.png")
        run(ictk, ["render", "walnut", "-o", a, "--size", "32,24", "--view", "0,0,4",
                   "--projection", projection])
        run(ictk, ["render", "walnut", "-o", c, "--size", "32,24", "--camera", path])
        if read_png(a)[2] != read_png(c)[2]:
            sys.exit(f"FAIL: the {projection} camera file does not give --view's picture")
    bad = os.path.join(work, "bad.json")
    for text, message in (('{"position": [0, 0, 5]}', "has no 'focal_point'"),
                          ('{"position": [0, 0, 5], "focal_point": [0, 0, 0], "zoom": 2}',
                           "unknown key 'zoom'"),
                          ('{"position": [0, 0, 5], "focal_point": [0, 0, 0]}',
                           "up is zero or along its view direction"),
                          ('[1, 2]', "is not a JSON object")):
        with open(bad, "w") as f:
            f.write(text)
        p = run(ictk, ["render", "walnut", "-o", os.path.join(work, "x.png"), "--camera", bad],
                check=False)
        if p.returncode != 2 or message not in p.stderr:
            sys.exit(f"FAIL: {text}: exit {p.returncode}, {p.stderr!r} lacks {message!r}")
    no_leftovers(work)


# The pictures compared with baselines: small, one per kind of scene.
BASELINES = {
    "RenderWalnut.png": ["walnut", "--size", "64,48"],
    "RenderWalnutMaterials.png": ["walnut", "--size", "64,48", "--colour-by", "material",
                                  "--colour-map", "rainbow", "--view", "90,0"],
    "RenderFlower.png": ["@DATA@/Models/flower/flower.json", "--size", "64,48", "--view", "-70,25"],
    "RenderDisk.png": ["@DATA@/Models/icm/ch5_1_disk_rectangle.icm", "--size", "64,48",
                       "--time", "3"],
}
# A pixel differs when a channel differs by more than this (of 255); a picture passes when at
# most TOLERANCE_PIXELS of its pixels differ (rounding of shading, libm, silhouettes).
TOLERANCE_CHANNEL = 8
TOLERANCE_PIXELS = 0.01


def write_png(path, w, h, pixels):
    import vtk
    image = vtk.vtkImageData()
    image.SetDimensions(w, h, 1)
    a = vtk.vtkUnsignedCharArray()
    a.SetNumberOfComponents(4)
    a.SetNumberOfTuples(w * h)
    for i, q in enumerate(pixels):
        for c in range(4):
            a.SetComponent(i, c, q[c])
    image.GetPointData().SetScalars(a)
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()


def check_baselines(ictk, work, data):
    """Pictures against their baselines with a tolerance; the difference image is written on
    failure (white where equal, the difference amplified eight times elsewhere)."""
    folder = os.path.join(data, "..", "Testing", "Data", "Baseline")
    regenerate = os.environ.get("ICTK_REGENERATE_BASELINES") == "1"
    failed = []
    for name, args in BASELINES.items():
        out = os.path.join(work, name)
        run(ictk, ["render"] + [a.replace("@DATA@", data) for a in args] + ["-o", out])
        baseline = os.path.join(folder, name)
        if regenerate:
            shutil.copyfile(out, baseline)
            print(f"wrote {baseline}")
            continue
        w, h, got = read_png(out)
        bw, bh, want = read_png(baseline)
        if (w, h) != (bw, bh):
            failed.append(f"{name}: {w} x {h}, the baseline is {bw} x {bh}")
            continue
        diff = [max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(got, want)]
        bad = sum(1 for d in diff if d > TOLERANCE_CHANNEL)
        print(f"{name}: {bad} of {w * h} pixels differ by more than {TOLERANCE_CHANNEL}")
        if bad > TOLERANCE_PIXELS * w * h:
            image = os.path.join(work, name.replace(".png", "-difference.png"))
            write_png(image, w, h, [(255, 255, 255, 255) if d == 0 else
                                    (255, max(0, 255 - 8 * d), max(0, 255 - 8 * d), 255)
                                    for d in diff])
            failed.append(f"{name}: {bad} pixels differ (difference image: {image})")
    if failed:
        sys.exit("FAIL: " + "; ".join(failed))


def check_pictures(ictk, work, data):
    """The README shows, under its pictures, the commands Scripts/pictures makes them with, and
    every picture is there; each command runs (at a tenth of the size, into the work folder),
    after the `ictk tetra` commands that make the meshes some pictures draw."""
    root = os.path.join(data, "..")
    with open(os.path.join(root, "Scripts", "pictures")) as f:
        script = [l.split() for l in f]
    lines = [l for l in script if l and l[0] == "picture"]
    meshes = [l for l in script if l and l[0] == "tetra"]
    with open(os.path.join(root, "README.md")) as f:
        readme = f.read()
    if len(lines) < 7:
        sys.exit(f"FAIL: {len(lines)} pictures in Scripts/pictures")
    made = {}
    for out, *args in (l[1:] for l in meshes):
        command = f"ictk tetra {' '.join(args)} -o {out}"
        if command not in readme:
            sys.exit(f"FAIL: the README does not show {command!r}")
        made[out] = os.path.join(work, out)
        run(ictk, ["tetra"] + [os.path.join(root, a) if a.startswith("Data/") else a
                               for a in args] + ["-o", made[out]])
    for name, *args in (l[1:] for l in lines):
        command = f"ictk render {' '.join(args)} -o docs/images/{name}"
        if command not in readme:
            sys.exit(f"FAIL: the README does not show {command!r}")
        if f"](docs/images/{name})" not in readme or not os.path.exists(
                os.path.join(root, "docs", "images", name)):
            sys.exit(f"FAIL: docs/images/{name} is not in the README or not in docs/images")
        small = [a if a != "240,180" else "24,18" for a in args]
        run(ictk, ["render"] + [os.path.join(root, a) if a.startswith("Data/") else
                                made.get(a, a) for a in small] + ["-o", os.path.join(work, name)])
    for path in made.values():
        os.remove(path)
    no_leftovers(work)


def read_depth(path):
    import vtk
    r = vtk.vtkXMLImageDataReader()
    r.SetFileName(path)
    r.Update()
    data = r.GetOutput().GetPointData()
    a = data.GetArray("depth")
    depth = [a.GetValue(i) for i in range(a.GetNumberOfTuples())]
    # The normal buffer (seed 003 item 37), when the renderer gives one: unit normals where a
    # surface is, zero on the background.
    n = data.GetArray("normal")
    if n is not None:
        for i, d in enumerate(depth):
            length = math.sqrt(sum(c * c for c in n.GetTuple3(i)))
            if abs(length - (1 if math.isfinite(d) else 0)) > 1e-5:
                sys.exit(f"FAIL: {path}: pixel {i}'s normal has length {length} (depth {d})")
    return depth, n is not None


def compare_modes(ictk, work, name, model, w, h, view, threshold_off=0.005):
    """One picture ray cast and through VTK's polygon pipeline (--mode mesh): the coverage masks
    agree on at least 99 % of the pixels, and where both are covered the depths agree within a
    pixel's footprint, except next to a silhouette (a jump of the ray-cast depth to a neighbour),
    where the two may see different surfaces."""
    depth = {}
    for mode in ("raycast", "mesh"):
        png, vti = (os.path.join(work, f"{name}-{mode}.png"),
                    os.path.join(work, f"{name}-{mode}.vti"))
        run(ictk, ["render", model, "-o", png, "--depth", vti, "--size", f"{w},{h}",
                   "--view", view, "--mode", mode])
        depth[mode], normals = read_depth(vti)
        if normals != (mode == "raycast"):
            sys.exit(f"FAIL: {name}: the {mode} depth file {'lacks' if not normals else 'has'} "
                     "a normal buffer")
    ray, mesh = depth["raycast"], depth["mesh"]
    agree = sum(1 for a, b in zip(ray, mesh) if math.isfinite(a) == math.isfinite(b))
    print(f"{name}: coverage agrees on {agree} of {w * h} pixels")
    if agree < 0.99 * w * h:
        sys.exit(f"FAIL: {name}: coverage agrees on {agree} of {w * h} pixels only")
    pixel = 2 * math.tan(math.radians(15)) / h  # a pixel's side at distance 1 (30 degrees high)
    both = off = 0
    for k, (a, b) in enumerate(zip(ray, mesh)):
        if not (math.isfinite(a) and math.isfinite(b)):
            continue
        both += 1
        footprint = pixel * a
        if abs(a - b) <= footprint:
            continue
        i, j = k % w, k // w
        near = [ray[jj * w + ii] for ii, jj in ((i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1))
                if 0 <= ii < w and 0 <= jj < h]
        if not any(not math.isfinite(n) or abs(n - a) > 3 * footprint for n in near):
            sys.exit(f"FAIL: {name}: pixel {i},{j}: depths {a} (ray cast) and {b} (mesh) differ "
                     f"by more than a footprint ({footprint}) away from any silhouette")
        off += 1
    print(f"{name}: depths agree within a footprint on {both - off} of {both} pixels covered by "
          "both")
    if off > threshold_off * both:
        sys.exit(f"FAIL: {name}: {off} of {both} depths differ by more than a footprint")


def check_mesh(ictk, work, data):
    """The flower complex and a lone FRep model (the walnut) ray cast and through VTK's polygon
    pipeline (--mode mesh): see compare_modes."""
    compare_modes(ictk, work, "flower", os.path.join(data, "Models/flower/flower.json"), 160, 120,
                  "-70,25")
    compare_modes(ictk, work, "walnut", "walnut", 160, 120, "30,20")
    check_tetmesh_mesh_mode(ictk, work)
    print("all checks passed")


def orthographic_camera(path, position, focal, up):
    import json
    with open(path, "w") as f:
        json.dump({"position": position, "focal_point": focal, "up": up,
                   "projection": "orthographic", "parallel_scale": 1}, f)
    return path


def check_tetmesh_mesh_mode(ictk, work):
    """A .vtu tetrahedral mesh through VTK's polygon pipeline (--mode mesh), against pictures
    worked out by hand, the ray caster's rasteriser, and bad input. The two cubes of
    write_two_cubes in 40 x 40 pixels of 0.05 (orthographic, parallel scale 1): seen from +z, the
    whole mesh's silhouette is the 2 x 1 rectangle, exactly the 40 x 20 pixels whose centres lie in
    it (half the picture); cut by x = 1 and seen from +x, the cut face is the 20 x 20 pixels of the
    unit square in the grey map's colour of material 1 (0.15: 38 of 255), or, from -x with the
    other half kept, of material 2 (255). Without --colour-by a mesh is coloured by its MaterialId:
    the same picture as with it. Then the cubes both ways in perspective (compare_modes)."""
    mesh = os.path.join(work, "cubes.vtu")
    write_two_cubes(mesh)
    top = orthographic_camera(os.path.join(work, "top.json"), [1, 0.5, 5], [1, 0.5, 0], [0, 1, 0])
    plus_x = orthographic_camera(os.path.join(work, "plus-x.json"), [5, 0.5, 0.5],
                                 [0, 0.5, 0.5], [0, 0, 1])
    minus_x = orthographic_camera(os.path.join(work, "minus-x.json"), [-5, 0.5, 0.5],
                                  [0, 0.5, 0.5], [0, 0, 1])
    cases = [("top", top, [], 12, 800, lambda row, col: 10 <= row < 30, None),
             ("cut", plus_x, ["--cut", "1,0,0,1"], 6, 400,
              lambda row, col: 10 <= row < 30 and 10 <= col < 30, round(255 * 0.15)),
             ("cut-other-side", minus_x, ["--cut", "-1,0,0,-1"], 6, 400,
              lambda row, col: 10 <= row < 30 and 10 <= col < 30, 255)]
    for name, camera, args, kept, covered, inside, grey in cases:
        pictures = {}
        for mode, colour_by in (("mesh", []), ("mesh", ["--colour-by", "MaterialId"]),
                                ("raycast", [])):
            png = os.path.join(work, f"tets-{name}-{mode}{'-by' if colour_by else ''}.png")
            p = run(ictk, ["render", mesh, "-o", png, "--size", "40,40", "--camera", camera,
                           "--mode", mode, "--colour-map", "grey", "--range", "1,2"]
                    + colour_by + args)
            expected = f"{kept} of 12 tetrahedra kept, {covered} pixels covered, colour map over"
            if expected not in p.stdout:
                sys.exit(f"FAIL: tets {name} {mode}: expected '{expected}' in:\n{p.stdout}")
            w, h, pixels = read_png(png)
            pictures[png] = pixels
            for row in range(h):
                for col in range(w):
                    r, g, b, a = pixels[row * w + col]
                    if inside(row, col) != (a == 255):
                        sys.exit(f"FAIL: tets {name} {mode}: pixel {col},{row} alpha {a}")
                    if grey is not None and a == 255 and abs(r - grey) > 1:
                        sys.exit(f"FAIL: tets {name} {mode}: pixel {col},{row} is {r}, "
                                 f"expected {grey}")
        default, by, ray = pictures.values()
        if default != by:
            sys.exit(f"FAIL: tets {name}: without --colour-by the mesh is not coloured by "
                     "MaterialId")
        if grey is not None and by != ray:
            sys.exit(f"FAIL: tets {name}: the face-on cut differs between the modes")
    print("tets: silhouettes and cut faces as worked out by hand in both modes")
    compare_modes(ictk, work, "tets", mesh, 160, 120, "30,20")
    # Bad input: one line naming the file, exit 2, no picture.
    import vtk
    empty = os.path.join(work, "empty.vtu")
    grid = vtk.vtkUnstructuredGrid()
    points = vtk.vtkPoints()
    points.InsertNextPoint(0, 0, 0)
    grid.SetPoints(points)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(empty)
    w.SetInputData(grid)
    w.Write()
    garbage = os.path.join(work, "garbage.vtu")
    with open(garbage, "w") as f:
        f.write("not XML\n")
    for path, message in ((empty, f"'{empty}' has no cells"),
                          (garbage, f"cannot read '{garbage}': not an XML file"),
                          (os.path.join(work, "nope.vtu"), "cannot read '")):
        out = os.path.join(work, "bad.png")
        q = subprocess.run([ictk, "render", path, "--mode", "mesh", "-o", out],
                           capture_output=True, text=True)
        lines = q.stderr.strip().splitlines()
        if q.returncode != 2 or len(lines) != 1 or message not in lines[0] or os.path.exists(out):
            sys.exit(f"FAIL: --mode mesh {path}: exit {q.returncode}, stderr:\n{q.stderr}")


def write_two_cubes(path):
    """The box [0,2] x [0,1] x [0,1] as two unit cubes of six Kuhn tetrahedra each (materials 1
    and 2 in the cell array MaterialId; the point array x is each point's x)."""
    import vtk
    points = vtk.vtkPoints()
    x = vtk.vtkDoubleArray()
    x.SetName("x")
    for i in range(3):
        for j in range(2):
            for k in range(2):
                points.InsertNextPoint(i, j, k)
                x.InsertNextValue(i)
    grid = vtk.vtkUnstructuredGrid()
    grid.SetPoints(points)
    material = vtk.vtkIntArray()
    material.SetName("MaterialId")
    for cube in range(2):
        for order in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
            c = [cube, 0, 0]
            ids = [c[0] * 4 + c[1] * 2 + c[2]]
            for axis in order:
                c[axis] += 1
                ids.append(c[0] * 4 + c[1] * 2 + c[2])
            # Positively oriented, as .vtu readers of tetrahedra expect: an odd order flips it.
            if order in ((0, 2, 1), (1, 0, 2), (2, 1, 0)):
                ids[2], ids[3] = ids[3], ids[2]
            grid.InsertNextCell(vtk.VTK_TETRA, 4, ids)
            material.InsertNextValue(cube + 1)
    grid.GetCellData().AddArray(material)
    grid.GetPointData().AddArray(x)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(path)
    w.SetInputData(grid)
    if not w.Write():
        sys.exit(f"cannot write {path}")


def check_tetcut(ictk, work, data):
    """A .vtu tetrahedral mesh cut open (--cut) against the cut worked out by hand: the two
    cubes cut by x = 1 keep the first cube's 6 tetrahedra; seen orthographically from +x (40 x 40
    pixels of 0.05), the cut face covers exactly the 20 x 20 pixels whose centres lie in the unit
    square, in the grey map's colour of material 1 (its low end: 0.15), or, by the point array x
    over [0, 2], its middle (0.575); the other side of the cut keeps material 2. Bad input is
    refused."""
    import json
    mesh = os.path.join(work, "cubes.vtu")
    write_two_cubes(mesh)
    camera = os.path.join(work, "camera.json")
    with open(camera, "w") as f:
        json.dump({"position": [5, 0.5, 0.5], "focal_point": [0, 0.5, 0.5], "up": [0, 0, 1],
                   "projection": "orthographic", "parallel_scale": 1}, f)
    cases = [("material", ["--cut", "1,0,0,1", "--colour-by", "MaterialId", "--range", "1,2"],
              round(255 * 0.15), 6),
             ("x", ["--cut", "1,0,0,1", "--colour-by", "x", "--range", "0,2"],
              round(255 * 0.575), 6),
             ("other-side", ["--cut", "-1,0,0,-1", "--colour-by", "MaterialId", "--range", "1,2"],
              255, 6)]
    for name, args, grey, kept in cases:
        png = os.path.join(work, name + ".png")
        view = camera
        if name == "other-side":  # seen from -x: the cut face of the second cube
            view = os.path.join(work, "camera-x.json")
            with open(view, "w") as f:
                json.dump({"position": [-5, 0.5, 0.5], "focal_point": [0, 0.5, 0.5],
                           "up": [0, 0, 1], "projection": "orthographic",
                           "parallel_scale": 1}, f)
        p = run(ictk, ["render", mesh, "-o", png, "--size", "40,40", "--camera", view,
                       "--colour-map", "grey"] + args)
        if f"{kept} of 12 tetrahedra kept, 400 pixels covered" not in p.stdout:
            sys.exit(f"FAIL: {name}: expected 6 of 12 tetrahedra and 400 pixels:\n{p.stdout}")
        w, h, pixels = read_png(png)
        for row in range(h):
            for col in range(w):
                r, g, b, a = pixels[row * w + col]
                inside = 10 <= row < 30 and 10 <= col < 30
                if inside != (a == 255):
                    sys.exit(f"FAIL: {name}: pixel {col},{row} alpha {a}")
                if inside and abs(r - grey) > 1:
                    sys.exit(f"FAIL: {name}: pixel {col},{row} is {r}, expected {grey}")
    # The whole mesh, no colours: its 12 tetrahedra, and a cut that leaves nothing warns.
    p = run(ictk, ["render", mesh, "-o", os.path.join(work, "whole.png"), "--size", "40,40"])
    if "12 of 12 tetrahedra kept" not in p.stdout:
        sys.exit(f"FAIL: the whole mesh:\n{p.stdout}")
    p = run(ictk, ["render", mesh, "-o", os.path.join(work, "none.png"), "--size", "8,8",
                   "--cut", "1,0,0,-5"])
    if "--cut leaves no tetrahedron" not in p.stderr:
        sys.exit(f"FAIL: no warning for a cut that leaves nothing:\n{p.stderr}")
    for args, message in (
            (["--cut", "0,0,0,1"], "--cut: the plane's normal nx,ny,nz is zero"),
            (["--cut", "1,0,0"], "--cut: expected nx,ny,nz,d"),
            (["--colour-by", "nope"], "has no cell or point array 'nope' (it has: MaterialId, x)"),
            (["--time", "1"], "is a tetrahedral mesh: --bounds, --time")):
        out = os.path.join(work, "bad.png")
        q = subprocess.run([ictk, "render", mesh, "-o", out] + args, capture_output=True,
                           text=True)
        if q.returncode != 2 or message not in q.stderr or os.path.exists(out):
            sys.exit(f"FAIL: {args}: exit {q.returncode}, stderr:\n{q.stderr}")
    # Files that are not meshes of tetrahedra.
    import vtk
    garbage = os.path.join(work, "garbage.vtu")
    with open(garbage, "w") as f:
        f.write("not XML\n")
    triangles = os.path.join(work, "triangle.vtu")
    grid = vtk.vtkUnstructuredGrid()
    points = vtk.vtkPoints()
    for p in ((0, 0, 0), (1, 0, 0), (0, 1, 0)):
        points.InsertNextPoint(*p)
    grid.SetPoints(points)
    grid.InsertNextCell(vtk.VTK_TRIANGLE, 3, [0, 1, 2])
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(triangles)
    w.SetInputData(grid)
    w.Write()
    # A grid without a points object: VTK's writer leaves out its <Points> element and VTK's
    # reader says "No Points element available in first piece found in file. Reading file may
    # fail."; ICTK's one line names the file instead, for every command that reads a .vtu.
    no_points = os.path.join(work, "no-points.vtu")
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(no_points)
    w.SetInputData(vtk.vtkUnstructuredGrid())
    w.Write()
    for path, message in ((garbage, f"cannot read '{garbage}': not an XML file"),
                          (triangles, "cell 0 is a vtkTriangle, not a tetrahedron"),
                          (no_points, f"cannot read '{no_points}': it has no points"),
                          (os.path.join(work, "nope.vtu"), "cannot read '")):
        out = os.path.join(work, "bad.png")
        q = subprocess.run([ictk, "render", path, "-o", out], capture_output=True, text=True)
        lines = q.stderr.strip().splitlines()
        if q.returncode != 2 or len(lines) != 1 or message not in lines[0] or os.path.exists(out):
            sys.exit(f"FAIL: {path}: exit {q.returncode}, stderr:\n{q.stderr}")
    out = os.path.join(work, "bad-solved.vtu")
    q = subprocess.run([ictk, "solve", no_points, "--compression", "0.01", "-o", out],
                       capture_output=True, text=True)
    lines = q.stderr.strip().splitlines()
    if (q.returncode != 2 or len(lines) != 1 or f"cannot read '{no_points}': it has no points"
            not in lines[0] or os.path.exists(out)):
        sys.exit(f"FAIL: solve {no_points}: exit {q.returncode}, stderr:\n{q.stderr}")
    q = subprocess.run([ictk, "render", "walnut", "-o", os.path.join(work, "bad.png"), "--cut",
                        "1,0,0,0"], capture_output=True, text=True)
    if q.returncode != 2 or "--cut cuts a tetrahedral mesh (.vtu) open" not in q.stderr:
        sys.exit(f"FAIL: --cut on a model: exit {q.returncode}, stderr:\n{q.stderr}")
    print("all checks passed")


def main():
    argv = sys.argv[1:]
    if len(argv) != 7 or argv[0] != "--ictk" or argv[2] != "--work" or argv[4] != "--data":
        sys.exit(__doc__)
    ictk, work, data, check = argv[1], argv[3], argv[5], argv[6]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    checks = {"flower": check_flower, "icm": check_icm, "frames": check_frames,
              "film": check_film, "interrupt": check_interrupt, "inside": check_inside,
              "camera": check_camera, "baselines": check_baselines,
              "pictures": check_pictures, "mesh": check_mesh, "tetcut": check_tetcut}
    if check not in checks:
        sys.exit(f"unknown check {check!r}")
    checks[check](ictk, work, data)
    print("OK")


if __name__ == "__main__":
    main()
