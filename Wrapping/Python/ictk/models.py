"""A Pythonic face of ICTK's core: models, complexes and dynamic complexes from files, evaluated
on NumPy arrays and sampled to NumPy, with the VTK classes underneath.

    import ictk
    model = ictk.load("Data/Models/bracket.hf")     # .hf, .xml, .vm, or a registered name
    f = model.evaluate(points)                      # points: (N, 3) or (N, 4) array -> (N,)
    g = model.gradient(points)                      # (N, 4): df/dx, df/dy, df/dz, df/dt
    a = model.attributes(points)                    # {name: (N, components)}
    grid = model.sample((64, 64, 64))               # grid.f: (nz, ny, nx), grid.attributes
    flower = ictk.load("Data/Models/flower/flower.json")
    data = flower.discretise(feature_size=0.05)     # vtkPartitionedDataSetCollection
    for frame in ictk.load("Data/Models/icm/ch5_1_disk_rectangle.icm").frames([0, 2, 4]):
        print(frame.time, frame.instance, frame.data.GetNumberOfPartitionedDataSets())

Arrays cross into C++ without copies: the points of an (N, 3) float64 C-contiguous array are read
in place and the results are written straight into the NumPy arrays returned (other dtypes or
layouts are converted once). Errors raise ictk.Error with ICTK's message (file:line:col for a
model file).
"""
import os

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.vtkConstants import VTK_STRING
from vtkmodules.vtkCommonCore import vtkCommand

from . import ictkFiltersComplex, ictkFiltersDynamics, ictkFiltersFRep, ictkFiltersMesh


class Error(RuntimeError):
    """An ICTK error: a model that does not read, bad arguments, a failed computation."""


class _Errors:
    """Collects the ErrorEvents of a VTK object, so that they become exceptions, not prints."""

    def __init__(self, obj):
        self.messages = []

        @calldata_type(VTK_STRING)  # VTK hands the message text to callbacks that ask for it
        def record(caller, event, text):
            self.messages.append(text)

        self._observer = record
        obj.AddObserver(vtkCommand.ErrorEvent, record)

    def raise_if_any(self, result):
        """Raises Error when messages were recorded or `result` is falsy (None: a failure)."""
        if self.messages or not result:
            text = "; ".join(_strip_vtk_prefix(m) for m in self.messages if m) or "failed"
            self.messages = []
            raise Error(text)


def _strip_vtk_prefix(text):
    # "ERROR: In file.cxx, line N\nclass (0x...): message" -> "message"
    lines = text.strip().splitlines()
    if lines and lines[0].startswith("ERROR: In ") and len(lines) > 1:
        first = lines[1]
        lines = [first.split("): ", 1)[1] if "): " in first else first] + lines[2:]
    return "\n".join(lines).strip()


def _points(points):
    """An (N, 3) or (N, 4) array as a vtkDataArray sharing its memory (converted once if it must be)."""
    array = np.asarray(points)
    if array.ndim != 2 or array.shape[1] not in (3, 4):
        raise Error(f"points must be an (N, 3) or (N, 4) array, got shape {array.shape}")
    if array.dtype != np.float64 or not array.flags.c_contiguous:
        array = np.ascontiguousarray(array, dtype=np.float64)
    return array, numpy_to_vtk(array, deep=False)


def _output(shape):
    array = np.empty(shape, dtype=np.float64)
    return array, numpy_to_vtk(array, deep=False)


class Grid:
    """A sampled model: f as an (nz, ny, nx) array (VTK's point order), each attribute as
    (nz, ny, nx[, components]), the grid's origin and spacing, and the vtkImageData itself."""

    def __init__(self, image):
        self.image = image
        nx, ny, nz = image.GetDimensions()
        self.origin = image.GetOrigin()
        self.spacing = image.GetSpacing()
        self.dimensions = (nx, ny, nz)
        pd = image.GetPointData()
        self.f = vtk_to_numpy(pd.GetArray("f")).reshape(nz, ny, nx)
        self.attributes = {}
        for i in range(pd.GetNumberOfArrays()):
            array = pd.GetArray(i)
            if array.GetName() == "f":
                continue
            values = vtk_to_numpy(array)
            c = array.GetNumberOfComponents()
            self.attributes[array.GetName()] = values.reshape((nz, ny, nx) + ((c,) if c > 1 else ()))


class Model:
    """An FRep model (hypervolume): a registered model's name or a .hf / .xml / .vm file."""

    def __init__(self, source, parameters=(), time=0.0, threads=0):
        self._evaluator = ictkFiltersFRep.ictkFRepEvaluator()
        self._errors = _Errors(self._evaluator)
        self.source = str(source)
        if _is_model_file(self.source):
            self._evaluator.SetFileName(self.source)
        else:
            self._evaluator.SetModelName(self.source)
        self.parameters = [float(p) for p in parameters]
        if self.parameters:
            self._evaluator.SetParameters(self.parameters, len(self.parameters))
        self._evaluator.SetTime(float(time))
        self._evaluator.SetNumberOfThreads(int(threads))
        if not self._evaluator.Load():
            self._errors.raise_if_any(None)

    @property
    def name(self):
        return self._evaluator.GetName()

    @property
    def time_dependent(self):
        return bool(self._evaluator.IsTimeDependent())

    @property
    def bounds(self):
        """(xmin, xmax, ymin, ymax, zmin, zmax): a box that holds the model."""
        b = [0.0] * 6
        self._evaluator.GetBounds(b)
        return tuple(b)

    @property
    def attribute_names(self):
        """{name: components}, in the order of the model."""
        e = self._evaluator
        return {e.GetAttributeName(i): e.GetAttributeNumberOfComponents(i) for i in range(e.GetNumberOfAttributes())}

    def _run(self, method, *arrays):
        if not method(*arrays):
            self._errors.raise_if_any(None)

    def evaluate(self, points, time=None):
        """f at the points, an (N,) array (4-column points carry their own t)."""
        array, vpoints = _points(points)
        if time is not None:
            self._evaluator.SetTime(float(time))
        values, vvalues = _output(len(array))
        self._run(self._evaluator.EvaluateValues, vpoints, vvalues)
        return values

    def gradient(self, points, time=None):
        """(N, 4): df/dx, df/dy, df/dz, df/dt at the points."""
        array, vpoints = _points(points)
        if time is not None:
            self._evaluator.SetTime(float(time))
        gradients, vgradients = _output((len(array), 4))
        self._run(self._evaluator.EvaluateGradients, vpoints, vgradients, None)
        return gradients

    def attributes(self, points, time=None):
        """{name: (N,) or (N, components)}: each attribute by the hypervolume default rule."""
        array, vpoints = _points(points)
        if time is not None:
            self._evaluator.SetTime(float(time))
        width = self._evaluator.GetAttributeComponentCount()
        out, vout = _output((len(array), max(width, 1)))
        if width:
            self._run(self._evaluator.EvaluateAttributes, vpoints, vout)
        result, column = {}, 0
        for name, components in self.attribute_names.items():
            block = out[:, column:column + components]
            result[name] = block[:, 0] if components == 1 else block
            column += components
        return result

    def sample(self, dimensions=(64, 64, 64), bounds=None, time=0.0, attributes=True, double=False):
        """The model on a grid (corners included) over `bounds` (default: the model's box)."""
        sampler = ictkFiltersFRep.ictkFRepSampler()
        errors = _Errors(sampler)
        if _is_model_file(self.source):
            sampler.SetFileName(self.source)
        else:
            sampler.SetModelName(self.source)
        for p in self.parameters:
            sampler.AddParameter(p)
        sampler.SetSampleDimensions(*[int(d) for d in dimensions])
        if bounds is not None:
            sampler.SetModelBounds(*[float(b) for b in bounds])
        sampler.SetTime(float(time))
        sampler.SetComputeAttributes(bool(attributes))
        sampler.SetOutputScalarType(11 if double else 10)
        sampler.Update()
        errors.raise_if_any(sampler.GetOutput().GetNumberOfPoints() or None)
        return Grid(sampler.GetOutput())


class Complex:
    """An implicit complex (.json)."""

    def __init__(self, path, threads=0):
        self.path = str(path)
        self._source = ictkFiltersComplex.ictkComplexSource()
        self._errors = _Errors(self._source)
        self._source.SetFileName(self.path)
        self._source.SetNumberOfThreads(int(threads))
        self._source.UpdateInformation()
        self._errors.raise_if_any(self._source.GetAssembly())

    @property
    def assembly(self):
        """The vtkDataAssembly: cells by dimension and by relation."""
        return self._source.GetAssembly()

    def discretise(self, feature_size=0.0, selectors=(), volume_resolution=0):
        """The cells' discretisations as a vtkPartitionedDataSetCollection (a copy)."""
        s = self._source
        s.SetFeatureSize(float(feature_size))
        s.SetVolumeResolution(int(volume_resolution))
        s.ClearSelectors()
        for selector in selectors:
            s.AddSelector(selector)
        s.Update()
        out = s.GetOutput()
        self._errors.raise_if_any(out.GetNumberOfPartitionedDataSets() or None)
        copy = type(out)()
        copy.ShallowCopy(out)
        return copy

    discretize = discretise

    def validate(self, feature_size=0.0, tolerance=0.0):
        """The relation report: a list of {status, relation, first, second, deviation, witness, reason}."""
        validator = ictkFiltersComplex.ictkComplexValidator()
        errors = _Errors(validator)
        validator.SetInputConnection(self._source.GetOutputPort())
        validator.SetFeatureSize(float(feature_size))
        validator.SetTolerance(float(tolerance))
        validator.Update()
        table = validator.GetOutput()
        errors.raise_if_any(table.GetNumberOfColumns() or None)
        columns = {table.GetColumnName(c): table.GetColumn(c) for c in range(table.GetNumberOfColumns())}
        rows = []
        for r in range(table.GetNumberOfRows()):
            rows.append({
                "status": columns["Status"].GetValue(r),
                "relation": columns["Relation"].GetValue(r),
                "first": columns["First"].GetValue(r),
                "second": columns["Second"].GetValue(r),
                "deviation": columns["Deviation"].GetValue(r),
                "witness": columns["Witness"].GetTuple3(r),
                "reason": columns["Reason"].GetValue(r),
            })
        return rows

    def tetrahedralize(self, size, backend="tetgen", deterministic=True):
        """A labelled tetrahedral mesh (vtkUnstructuredGrid: MaterialId, CellId, attributes)."""
        mesher = ictkFiltersMesh.ictkTetrahedralize()
        errors = _Errors(mesher)
        mesher.SetInputConnection(self._source.GetOutputPort())
        mesher.SetBackend({"cgal": 0, "tetgen": 1}[backend.lower()])
        mesher.SetSize(float(size))
        mesher.SetDeterministic(bool(deterministic))
        mesher.Update()
        errors.raise_if_any(mesher.GetOutput().GetNumberOfCells() or None)
        return mesher.GetOutput()


class Frame:
    """One time of a dynamic complex: the time, the active instance, its complex as VTK data."""

    def __init__(self, time, instance, data):
        self.time, self.instance, self.data = time, instance, data


class DynamicModel:
    """A dynamic implicit complex (.icm), run by ICTK's engine."""

    def __init__(self, path, time_step=0.0, feature_size=0.0):
        self.path = str(path)
        self._source = ictkFiltersDynamics.ictkDynamicComplexSource()
        self._errors = _Errors(self._source)
        self._source.SetFileName(self.path)
        self._source.SetTimeStepSize(float(time_step))
        self._source.SetFeatureSize(float(feature_size))
        self._source.UpdateInformation()
        self._errors.raise_if_any(self._source.GetOutputInformation(0).Has(_time_steps_key()) or None)

    @property
    def time_steps(self):
        info = self._source.GetOutputInformation(0)
        return list(info.Get(_time_steps_key()))

    def frame(self, time):
        self._source.UpdateTimeStep(float(time))
        out = self._source.GetOutput()
        self._errors.raise_if_any(out.GetNumberOfPartitionedDataSets() or None)
        copy = type(out)()
        copy.ShallowCopy(out)
        return Frame(float(time), self._source.GetInstanceName(), copy)

    def frames(self, times=None):
        """Iterates the frames at `times` (default: the model's time steps), in order."""
        for t in (self.time_steps if times is None else times):
            yield self.frame(t)


def _time_steps_key():
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
    return vtkStreamingDemandDrivenPipeline.TIME_STEPS()


def _is_model_file(source):
    return os.path.splitext(source)[1].lower() in (".hf", ".xml", ".vm", ".blob")


def load(path, **options):
    """A Model (.hf, .xml, .vm, .blob or a registered model's name), a Complex (.json) or a
    DynamicModel (.icm), by the file's extension."""
    ext = os.path.splitext(str(path))[1].lower()
    if ext == ".json":
        return Complex(path, **options)
    if ext == ".icm":
        return DynamicModel(path, **options)
    if ext and ext not in (".hf", ".xml", ".vm", ".blob"):
        raise Error(f"'{path}' is not a model file ICTK reads (.hf, .xml, .vm, .blob, .json, .icm)")
    return Model(path, **options)
