#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""What ictk survives (issue 19, docs/reliability.md), run as a user would.

Usage: ictk_reliability_check.py --ictk PATH --work DIR CHECK [DATA]
  reader-errors        broken voxel and mesh files in a complex: one diagnostic naming the file
                       and what was wrong, exit 2, no VTK text (VTK's text with --verbose)
  faults DATA [tetgen]  writers past the file size limit (as a full disk) and in a read-only folder
  series-faults DATA   .pvd series (run, sample --frames) and render --frames filling the disk
                       mid-run: the frame and its file named, exit 2, the earlier series kept
  hyperfun-strict DATA `ictk --strict` refuses ICTK's HyperFun extensions at their place
  vanishing-files DATA SHIM  files cut short or gone while ictk reads them (SHIM: ictkFaultRead,
                       loaded with LD_PRELOAD): one diagnostic naming the file, exit 2, no output
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


def frame_sizes(folder, pattern):
    """The largest file of each frame (its file, or its pieces), by frame number."""
    sizes = {}
    for name in tree(folder):
        m = re.search(pattern, name)
        if m:
            k = int(next(g for g in m.groups() if g is not None))
            sizes[k] = max(sizes.get(k, 0), os.path.getsize(os.path.join(folder, name)))
    return [sizes[k] for k in sorted(sizes)]


def check_series_faults(ictk, work, data):
    """A series whose frames fill the disk mid-run (the file size limit, as in check_faults, set
    between the first frames' sizes and a later frame's): exit 2, one line naming the frame and
    its file, no crash, the earlier series of the same name kept whole (its .pvd and frames),
    nothing else left behind."""
    models = os.path.join(data, "Models")
    cases = [
        ("run", ["run", os.path.join(models, "icm", "ch5_1_disk_rectangle.icm"), "--frames", "0:6:0.5"],
         "series.pvd", r"series_(\d+)\.vtpc|series_(\d+)/"),
        ("sample", ["sample", "morph", "--resolution", "24", "--frames", "0.125:0.875:0.125"],
         "series.pvd", r"series_(\d+)\.vti"),
        ("render", ["render", "morph", "--size", "64,64", "--frames", "0:1:0.125"],
         "frames/%04d.png", r"(\d+)\.png"),
    ]
    for command, args, output, pattern in cases:
        # The series as it is when nothing fails: the earlier result, and the frames' sizes.
        folder = os.path.join(work, command)
        os.makedirs(folder)
        target = os.path.join(folder, output)
        run(ictk, args + ["-o", target])
        before = {name: open(os.path.join(folder, name), "rb").read() for name in tree(folder)}
        sizes = frame_sizes(folder, pattern)
        # The limit: lowered from well above every file until the series fails. A single file
        # fails when it reaches the limit, so the first failure is at the first frame whose
        # largest file is the largest of all (a later frame for these models: mid-run); a
        # composite frame is refused when one of its pieces may not fit (their sizes in memory,
        # not known here), so its frame is read from the message. A run that succeeds rewrites
        # the same bytes (Reliability.Determinism), so the earlier series stays as it was.
        expected = next((k for k in range(1, len(sizes)) if sizes[k] > max(sizes[:k])), None)
        if command == "run":
            limit = 4 * max(sizes)
            while True:
                p = run_limited(ictk, args + ["-o", target], limit)
                if p.returncode != 0 or limit < 64:
                    break
                limit = int(limit * 0.9)
        elif expected is None:
            sys.exit(f"FAIL: {command}: no frame larger than the ones before it ({sizes})")
        else:
            limit = max(sizes[:expected]) + 1
            p = run_limited(ictk, args + ["-o", target], limit)
        lines = p.stderr.strip().splitlines()
        m = re.search(r"frame (\d+) of|(\d+)\.png'", lines[-1] if lines else "")
        failing = int(next(g for g in m.groups() if g is not None)) if m else -1
        if command == "run":
            expected = failing
        if command == "render":
            frame = os.path.join(folder, "frames", f"{failing:04d}.png")
            want = f"ictk: error: cannot write '{re.escape(frame)}': .*"
        else:
            ext = "vtpc" if command == "run" else "vti"
            frame = os.path.join(folder, "series", f"series_{failing:04d}.{ext}")
            want = (f"ictk: error: cannot write frame {failing} of '{re.escape(target)}' "
                    f"\\({re.escape(frame)}\\): .*; nothing written")
        if failing != expected or not 0 <= failing < len(sizes):
            sys.exit(f"FAIL: {command}: frame {failing} failed, expected {expected} (frame sizes {sizes}):\n"
                     f"{p.stderr}")
        if p.returncode != 2 or not lines or not re.fullmatch(want, lines[-1]) or VTK_TEXT.search(p.stderr):
            sys.exit(f"FAIL: {command} series past the file size limit {limit} (frame sizes {sizes}): exit "
                     f"{p.returncode}, stderr:\n{p.stderr}\nexpected the last line to match {want!r}")
        after = {name: open(os.path.join(folder, name), "rb").read() for name in tree(folder)}
        if after != before:
            changed = sorted(set(before) ^ set(after) | {n for n in before if after.get(n) != before[n]})
            sys.exit(f"FAIL: {command}: the earlier series changed or files were left: {changed[:10]}")
        print(f"{command}: frame {failing} over {limit} bytes refused, the earlier series kept")


def check_hyperfun_strict(ictk, work, data):
    """--strict (before or after the command) refuses ICTK's own library functions in a model file
    with the diagnostic at the call, and reads HyperFun-ordered calls; without it, ICTK reads both."""
    models = os.path.join(data, "Models")
    blend = os.path.join(models, "stb_cross_disks.hf")
    out = os.path.join(work, "x.vti")
    for args in (["--strict", "sample", blend], ["sample", blend, "--strict"]):
        p = run(ictk, args + ["--time", "0.5", "--resolution", "8", "-o", out], check=False)
        lines = p.stderr.splitlines()
        want = (re.escape(blend) + r":14:21: error: 'hfSpaceTimeBlend' is ICTK's own, not in HyperFun's "
                r"library \(refused by --strict\)")
        if p.returncode != 2 or not lines or not re.fullmatch(want, lines[0]) or os.path.exists(out):
            sys.exit(f"FAIL: ictk {' '.join(args)}: exit {p.returncode}, stderr:\n{p.stderr}\nexpected {want!r}")
    run(ictk, ["sample", blend, "--time", "0.5", "--resolution", "8", "-o", out])
    # functions.hf calls bead, defined before my_model, as HyperFun requires.
    run(ictk, ["--strict", "sample", os.path.join(models, "functions.hf"), "--params", "0,1",
               "--resolution", "8", "-o", out])


def run_with_fault(ictk, args, shim, path, after, fault):
    """ictk with ictkFaultRead striking `path` (absolute) once a read passes byte `after`."""
    env = dict(os.environ)
    env["LD_PRELOAD"] = " ".join(filter(None, [env.get("LD_PRELOAD", ""), shim]))
    env.update(ICTK_FAULT_PATH=path, ICTK_FAULT_AFTER=str(after), ICTK_FAULT=fault)
    return subprocess.run([ictk] + args, capture_output=True, text=True, timeout=100, env=env)


def check_vanishing_files(ictk, work, data, shim):
    """A model file, a complex's voxel file and an .icm's mesh file each cut short (truncate) or
    gone with its disk (vanish) half-way through being read: exit 2, the first line a diagnostic
    naming the file and what happened, none of VTK's text, no output, the earlier output kept."""
    earlier = b"the user's earlier result"
    # A HyperFun model (read whole by readSourceFile).
    model = os.path.join(work, "torus.hf")
    with open(os.path.join(data, "Models", "twisted_torus.hf"), "rb") as f:
        write(model, f.read())
    size = os.path.getsize(model)
    # A voxel file of a complex (read by VTK's XML reader under ictk's error capture).
    scan = os.path.join(work, "scan.vti")
    run(ictk, ["sample", "sphere", "-o", scan, "--resolution", "40"])
    with open(os.path.join(work, "complex.json"), "w") as f:
        f.write('{ "cells": [\n  { "name": "scan", "kind": "V", "dimension": 3, "file": "scan.vti" } ] }\n')
    # The mesh file of an .icm B-cell: cut at a line boundary, what is left is itself a smaller
    # valid mesh, which only the size check tells from the file.
    mesh = os.path.join(work, "handle.obj")
    lines = [f"v {math.cos(k * 0.1):.6f} {math.sin(k * 0.1):.6f} {z}" for z in (0, 1) for k in range(63)]
    lines += [f"f {k + 1} {(k + 1) % 63 + 1} {k + 64}" for k in range(63)]
    write(mesh, ("\n".join(lines) + "\n").encode())
    cut = ("\n".join(lines[:126 + 40]) + "\n").encode()  # every vertex, 40 of the 63 faces
    with open(os.path.join(work, "handle.icm"), "w") as f:
        f.write("name = HANDLE;\nTIMESPANS { film : TIMESPAN(0, 1); }\n"
                "CELLS {\n  Handle { type = B-CELL; shape = file(\"handle.obj\"); dim = 2D; }\n}\n"
                "K { CELLS { Handle; } }\n")
    cases = [
        (model, ["sample", model, "--resolution", "16", "-o"], "out.vti", size // 2,
         re.escape(model) + r": error: the file changed while it was read: it had " + str(size) +
         " bytes when opened, " + str(size // 2) + " were read",
         re.escape(model) + r": error: cannot read the file: Input/output error"),
        (scan, ["mesh", os.path.join(work, "complex.json"), "-o"], "out.vtpc", os.path.getsize(scan) // 2,
         re.escape(os.path.join(work, "complex.json") + ":2:13: error: cell 'scan': cannot read '" + scan +
                   "': ") + r"its data is cut short or corrupt.*",
         re.escape(os.path.join(work, "complex.json") + ":2:13: error: cell 'scan': cannot read '" + scan +
                   "': ") + r".*"),
        (mesh, ["run", os.path.join(work, "handle.icm"), "--frames", "0:1:0.5", "-o"], "out.pvd", len(cut),
         ".*" + re.escape(mesh) + r".*the file changed while it was read: it had " +
         str(os.path.getsize(mesh)) + " bytes when opened, " + str(len(cut)) + " were read",
         ".*" + re.escape(mesh) + r".*cannot read the file: Input/output error"),
    ]
    keep = {"torus.hf", "scan.vti", "complex.json", "handle.obj", "handle.icm"}
    for path, args, output, after, truncated, vanished in cases:
        with open(path, "rb") as f:
            original = f.read()
        for fault, want in (("truncate", truncated), ("vanish", vanished)):
            target = os.path.join(work, output)
            write(target, earlier)
            p = run_with_fault(ictk, args + [target], shim, path, after, fault)
            lines = p.stderr.strip().splitlines()
            if p.returncode != 2 or not lines or not re.fullmatch(want, lines[0]) or VTK_TEXT.search(p.stderr):
                sys.exit(f"FAIL: {os.path.basename(path)} {fault} while read: exit {p.returncode}, stderr:\n"
                         f"{p.stderr}\nexpected the first line to match {want!r}")
            with open(target, "rb") as f:
                if f.read() != earlier:
                    sys.exit(f"FAIL: {os.path.basename(path)} {fault}: the earlier {output} was changed")
            left = sorted(set(os.listdir(work)) - keep - {output})
            if left:
                sys.exit(f"FAIL: {os.path.basename(path)} {fault}: files left behind: {left}")
            if fault == "truncate" and os.path.getsize(path) != after:
                sys.exit(f"FAIL: the fault did not strike {path} ({os.path.getsize(path)} bytes)")
            write(path, original)
            os.remove(target)
        print(f"{os.path.basename(path)}: cut at byte {after} and gone: refused")


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
    elif check == "hyperfun-strict":
        check_hyperfun_strict(ictk, work, rest[0])
    elif check == "vanishing-files":
        check_vanishing_files(ictk, work, rest[0], rest[1])
    elif check == "series-faults":
        check_series_faults(ictk, work, rest[0])
    elif check.startswith("determinism-"):
        check_determinism(ictk, work, check[len("determinism-"):], rest[0], rest[1:])
    else:
        sys.exit(f"unknown check {check!r}")
    print("OK")


if __name__ == "__main__":
    main()
