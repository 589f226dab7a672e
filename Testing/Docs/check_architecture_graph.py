"""docs/architecture.md's core graph against the one CMake recorded (build/ictk-core-graph.txt).

Every library CMake built must be in the page with the same dependencies; a library of the page
that CMake did not build must be marked optional there.

usage: check_architecture_graph.py ARCHITECTURE.md ictk-core-graph.txt
"""
import sys


def parse(lines):
    graph, optional = {}, set()
    for line in lines:
        text, _, comment = line.partition("#")
        if ":" not in text:
            continue
        name, _, deps = text.partition(":")
        graph[name.strip()] = sorted(deps.split())
        if "optional" in comment:
            optional.add(name.strip())
    return graph, optional


page = open(sys.argv[1]).read()
marker = page.index("<!-- core-graph")
block = page[page.index("```", marker) + 3:]
block = block[block.index("\n") + 1:block.index("```")]
documented, optional = parse(block.splitlines())
built, _ = parse(open(sys.argv[2]).read().splitlines())
problems = []
for name, deps in built.items():
    if name not in documented:
        problems.append(f"{name} is built but not in the page")
    elif documented[name] != deps:
        problems.append(f"{name}: CMake says {' '.join(deps) or '(nothing)'}, the page {' '.join(documented[name]) or '(nothing)'}")
for name in documented:
    if name not in built and name not in optional:
        problems.append(f"{name} is in the page but not built (and not marked optional)")
for p in problems:
    print("FAIL:", p)
if problems:
    sys.exit(1)
print(f"{len(built)} core libraries: the page matches CMake")
