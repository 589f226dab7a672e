#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""What ictk survives (issue 19, docs/reliability.md), run as a user would.

Usage: ictk_reliability_check.py --ictk PATH --work DIR CHECK [DATA]
  reader-errors        broken voxel and mesh files in a complex: one diagnostic naming the file
                       and what was wrong, exit 2, no VTK text (VTK's text with --verbose)
  faults DATA [tetgen]  writers past the file size limit (as a full disk) and in a read-only folder
  mesh-2d DATA         a 2D model (x[2]) meshed as its boundary curve; .stl refused with the why
  determinism-COMMAND DATA [BACKENDS...]   the same command on 1, 2 and 8 threads writes
                       byte-identical files (COMMAND: sample, mesh, tetra, run, render; tetra with
                       each backend named)
"""
import filecmp
import math
import os
import re
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ictk_cli_check import near, parse_arguments, read_polydata, run  # noqa: E402

# Text that only VTK's own reports carry: an object's address, the source line, the executive.
VTK_TEXT = re.compile(r"0x[0-9a-f]+|ERROR: In |vtkXML|vtkExecutive|vtkInformation|returned failure")


def write(path, data):
    with open(path, "wb") as f:
        f.write(data)


def check_reader_errors(ictk, work):
    """Each broken file referenced by a complex gives the diagnostic
    'complex.json:L:C: error: cell 'scan': cannot read 'FILE': WHY' (with the source line and a
    caret under it, as every model-file error), exit code 2, and none of VTK's own text."""
    import vtk
    sphere = os.path.join(work, "sphere.vti")
    run(ictk, ["sample", "sphere", "-o", sphere, "--resolution", "16"])
    with open(sphere, "rb") as f:
        image = f.read()
    surface = os.path.join(work, "sphere.vtp")
    run(ictk, ["mesh", "sphere", "-o", surface, "--resolution", "16"])
    with open(surface, "rb") as f:
        polydata = f.read()
    empty_image = vtk.vtkImageData()
    empty_image.SetDimensions(3, 3, 3)
    writer = vtk.vtkXMLImageDataWriter()
    writer.SetFileName(os.path.join(work, "noarray.vti"))
    writer.SetInputData(empty_image)
    writer.Write()
    write(os.path.join(work, "garbage.vti"), b"\x89 not XML at all \x00\x01\x02")
    write(os.path.join(work, "empty.vti"), b"")
    write(os.path.join(work, "polydata.vti"), polydata)
    write(os.path.join(work, "cut.vti"), image[:1500])
    write(os.path.join(work, "unclosed.vti"), b'<?xml version="1.0"?>\n<VTKFile type="ImageData">\n  <ImageData')
    write(os.path.join(work, "text.mha"), b"hello")
    write(os.path.join(work, "text.nii"), b"hello")
    write(os.path.join(work, "text.nrrd"), b"hello")
    write(os.path.join(work, "text.ply"), b"hello")
    write(os.path.join(work, "text.stl"), b"hello\x00")
    voxel = {
        "garbage.vti": "cannot read '{}': not an XML file",
        "empty.vti": "cannot read '{}': the file is empty",
        "polydata.vti": "cannot read '{}': a VTK PolyData file, not ImageData",
        "cut.vti": r"cannot read '{}': its data is cut short or corrupt \(Error reading extent 0 15 0 15 0 15 from piece 0\)",
        "unclosed.vti": r"cannot read '{}': not well-formed XML \(line 3, column 3: unclosed token\)",
        "noarray.vti": "'{}' has no point array",
        "text.mha": "cannot read '{}': not a MetaImage file",
        "text.nii": "cannot read '{}': not a NIfTI file",
        "text.nrrd": "cannot read '{}': not a NRRD file",
    }
    mesh = {
        "text.ply": "cannot read '{}': not a PLY file",
        "text.stl": "cannot read '{}': Premature EOF while reading header.",
        "garbage.vti": "'{}': explicit cells are read from .vtp, .vtu, .stl, .ply or .obj files",
    }
    cases = [("V", 3, name, why) for name, why in voxel.items()] + \
            [("B", 2, name, why) for name, why in mesh.items()]
    for kind, dimension, name, why in cases:
        complex_path = os.path.join(work, "complex.json")
        with open(complex_path, "w") as f:
            f.write('{ "cells": [\n  { "name": "scan", "kind": "%s", "dimension": %d, "file": "%s" } ] }\n'
                    % (kind, dimension, name))
        target = os.path.join(work, name)
        commands = [["info", complex_path]]
        if name == "garbage.vti" and kind == "V":
            commands.append(["mesh", complex_path, "-o", os.path.join(work, "x.vtpc")])
        for command in commands:
            p = run(ictk, command, check=False)
            lines = p.stderr.splitlines()
            expected = re.escape(complex_path + ":2:13: error: cell 'scan': ") + why.format(re.escape(target))
            if p.returncode != 2 or not lines or not re.fullmatch(expected, lines[0]):
                sys.exit(f"FAIL: ictk {' '.join(command)} ({name}): exit {p.returncode}, stderr:\n{p.stderr}\n"
                         f"expected the first line to be {expected!r}")
            if len(lines) != 3 or lines[2].strip() != "^" or VTK_TEXT.search(p.stderr + p.stdout):
                sys.exit(f"FAIL: {name}: more than the diagnostic, or VTK's text:\n{p.stderr}")
            if os.path.exists(os.path.join(work, "x.vtpc")) or os.path.exists(os.path.join(work, "x")):
                sys.exit(f"FAIL: {name}: output written despite the error")
    # --verbose adds VTK's own reports, after or before the same diagnostic.
    with open(complex_path, "w") as f:
        f.write('{ "cells": [\n  { "name": "scan", "kind": "V", "dimension": 3, "file": "garbage.vti" } ] }\n')
    p = run(ictk, ["info", complex_path, "--verbose"], check=False)
    if p.returncode != 2 or "vtkXMLDataParser" not in p.stderr or "not an XML file" not in p.stderr:
        sys.exit(f"FAIL: --verbose does not show VTK's report:\n{p.stderr}")


def check_mesh_2d(ictk, work, data):
    """A HyperFun x[2] model (disk2d: the disk of radius 2 minus the disk of radius 0.5 at (1, 0))
    meshed: its boundary curve, closed, on both circles; formats without curves refused."""
    model = os.path.join(data, "Models", "disk2d.hf")
    vtp = os.path.join(work, "disk.vtp")
    p = run(ictk, ["mesh", model, "-o", vtp, "--resolution", "96"])
    if not re.search(r"\(\d+ points, \d+ line segments from a 96 x 96 x 1 grid\)", p.stdout) or p.stderr.count("error"):
        sys.exit(f"FAIL: mesh of a 2D model:\n{p.stdout}\n{p.stderr}")
    curve = read_polydata(vtp)
    if curve.GetNumberOfPolys() != 0 or curve.GetNumberOfLines() < 100:
        sys.exit(f"FAIL: {curve.GetNumberOfLines()} lines, {curve.GetNumberOfPolys()} polygons")
    # Closed: every point ends exactly two segments.
    uses = [0] * curve.GetNumberOfPoints()
    lines = curve.GetLines()
    ids = vtk_id_list()
    lines.InitTraversal()
    while lines.GetNextCell(ids):
        for k in range(ids.GetNumberOfIds()):
            uses[ids.GetId(k)] += 1
    if set(uses) != {2}:
        sys.exit(f"FAIL: the curve is not closed: point uses {sorted(set(uses))}")
    spacing = 4.0 / 95  # the model's bounds are [-2, 2]^2 (interval bounds of the disk)
    outer = inner = 0
    for i in range(curve.GetNumberOfPoints()):
        x, y, z = curve.GetPoint(i)
        near(z, 0.0, 0.0, "z of the 2D curve")
        r_outer, r_inner = math.hypot(x, y) - 2, math.hypot(x - 1, y) - 0.5
        if abs(r_outer) < abs(r_inner):
            outer += 1
            near(r_outer, 0.0, 0.1 * spacing, f"radius of the outer circle at {(x, y)}")
        else:
            inner += 1
            near(r_inner, 0.0, 0.1 * spacing, f"radius of the inner circle at {(x, y)}")
    if outer < 100 or inner < 20:
        sys.exit(f"FAIL: {outer} points on the outer circle, {inner} on the inner one")
    run(ictk, ["mesh", model, "-o", os.path.join(work, "disk.obj"), "--resolution", "32"])
    with open(os.path.join(work, "disk.obj")) as f:
        if not any(l.startswith("l ") for l in f):
            sys.exit("FAIL: the .obj curve has no 'l' lines")
    # The x[2] model as .stl: refused before any work, saying why and how.
    stl = os.path.join(work, "x.stl")
    p = run(ictk, ["mesh", model, "-o", stl], check=False)
    want = (f"ictk: error: -o: 'disk2d' is sampled on a flat 128 x 128 x 1 grid (a 2D model): its boundary "
            f"f = 0 is a curve, written as .vtp or .obj, not '{stl}'")
    if p.returncode != 2 or p.stderr.strip().splitlines() != [want] or os.path.exists(stl):
        sys.exit(f"FAIL: 2D model as .stl: exit {p.returncode}, stderr:\n{p.stderr}\nexpected {want!r}")
    # A grid flat along two axes has no surface at all.
    p = run(ictk, ["mesh", "sphere", "-o", os.path.join(work, "x.vtp"), "--dims", "20,1,1"], check=False)
    want = ("ictk: error: -o: a 20 x 1 x 1 grid has no surface f = 0 to extract; give two or three axes "
            "at least 2 points (--dims, --bounds)")
    if p.returncode != 2 or p.stderr.strip().splitlines() != [want]:
        sys.exit(f"FAIL: a 1D grid: exit {p.returncode}, stderr:\n{p.stderr}")
    # A 3D model cut by a flat box along x: the unit circle in the plane x = 0.
    p = run(ictk, ["mesh", "sphere", "-o", vtp, "--resolution", "40", "--bounds=0,0,-1.2,1.2,-1.2,1.2"])
    curve = read_polydata(vtp)
    for i in range(curve.GetNumberOfPoints()):
        x, y, z = curve.GetPoint(i)
        near(x, 0.0, 0.0, "x of the section")
        near(math.hypot(y, z), 1.0, 0.01, "radius of the section")


def determinism_commands(data):
    """The commands of each determinism check, writing into the current folder ({threads} is the
    thread count): every command that writes a file, with its outputs."""
    models = os.path.join(data, "Models")
    flower = os.path.join(models, "flower", "flower.json")
    bar = os.path.join(models, "bar", "two_material_bar.json")
    return {
        "sample": [["sample", "walnut", "-o", "walnut.vti", "--resolution", "40", "--surface", "walnut.vtp"],
                   ["sample", "morph", "-o", "morph.vti", "--resolution", "24", "--time", "0.5", "--double"]],
        "mesh": [["mesh", "walnut", "-o", "walnut.vtp", "--resolution", "48"],
                 ["mesh", os.path.join(models, "twisted_torus.hf"), "-o", "torus.ply", "--resolution", "40"],
                 ["mesh", os.path.join(models, "disk2d.hf"), "-o", "disk.vtp"],
                 ["mesh", flower, "-o", "flower-c.vtpc"],
                 ["mesh", flower, "-o", "flower-m.vtm", "--size", "0.05", "--volume-resolution", "12"]],
        "tetra": [["tetra", bar, "-o", f"bar-{backend}.{ext}", "--backend", backend, "--size", "0.05",
                   "--deterministic"] for backend in ("tetgen", "cgal") for ext in ("vtu", "inp")],
        "run": [["run", os.path.join(models, "icm", "ch5_1_disk_rectangle.icm"), "--frames", "0:2:0.5",
                 "-o", "disk.pvd", "--trace", "disk.jsonl"]],
        "render": [["render", "walnut", "-o", "walnut.png", "--size", "96,64", "--depth", "walnut-depth.vti"],
                   ["render", os.path.join(models, "twisted_torus.hf"), "-o", "torus.png", "--size", "64,64",
                    "--view", "30,40", "--projection", "orthographic"]],
    }


def tree(folder):
    """Every file under `folder`, relative to it."""
    return sorted(os.path.relpath(os.path.join(root, name), folder)
                  for root, _, names in os.walk(folder) for name in names)


def check_determinism(ictk, work, command, data, backends):
    """The same command on 1, 2 and 8 threads writes the same files, byte for byte (tetra: with
    each of the built `backends`)."""
    commands = determinism_commands(data)[command]
    if command == "tetra":
        commands = [c for c in commands if c[c.index("--backend") + 1] in backends]
    outputs = {}
    for threads in (1, 2, 8):
        folder = os.path.join(work, f"threads-{threads}")
        os.makedirs(folder)
        for args in commands:
            args = [os.path.join(folder, a) if i > 0 and args[i - 1] in ("-o", "--surface", "--trace", "--depth")
                    else a for i, a in enumerate(args)]
            run(ictk, args + ["--threads", str(threads)])
        outputs[threads] = tree(folder)
    if not outputs[1] or outputs[2] != outputs[1] or outputs[8] != outputs[1]:
        sys.exit(f"FAIL: the files differ by thread count: {outputs}")
    for threads in (2, 8):
        for name in outputs[1]:
            a = os.path.join(work, "threads-1", name)
            b = os.path.join(work, f"threads-{threads}", name)
            if not filecmp.cmp(a, b, shallow=False):
                sys.exit(f"FAIL: {name} differs between 1 and {threads} threads")
    print(f"{len(outputs[1])} files identical on 1, 2 and 8 threads")


def run_limited(ictk, args, file_size):
    """ictk under a file size limit of `file_size` bytes (ulimit -f), with SIGXFSZ ignored as a
    shell's `trap '' XFSZ` does, so that a write past it fails (EFBIG) as on a full disk (ENOSPC)."""
    import resource
    import signal

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (file_size, file_size))
    return subprocess.run([ictk] + args, capture_output=True, text=True, timeout=100, preexec_fn=limit)


def check_faults(ictk, work, data):
    """Writers against a full disk (the file size limit) and a read-only folder: exit 2, one
    'ictk: error: cannot write' line naming the output, nothing written, and the user's earlier
    file of the same name untouched."""
    models = os.path.join(data, "Models")
    bar = os.path.join(models, "bar", "two_material_bar.json")
    flower = os.path.join(models, "flower", "flower.json")
    cases = [
        (["sample", "walnut", "--resolution", "40", "-o"], "walnut.vti", "File too large"),
        (["mesh", "walnut", "-o"], "walnut.vtp", "File too large"),
        (["mesh", "walnut", "-o"], "walnut.stl", "Ran out of disk space"),
        (["mesh", "walnut", "-o"], "walnut.ply", r"the file reached the file size limit \(ulimit -f\) of 4096 bytes"),
        (["mesh", "walnut", "-o"], "walnut.obj", r"the file reached the file size limit \(ulimit -f\) of 4096 bytes"),
        (["mesh", flower, "-o"], "flower.vtpc",
         r"a piece may need up to \d+ bytes, over the file size limit \(ulimit -f\) of 4096 bytes"),
        (["render", "walnut", "--size", "400,400", "-o"], "walnut.png", "Ran out of disk space"),
        (["convert", "walnut"], "walnut.xml", "cannot write the temporary file: File too large"),
    ]
    if "tetgen" in sys.argv[6:]:
        cases += [(["tetra", bar, "--backend", "tetgen", "--size", "0.05", "-o"], "bar.msh", "File too large")]
    earlier = b"the user's earlier result"
    for args, name, why in cases:
        target = os.path.join(work, name)
        write(target, earlier)
        p = run_limited(ictk, args + [target], 4096)
        lines = p.stderr.strip().splitlines()
        verb = "save" if args[0] == "convert" else "write"
        want = f"ictk: error: cannot {verb} '{re.escape(target)}': {why}(; nothing written)?"
        if p.returncode != 2 or not lines or not re.fullmatch(want, lines[-1]) or VTK_TEXT.search(p.stderr):
            sys.exit(f"FAIL: {name} past the file size limit: exit {p.returncode}, stderr:\n{p.stderr}\n"
                     f"expected the last line to match {want!r}")
        with open(target, "rb") as f:
            if f.read() != earlier:
                sys.exit(f"FAIL: {name}: the earlier file was changed by the failed write")
        left = sorted(set(os.listdir(work)) - {n for _, n, _ in cases})
        if left:
            sys.exit(f"FAIL: {name}: files left behind: {left}")
    # Composites named alike share their pieces folder: flower.vtm next to flower.vtpc is refused
    # rather than replacing the .vtpc's pieces.
    run(ictk, ["mesh", flower, "-o", os.path.join(work, "flower.vtpc")])
    pieces = tree(os.path.join(work, "flower"))
    p = run(ictk, ["mesh", flower, "-o", os.path.join(work, "flower.vtm")], check=False)
    want = (f"ictk: error: cannot write '{os.path.join(work, 'flower.vtm')}': the folder "
            f"'{os.path.join(work, 'flower')}' holds the pieces of '{os.path.join(work, 'flower.vtpc')}'; "
            "choose another name")
    if p.returncode != 2 or p.stderr.strip().splitlines() != [want] or tree(os.path.join(work, "flower")) != pieces:
        sys.exit(f"FAIL: a .vtm beside a .vtpc of the same name: exit {p.returncode}, stderr:\n{p.stderr}")
    # A read-only folder (as root, whom permissions do not stop, a folder of /proc).
    folder = os.path.join(work, "read-only")
    os.makedirs(folder)
    os.chmod(folder, 0o555)
    if os.geteuid() == 0:
        folder = "/proc/self"
    for args, name, _ in cases:
        target = os.path.join(folder, name)
        p = run(ictk, args + [target], check=False)
        lines = p.stderr.strip().splitlines()
        want = re.escape(f"ictk: error: cannot {'save' if args[0] == 'convert' else 'write'} '{target}'")
        if p.returncode != 2 or len(lines) != 1 or not re.match(want, lines[0]):
            sys.exit(f"FAIL: {name} in a read-only folder: exit {p.returncode}, stderr:\n{p.stderr}")


def vtk_id_list():
    import vtk
    return vtk.vtkIdList()


def main():
    ictk, work, check, rest = parse_arguments(__doc__)
    if check == "reader-errors":
        check_reader_errors(ictk, work)
    elif check == "mesh-2d":
        check_mesh_2d(ictk, work, rest[0])
    elif check == "faults":
        check_faults(ictk, work, rest[0])
    elif check.startswith("determinism-"):
        check_determinism(ictk, work, check[len("determinism-"):], rest[0], rest[1:])
    else:
        sys.exit(f"unknown check {check!r}")
    print("OK")


if __name__ == "__main__":
    main()
