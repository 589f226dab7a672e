#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""`ictk` on animated BlobTrees (.blob, docs/blobtree.md) as a user runs it: each command
instantiates the tree at --time (or at every frame of --frames), the values agree with the
kernel's formula at the instance's hand-derived parameters, and without a time the file is refused
with its path (exit code 2, no output file).

Usage: blob_check.py --ictk PATH --work DIR --data DATA
"""
import json
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET


def run(ictk, args, code=0):
    p = subprocess.run([ictk] + args, capture_output=True, text=True, timeout=200)
    if p.returncode != code:
        sys.exit(f"FAIL: ictk {' '.join(args)} exited {p.returncode}, not {code}\n"
                 f"stdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p


def wyvill(d, R):
    """Wyvill's soft-object kernel g(d) for radius R (docs/blobtree.md)."""
    q = d * d / (R * R)
    return 1 - 22 / 9 * q + 17 / 9 * q * q - 4 / 9 * q ** 3 if q < 1 else 0.0


def pulse(t, p):
    """pulse.blob's f = g(|p - c(t)|; R(t)) - T: c = (sin(2 pi t / 4), 0, 0), R linear 2 -> 3
    over t in [0, 2], clamped, T = 0.5."""
    c = math.sin(2 * math.pi * t / 4)
    R = 2 + 0.5 * min(max(t, 0.0), 2.0)
    return wyvill(math.dist(p, (c, 0, 0)), R) - 0.5


def fract(x):
    return x - math.floor(x)


def lattice_hash(i, j, k):
    """FRep/SolidTexture.h's hash, from its formula."""
    a, b, c = fract(0.1031 * i), fract(0.1031 * j), fract(0.1031 * k)
    d = a * (c + 33.33) + b * (b + 33.33) + c * (a + 33.33)
    return fract((a + d + b + d) * (c + d))


def noise(x, y, z):
    """Value noise: the hash at the cell's corners mixed with weights u = f^2 (3 - 2 f)."""
    i, j, k = math.floor(x), math.floor(y), math.floor(z)
    u = [f * f * (3 - 2 * f) for f in (x - i, y - j, z - k)]
    mix = lambda a, b, w: a + (b - a) * w
    c = lambda di, dj, dk: lattice_hash(i + di, j + dj, k + dk)
    x00, x10 = mix(c(0, 0, 0), c(1, 0, 0), u[0]), mix(c(0, 1, 0), c(1, 1, 0), u[0])
    x01, x11 = mix(c(0, 0, 1), c(1, 0, 1), u[0]), mix(c(0, 1, 1), c(1, 1, 1), u[0])
    return mix(mix(x00, x10, u[1]), mix(x01, x11, u[1]), u[2])


def fbm(p, octaves):
    return sum(0.5 ** o * noise(*(2 ** o * c for c in p)) for o in range(octaves)) / \
        sum(0.5 ** o for o in range(octaves))


def main():
    a = sys.argv[1:]
    if len(a) != 6 or a[0] != "--ictk" or a[2] != "--work" or a[4] != "--data":
        sys.exit(__doc__)
    ictk, work, data = a[1], a[3], a[5]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    blob = os.path.join(data, "Models", "blob", "pulse.blob")

    # eval at two times, by --time and by --at's fourth value: the formula at the instance.
    for t, p in ((0.0, (1.5, 0, 0)), (1.0, (1.5, 0, 0)), (3.0, (-0.4, 0.3, 0.2)), (1.7, (0.9, 1.1, 0))):
        for args in (["--at", ",".join(map(str, p)), "--time", str(t)],
                     ["--at", ",".join(map(str, p + (t,)))]):
            v = json.loads(run(ictk, ["eval", blob, "--json"] + args).stdout)["value"]
            if abs(v - pulse(t, p)) > 1e-12:
                sys.exit(f"FAIL: eval {args} gives {v}, the formula {pulse(t, p)}")
    # The two times differ (the check would not see a model read at one time only).
    if abs(pulse(0.0, (1.5, 0, 0)) - pulse(1.0, (1.5, 0, 0))) < 0.1:
        sys.exit("FAIL: the check's times do not tell the instances apart")

    # Without a time: refused with the path, nothing written.
    for args in (["eval", blob, "--at", "0,0,0"], ["sample", blob, "-o", os.path.join(work, "x.vti")],
                 ["mesh", blob, "-o", os.path.join(work, "x.vtp")],
                 ["render", blob, "-o", os.path.join(work, "x.png")],
                 ["info", blob], ["convert", blob, os.path.join(work, "x.hf")]):
        p = run(ictk, args, code=2)
        if f"'{blob}' is an animated BlobTree" not in p.stderr or "--time" not in p.stderr:
            sys.exit(f"FAIL: ictk {' '.join(args)} without a time says:\n{p.stderr}")
    # convert: a .blob is written only from a .blob, --time only instantiates a .blob.
    for args, says in ((["convert", "walnut", os.path.join(work, "w.blob")], "written only from a .blob"),
                       (["convert", os.path.join(data, "Models", "bracket.hf"), os.path.join(work, "b.xml"),
                         "--time", "1"], "--time instantiates a .blob"),
                       (["convert", blob, os.path.join(work, "n.blob"), "--time", "nan"], "finite")):
        p = run(ictk, args, code=2)
        if says not in p.stderr:
            sys.exit(f"FAIL: ictk {' '.join(args)} says:\n{p.stderr}")
    if os.listdir(work):
        sys.exit(f"FAIL: refused commands wrote {os.listdir(work)}")

    # convert to .blob: the whole tree keeps its animations (eval at two times gives the formula),
    # --time t writes the static instance at t (eval without a time gives the formula at t), and
    # --time t to .xml the instance's model.
    whole, frozen, xml = (os.path.join(work, n) for n in ("whole.blob", "frozen.blob", "frozen.xml"))
    run(ictk, ["convert", blob, whole])
    run(ictk, ["convert", blob, frozen, "--time", "1.7"])
    run(ictk, ["convert", blob, xml, "--time", "1.7"])
    run(ictk, ["info", frozen])  # static: no time needed
    for path, t, p, time_args in ((whole, 0.0, (1.5, 0, 0), ["--time", "0"]),
                                  (whole, 3.0, (-0.4, 0.3, 0.2), ["--time", "3"]),
                                  (frozen, 1.7, (0.9, 1.1, 0), []), (xml, 1.7, (0.9, 1.1, 0), []),
                                  (frozen, 1.7, (2.2, 0.1, -0.3), [])):
        v = json.loads(run(ictk, ["eval", path, "--json", "--at", ",".join(map(str, p))] + time_args)
                       .stdout)["value"]
        if abs(v - pulse(t, p)) > 1e-12:
            sys.exit(f"FAIL: {os.path.basename(path)} at {p} (t = {t}) gives {v}, the formula {pulse(t, p)}")
    # The T-Rex's instance at t = 0.5 (its 66 cylinders expanded into elements) is the same field.
    trex = os.path.join(data, "Models", "blob", "trex.blob")
    trex_frozen = os.path.join(work, "trex-0.5.blob")
    run(ictk, ["convert", trex, trex_frozen, "--time", "0.5"])
    # (points in the body and at its edge, where elements overlap: the values are 1.5, -0.135..,
    # 1.0065.. and 0.5038..)
    for p in ((0.0, 0.0, 3.0), (0.0, 0.0, 2.0), (1.0, 0.0, 3.0), (3.0, 0.0, 4.0)):
        at = ",".join(map(str, p))
        a = json.loads(run(ictk, ["eval", trex, "--json", "--at", at, "--time", "0.5"]).stdout)["value"]
        b = json.loads(run(ictk, ["eval", trex_frozen, "--json", "--at", at]).stdout)["value"]
        if abs(a - b) > 1e-12:
            sys.exit(f"FAIL: the T-Rex at t = 0.5 and its converted instance differ at {p}: {a}, {b}")

    # mesh --time 1: every vertex lies on the sphere |p - (1, 0, 0)| = r, g(r; 2.5) = 1/2, which
    # is r = 1.25 (g(R / 2) = 1/2 for Wyvill's kernel), to the grid's accuracy.
    vtp = os.path.join(work, "t1.vtp")
    run(ictk, ["mesh", blob, "--time", "1", "-o", vtp, "--resolution", "40"])
    import vtk  # Debian's python3-vtk
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(vtp)
    r.Update()
    pts = r.GetOutput().GetPoints()
    if pts is None or pts.GetNumberOfPoints() < 100:
        sys.exit("FAIL: mesh --time 1 wrote no surface")
    worst = max(abs(math.dist(pts.GetPoint(i), (1, 0, 0)) - 1.25) for i in range(pts.GetNumberOfPoints()))
    if worst > 0.02:
        sys.exit(f"FAIL: mesh --time 1: a vertex is {worst} from the sphere of radius 1.25 about (1, 0, 0)")

    # sample --frames: each frame is the instance at its time; one grid holds every frame.
    pvd = os.path.join(work, "pulse.pvd")
    run(ictk, ["sample", blob, "--frames", "0:2:1", "-o", pvd, "--dims", "9,5,5", "--double"])
    frames = [(float(d.get("timestep")), os.path.join(work, d.get("file")))
              for d in ET.parse(pvd).getroot().iter("DataSet")]
    if [t for t, _ in frames] != [0.0, 1.0, 2.0]:
        sys.exit(f"FAIL: the series' times are {[t for t, _ in frames]}")
    for t, path in frames:
        reader = vtk.vtkXMLImageDataReader()
        reader.SetFileName(path)
        reader.Update()
        image = reader.GetOutput()
        f = image.GetPointData().GetArray("f")
        for i in range(0, image.GetNumberOfPoints(), 7):
            p = image.GetPoint(i)
            if abs(f.GetValue(i) - pulse(t, p)) > 1e-12:
                sys.exit(f"FAIL: frame t = {t} at {p}: {f.GetValue(i)}, the formula {pulse(t, p)}")
        # The grid holds the model at t = 1 (centre x = 1, R = 2.5: x up to 3.5).
        b = image.GetBounds()
        if not (b[0] <= -2.0 and b[1] >= 3.5):
            sys.exit(f"FAIL: the series' grid {b} does not hold every frame")

    # render --time and --frames draw the instances.
    run(ictk, ["render", blob, "--time", "1", "-o", os.path.join(work, "t1.png"), "--size", "40,30"])
    run(ictk, ["render", blob, "--frames", "0:1:1", "-o", os.path.join(work, "f%02d.png"),
               "--size", "40,30"])
    for name in ("t1.png", "f00.png", "f01.png"):
        if not os.path.getsize(os.path.join(work, name)):
            sys.exit(f"FAIL: render wrote no {name}")
    # A value valid when read but out of its range at t: R(t) = 1 - 0.8 t (linear keys) is -0.2 at
    # t = 1.5. eval and mesh instantiate at t = 0, and refuse t = 1.5 (exit 2, nothing written)
    # naming the node's line and column, the value and t.
    shrinking = os.path.join(work, "shrinking.blob")
    with open(shrinking, "w") as f:
        f.write("blend {\n  point 1 1 [2 0 0]\n  point keys(1, 0 1, 2 -0.6) 1 [0 0 0]\n}\n")
    v = json.loads(run(ictk, ["eval", shrinking, "--json", "--at", "0,0,0", "--time", "0"]).stdout)["value"]
    if abs(v - 0.5) > 1e-12:  # g(0) = 1 at the centre, the other point 2 away with R = 1: 1 - T
        sys.exit(f"FAIL: shrinking.blob at the origin, t = 0, gives {v}, not 0.5")
    refused = os.path.join(work, "refused.vtp")
    for args in (["eval", shrinking, "--at", "0,0,0", "--time", "1.5"],
                 ["mesh", shrinking, "--time", "1.5", "-o", refused]):
        p = run(ictk, args, code=2)
        says = (f"{shrinking}:3:3: error: blobtree: point: the radius of influence R must be "
                "positive (got -0.2) at t = 1.5")
        if says not in p.stderr or "point keys(1, 0 1, 2 -0.6)" not in p.stderr:
            sys.exit(f"FAIL: ictk {' '.join(args)} says:\n{p.stderr}")
    if os.path.exists(refused):
        sys.exit("FAIL: the refused mesh was written")
    run(ictk, ["mesh", shrinking, "--time", "0", "-o", os.path.join(work, "t0.vtp"), "--resolution", "16"])

    # Solid textures (docs/blobtree.md) through the attribute machinery: a granite ball, its
    # colour in the sampled volume equal to the noise formula at every grid point, and a marble
    # ball, its colour on the mesh's vertices equal to the vein formula (evaluated just inside).
    textured = os.path.join(work, "granite.blob")
    with open(textured, "w") as f:
        f.write("granite [1 0 0] [0 0 1] 0.1 0.2 1.3 0.35 0 3 { point 2 1 [0 0 0] }\n")
    vti = os.path.join(work, "granite.vti")
    run(ictk, ["sample", textured, "-o", vti, "--dims", "11,9,7", "--double"])
    reader = vtk.vtkXMLImageDataReader()
    reader.SetFileName(vti)
    reader.Update()
    image = reader.GetOutput()
    colour, optics = (image.GetPointData().GetArray(n) for n in ("colour", "optics"))
    spread = []
    for i in range(image.GetNumberOfPoints()):
        p = image.GetPoint(i)
        s = fbm([c / 0.35 for c in p], 3)
        got = colour.GetTuple3(i)
        if max(abs(got[0] - (1 - s)), abs(got[1]), abs(got[2] - s)) > 1e-12 or \
                optics.GetTuple3(i) != (0.1, 0.2, 1.3):
            sys.exit(f"FAIL: granite at {p}: colour {got}, the formula s = {s}")
        spread.append(s)
    if max(spread) - min(spread) < 0.3:
        sys.exit(f"FAIL: the granite's noise hardly varies: {min(spread)} .. {max(spread)}")
    marble = os.path.join(work, "marble.blob")
    with open(marble, "w") as f:
        f.write("marble [1 0 0] [0 0 1] 0 0 1 0.8 0 1 { point 2 1 [0 0 0] }\n")
    vtp = os.path.join(work, "marble.vtp")
    run(ictk, ["mesh", marble, "-o", vtp, "--resolution", "32"])
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(vtp)
    r.Update()
    mesh = r.GetOutput()
    colour = mesh.GetPointData().GetArray("colour")
    if mesh.GetNumberOfPoints() < 100 or colour is None:
        sys.exit("FAIL: the marble mesh has no colour on its vertices")
    worst = 0
    for i in range(mesh.GetNumberOfPoints()):
        x = mesh.GetPoint(i)[0]
        s = 0.5 + 0.5 * math.sin(2 * math.pi * x / 0.8)
        worst = max(worst, abs(colour.GetTuple3(i)[2] - s), abs(colour.GetTuple3(i)[0] - (1 - s)))
    # Attributes are evaluated 1e-3 grid steps inside: |ds/dx| <= pi / 0.8, the step 2.04 / 31.
    if worst > 1e-3:
        sys.exit(f"FAIL: the marble's vertex colours are {worst} from the formula")
    run(ictk, ["mesh", os.path.join(data, "Models", "blob", "solid_textures.blob"), "-o",
               os.path.join(work, "textures.vtp"), "--resolution", "24"])
    print("OK")


if __name__ == "__main__":
    main()
