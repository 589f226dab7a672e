#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Reads the files of ictkMesh's writers back with independent readers (meshio and gmsh's own
Python API) and checks counts, labels and volumes per material against the writer's manifest.

Usage: mesh_files_check.py --writer PATH --work DIR
Fails when meshio or gmsh is not installed: Scripts/setup installs python3-meshio and
python3-gmsh, so a missing reader is a broken install.
"""
import argparse
import os
import shutil
import subprocess
import sys

try:
    import numpy as np
    import meshio
    import gmsh
except ImportError as e:
    sys.exit(f"FAIL: {e} (install python3-meshio and python3-gmsh: Scripts/setup)")


def fail(message):
    sys.exit(f"FAIL: {message}")


def near(a, b, tol, what):
    if not abs(a - b) <= tol:
        fail(f"{what}: {a} != {b} (tolerance {tol})")


def volumes(points, tets):
    """Signed volumes of tetrahedra (rows of 4 0-based point indices)."""
    p = np.asarray(points, dtype=float)[:, :3]
    t = np.asarray(tets, dtype=np.int64)
    a, b, c, d = (p[t[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0


def read_manifest(path):
    with open(path) as f:
        lines = f.read().splitlines()
    points, tets = (int(v) for v in lines[0].split())
    materials = []
    for line in lines[1:]:
        fields = line.split(" ", 5)
        materials.append({"id": int(fields[0]), "tets": int(fields[1]), "volume": float(fields[2]),
                          "E": float(fields[3]), "set": fields[4], "name": fields[5]})
    return points, tets, materials


def check_groups(what, groups, materials, key):
    """groups: {label: (count, volume, min signed volume)}; key: how materials are labelled."""
    want = {m[key]: m for m in materials}
    if set(groups) != set(want):
        fail(f"{what}: groups {sorted(groups)} != {sorted(want)}")
    for label, (count, volume, smallest) in groups.items():
        m = want[label]
        if count != m["tets"]:
            fail(f"{what}: group {label!r} has {count} tetrahedra, not {m['tets']}")
        near(volume, m["volume"], 1e-12, f"{what}: volume of {label!r}")
        if not smallest > 0:
            fail(f"{what}: group {label!r} has a tetrahedron of volume {smallest} (orientation)")


def summarise(points, tets, labels):
    v = volumes(points, tets)
    out = {}
    for label in np.unique(labels):
        sel = labels == label
        out[label.item() if hasattr(label, "item") else label] = (int(sel.sum()), float(v[sel].sum()),
                                                                 float(v[sel].min()))
    return out


def check_meshio(work, n_points, n_tets, materials):
    by_id = {m["id"]: m for m in materials}
    # Gmsh 2.2 and 4.1: physical tags = material ids, named after the cells.
    for name in ("bar22.msh", "bar41.msh"):
        mesh = meshio.read(os.path.join(work, name))
        what = f"meshio {name}"
        if len(mesh.points) != n_points:
            fail(f"{what}: {len(mesh.points)} points, not {n_points}")
        tets, tags = [], []
        for block, phys in zip(mesh.cells, mesh.cell_data["gmsh:physical"]):
            if block.type != "tetra":
                fail(f"{what}: unexpected cell block {block.type}")
            tets.append(block.data)
            tags.append(phys)
        tets, tags = np.concatenate(tets), np.concatenate(tags)
        if len(tets) != n_tets:
            fail(f"{what}: {len(tets)} tetrahedra, not {n_tets}")
        check_groups(what, summarise(mesh.points, tets, tags), materials, "id")
        names = {int(v[0]): k for k, v in mesh.field_data.items() if int(v[1]) == 3}
        if names != {m["id"]: m["name"] for m in materials}:
            fail(f"{what}: physical names {names}")
    # Abaqus: element sets named after the cells (sanitised).
    mesh = meshio.read(os.path.join(work, "bar.inp"))
    what = "meshio bar.inp"
    if len(mesh.points) != n_points:
        fail(f"{what}: {len(mesh.points)} points, not {n_points}")
    tets = np.concatenate([b.data for b in mesh.cells if b.type == "tetra"])
    if len(tets) != n_tets or any(b.type != "tetra" for b in mesh.cells):
        fail(f"{what}: {len(tets)} tetrahedra in {[b.type for b in mesh.cells]}, not {n_tets}")
    v = volumes(mesh.points, tets)
    groups = {}
    for set_name, per_block in mesh.cell_sets.items():
        if set_name not in {m["set"] for m in materials}:
            continue
        offset, picked = 0, []
        for block, ids in zip(mesh.cells, per_block):
            picked.extend(offset + np.asarray(ids, dtype=np.int64))
            offset += len(block.data)
        picked = np.asarray(picked, dtype=np.int64)
        groups[set_name] = (len(picked), float(v[picked].sum()), float(v[picked].min()))
    check_groups(what, groups, materials, "set")
    # The material lines (meshio does not read them): *ELASTIC after each *MATERIAL.
    with open(os.path.join(work, "bar.inp")) as f:
        lines = [line.strip() for line in f]
    for m in materials:
        i = lines.index(f"*MATERIAL, NAME={m['set']}")
        if lines[i + 1] != "*ELASTIC":
            fail(f"bar.inp: no *ELASTIC after {lines[i]}")
        e, nu = (float(x) for x in lines[i + 2].split(","))
        near(e, m["E"], 1e-9 * m["E"], f"bar.inp: E of {m['set']}")
        if f"*SOLID SECTION, ELSET={m['set']}, MATERIAL={m['set']}" not in lines:
            fail(f"bar.inp: no *SOLID SECTION for {m['set']}")
        if max(len(x.strip()) for x in lines[i + 2].split(",")) > 20:
            fail(f"bar.inp: a number longer than 20 characters: {lines[i + 2]}")
    # MEDIT: references = material ids.
    mesh = meshio.read(os.path.join(work, "bar.mesh"))
    what = "meshio bar.mesh"
    if len(mesh.points) != n_points:
        fail(f"{what}: {len(mesh.points)} points, not {n_points}")
    tets = np.concatenate([b.data for b in mesh.cells if b.type == "tetra"])
    refs = np.concatenate([r for b, r in zip(mesh.cells, mesh.cell_data["medit:ref"])
                           if b.type == "tetra"])
    if len(tets) != n_tets:
        fail(f"{what}: {len(tets)} tetrahedra, not {n_tets}")
    check_groups(what, summarise(mesh.points, tets, refs), materials, "id")
    print(f"meshio: 4 files, {n_points} points, {n_tets} tetrahedra, {len(materials)} materials: ok")


def check_gmsh(work, n_points, n_tets, materials):
    gmsh.initialize(["gmsh", "-v", "2"])  # errors and warnings only
    try:
        for name in ("bar22.msh", "bar41.msh", "bar.mesh"):
            what = f"gmsh {name}"
            gmsh.clear()
            gmsh.open(os.path.join(work, name))
            tags, coords, _ = gmsh.model.mesh.getNodes()
            if len(tags) != n_points:
                fail(f"{what}: {len(tags)} nodes, not {n_points}")
            index = {int(t): i for i, t in enumerate(tags)}
            points = np.asarray(coords).reshape(-1, 3)
            groups = {}
            if name.endswith(".msh"):
                for dim, tag in gmsh.model.getPhysicalGroups(3):
                    label = gmsh.model.getPhysicalName(dim, tag)
                    want = [m for m in materials if m["id"] == tag]
                    if not want or want[0]["name"] != label:
                        fail(f"{what}: physical group {tag} is named {label!r}")
                    entities = gmsh.model.getEntitiesForPhysicalGroup(dim, tag)
                    groups[tag] = entities
                key = "id"
            else:
                # MEDIT references become elementary volumes.
                groups = {tag: [tag] for dim, tag in gmsh.model.getEntities(3)}
                key = "id"
            summary, total = {}, 0
            for label, entities in groups.items():
                tets = []
                for entity in entities:
                    types, _, nodes = gmsh.model.mesh.getElements(3, entity)
                    for t, n in zip(types, nodes):
                        if t != 4:
                            fail(f"{what}: element type {t} in volume {entity}")
                        tets.extend(index[int(x)] for x in n)
                tets = np.asarray(tets, dtype=np.int64).reshape(-1, 4)
                v = volumes(points, tets)
                summary[label] = (len(tets), float(v.sum()), float(v.min()))
                total += len(tets)
            if total != n_tets:
                fail(f"{what}: {total} tetrahedra in the groups, not {n_tets}")
            check_groups(what, summary, materials, key)
    finally:
        gmsh.finalize()
    print(f"gmsh: 3 files (msh 2.2, msh 4.1, MEDIT): ok")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--writer", required=True)
    parser.add_argument("--work", required=True)
    args = parser.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    p = subprocess.run([args.writer, args.work], capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        fail(f"{args.writer} exited {p.returncode}\n{p.stdout}\n{p.stderr}")
    print(p.stdout, end="")
    n_points, n_tets, materials = read_manifest(os.path.join(args.work, "manifest.txt"))
    if len(materials) != 2 or materials[0]["name"] != "t_0^3 steel":
        fail(f"manifest: {materials}")
    leftovers = [f for f in os.listdir(args.work) if ".tmp-" in f]
    if leftovers:
        fail(f"temporary files left: {leftovers}")
    check_meshio(args.work, n_points, n_tets, materials)
    check_gmsh(args.work, n_points, n_tets, materials)
    print("PASS")


if __name__ == "__main__":
    main()
