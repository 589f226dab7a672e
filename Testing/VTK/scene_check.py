#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""`ictk` on seed 003's scenes (.scn, docs/scene.md) as a user runs it: every command reads them,
`convert` writes a scene with `object` references as one file, `render --pick` names the
frontmost object, and a broken scene is reported at file:line:col with exit code 2.

Usage: scene_check.py --ictk PATH --work DIR --data DATA
"""
import json
import os
import re
import shutil
import subprocess
import sys


def run(ictk, args, code=0):
    p = subprocess.run([ictk] + args, capture_output=True, text=True, timeout=200)
    if p.returncode != code:
        sys.exit(f"FAIL: ictk {' '.join(args)} exited {p.returncode}, not {code}\n"
                 f"stdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p


def value(ictk, model, at):
    return json.loads(run(ictk, ["eval", model, "--at", at, "--json"]).stdout)


def main():
    a = sys.argv[1:]
    if len(a) != 6 or a[0] != "--ictk" or a[2] != "--work" or a[4] != "--data":
        sys.exit(__doc__)
    ictk, work, data = a[1], a[3], a[5]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scenes = os.path.join(data, "Models", "scenes")

    # eval: item 30's fixture through the language, F'(1, 0, 0) = 10 / 64, and the object id.
    v = value(ictk, os.path.join(scenes, "perturbed.scn"), "1,0,0")
    if abs(v["value"] - 0.15625) > 1e-12 or v["attributes"]["object"] != 1:
        sys.exit(f"FAIL: perturbed.scn at (1, 0, 0): {v}")

    # convert: y.scn refers to x.scene; the written scene has no reference and the same field.
    flat = os.path.join(work, "flat.scn")
    p = run(ictk, ["convert", os.path.join(scenes, "y.scn"), flat])
    if "one self-contained scene" not in p.stdout:
        sys.exit(f"FAIL: convert says {p.stdout!r}")
    text = open(flat).read()
    if re.search(r"^\s*object\b", text, re.M):
        sys.exit(f"FAIL: the written scene still refers to a file:\n{text}")
    for at in ("0,0,0", "1.1,0,0.05", "0.5,0.5,0.5", "1.2,1.2,0"):
        a, b = value(ictk, flat, at)["value"], value(ictk, os.path.join(scenes, "y.scn"), at)["value"]
        if a != b:
            sys.exit(f"FAIL: at {at} the written scene gives {a}, y.scn {b}")
    # A scene is written only from a scene; a scene converts to HyperFun like any model.
    run(ictk, ["convert", "sphere", os.path.join(work, "s.scn")], code=2)
    run(ictk, ["convert", os.path.join(scenes, "perturbed.scn"), os.path.join(work, "p.hf")])

    # mesh and sample read scenes like any model.
    run(ictk, ["mesh", os.path.join(scenes, "two_objects.scn"), "-o", os.path.join(work, "two.vtp"),
               "--resolution", "24"])

    # render --pick (item 38): two balls on the z axis seen from above, orthographic, 8 units in
    # 80 pixels. Pixel (40, 39) from the top is (0.05, 0.05): the small ball (object 2) in front;
    # (47, 39) is x = 0.75, where only the big one (object 1) is; (0, 0) is background.
    camera = os.path.join(work, "camera.json")
    with open(camera, "w") as f:
        json.dump({"position": [0, 0, 10], "focal_point": [0, 0, 0], "up": [0, 1, 0],
                   "projection": "orthographic", "parallel_scale": 4}, f)
    png = os.path.join(work, "two.png")
    for pixel, expected in (("40,39", "object 2"), ("47,39", "object 1"), ("0,0", "nothing")):
        p = run(ictk, ["render", os.path.join(scenes, "two_objects.scn"), "-o", png, "--size", "80,80",
                       "--camera", camera, "--pick", pixel])
        line = [l for l in p.stdout.splitlines() if l.startswith("pick ")]
        if len(line) != 1 or expected not in line[0]:
            sys.exit(f"FAIL: --pick {pixel}: expected {expected!r}, got:\n{p.stdout}")
    m = re.search(r"depth ([0-9.]+), object 2", run(ictk, ["render", os.path.join(scenes, "two_objects.scn"),
        "-o", png, "--size", "80,80", "--camera", camera, "--pick", "40,39"]).stdout)
    if not m or abs(float(m.group(1)) - (8 - 0.245 ** 0.5)) > 1e-5:
        sys.exit("FAIL: the depth of the small ball's top")
    p = run(ictk, ["render", os.path.join(scenes, "two_objects.scn"), "-o", png, "--size", "80,80",
                   "--pick", "80,0"], code=2)
    if "--pick: 80,0 is outside the 80 x 80 picture" not in p.stderr:
        sys.exit(f"FAIL: a pixel outside the picture:\n{p.stderr}")

    # A broken scene: every error with its place, the source line and a caret; exit code 2.
    bad = os.path.join(work, "bad.scn")
    with open(bad, "w") as f:
        f.write("ell {\n  color 1 0\n}\nsphere\n")
    p = run(ictk, ["eval", bad, "--at", "0,0,0"], code=2)
    for expected in (f"{bad}:2:3: error: 'color' takes 3 numbers, found 2",
                     f"{bad}:4:1: error: unknown object 'sphere'"):
        if expected not in p.stderr:
            sys.exit(f"FAIL: {expected!r} not in:\n{p.stderr}")
    print("OK")


if __name__ == "__main__":
    main()
