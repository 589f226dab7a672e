"""Bad files opened in ParaView: ICTK's error, with the file, line and column, reaches the output
window; nothing crashes, and a good file opens afterwards in the same session.

usage: pvpython TestParaViewBadFiles.py WORK
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.vtkConstants import VTK_STRING
from vtkmodules.vtkCommonCore import vtkOutputWindow

WORK = sys.argv[1]
os.makedirs(WORK, exist_ok=True)
# What reaches ParaView's output window (pvpython prints Python's own output through it too, so
# the window is observed, not replaced).
messages = []


@calldata_type(VTK_STRING)
def on_error(caller, event, text):
    messages.append(text)


vtkOutputWindow.GetInstance().AddObserver("ErrorEvent", on_error)
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message, flush=True)


def write(name, text):
    path = os.path.join(WORK, name)
    with open(path, "w") as out:
        out.write(text)
    return path


cases = [
    # file, text, what the error must say
    ("syntax.hf", "m(x[3], a[1])\n{\n  m = 1 - * x[1];\n}\n", ":3:"),
    ("unknown.hf", "m(x[3], a[1])\n{\n  m = hfNoSuchPrimitive(x, 1);\n}\n", ":3:"),
    ("truncated.xml", '<?xml version="1.0"?>\n<frep version="1" name="m">\n  <geometry domain="XYZ">\n', "truncated.xml"),
    ("complex.json", '{ "cells": [ { "name": "a", "kind": "F", "dimension": 3, "inside": ["1 - "] } ] }\n', "complex.json"),
    ("model.icm", "MODEL m {\n  TIMESPANS { t : TIMESPAN(0, ; }\n}\n", ":1:7: error"),
    ("nan.hf", "m(x[3], a[1])\n{\n  m = 1 - x[1] * nan;\n}\n", "nan.hf"),
]
for name, text, place in cases:
    path = write(name, text)
    messages.clear()
    # .xml is also claimed by ParaView's CityGML reader: a user picks ICTK's in File > Open.
    reader = ICTKFRepModelReader(FileName=path) if name.endswith(".xml") else OpenDataFile(path)
    check(reader is not None, f"{name}: a reader was chosen")
    if reader is None:
        continue
    try:
        reader.UpdatePipeline()
    except Exception as e:  # ParaView reports, it does not raise; either way no crash
        print(f"{name}: {e}")
    errors = "".join(messages)
    print(f"--- {name}:", errors.split("ERROR: In vtkExecutive")[0].strip().replace("\n", "\n    "))
    check(path in errors or os.path.basename(path) in errors, f"{name}: the error names the file: {errors[:300]!r}")
    check(place in errors, f"{name}: the error says {place!r}: {errors[:400]!r}")
    Delete(reader)

# A missing file: ParaView itself refuses it before any reader runs.
try:
    OpenDataFile(os.path.join(WORK, "missing.hf"))
    check(False, "a missing file raises")
except RuntimeError as e:
    check("missing.hf" in str(e), f"missing file: {e}")

# The session still works.
good = write("good.hf", "m(x[3], a[1])\n{\n  m = 1 - x[1]^2 - x[2]^2 - x[3]^2;\n}\n")
reader = OpenDataFile(good)
reader.SampleDimensions = [5, 5, 5]
reader.UpdatePipeline()
check(reader.GetDataInformation().GetNumberOfPoints() == 125, "a good file opens after the bad ones")
if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("all checks passed")
