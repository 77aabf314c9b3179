"""A STEP or IGES file as OpenCASCADE reads it: its faces, in millimetres.

STEPControl_Reader / IGESControl_Reader, TransferRoots, OneShape, with OpenCASCADE's
default unit (`xstep.cascade.unit` = MM, the unit patchtrace's `trace` also reports CAD hit
points in). Faces are numbered from 1 in `TopExp::MapShapes` order over the whole shape,
so an instance placed twice counts twice; that number is the face a report names.
"""

import contextlib
import math
import os
import sys
from dataclasses import dataclass, field

from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepBndLib import BRepBndLib
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.IGESControl import IGESControl_Controller, IGESControl_Reader
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Compound

STEP_SUFFIXES = (".step", ".stp")
IGES_SUFFIXES = (".igs", ".iges")


class ReadError(Exception):
    """OpenCASCADE could not read the file, or read no faces from it."""


def is_cad_file(path):
    return path.lower().endswith(STEP_SUFFIXES + IGES_SUFFIXES)


@dataclass
class Model:
    path: str
    writer: str
    shape: object  # the whole shape read
    faces: list  # TopoDS_Face, face number i + 1
    traceable: list  # numbers of the faces with a surface (not tessellation only)
    lo: tuple
    hi: tuple
    centre: tuple = field(init=False)
    size: float = field(init=False)  # bounding-box diagonal: "the model size"

    def __post_init__(self):
        self.centre = tuple((a + b) / 2 for a, b in zip(self.lo, self.hi))
        self.size = math.dist(self.lo, self.hi)

    def traceable_shape(self):
        """A compound of the faces with a surface: what a ray can be traced against."""
        return self.shape_of(self.traceable)

    def shape_of(self, numbers):
        """A compound of the faces with these numbers."""
        return _compound(self.faces[n - 1] for n in numbers)

    def surface_type(self, number):
        kind = BRepAdaptor_Surface(self.faces[number - 1]).GetType()
        return kind.name.removeprefix("GeomAbs_")


# IGES `read.surfacecurve.mode` values: which curve of a 142 curve on surface (or 141
# boundary) OpenCASCADE builds a face's edges from.
IGES_CURVE_MODES = {"file": 0, "2d": -2, "3d": -3}


def use_iges_curves(mode):
    """Makes OpenCASCADE's IGES reader take the trim curves each file prefers ("file"), or
    force parameter-space ("2d") or model-space ("3d") ones: to check a file whose two
    representations of a boundary disagree."""
    IGESControl_Controller.Init_s()
    if not Interface_Static.SetIVal_s("read.surfacecurve.mode", IGES_CURVE_MODES[mode]):
        raise RuntimeError("OpenCASCADE has no read.surfacecurve.mode")


def read_model(path):
    """The file's faces; raises ReadError when OpenCASCADE reads none."""
    reader = _reader(path)
    status = reader.ReadFile(path)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise ReadError(f"OpenCASCADE cannot read it ({status.name})")
    writer = _writer(reader)
    if reader.TransferRoots() == 0 or reader.OneShape().IsNull():
        raise ReadError("OpenCASCADE transferred nothing from it")
    shape = reader.OneShape()
    face_map = ShapeMap()
    TopExp.MapShapes_s(shape, TopAbs_FACE, face_map)
    faces = [TopoDS.Face(face_map.FindKey(i)) for i in range(1, face_map.Extent() + 1)]
    if not faces:
        raise ReadError("OpenCASCADE read no faces from it")
    traceable = [i + 1 for i, f in enumerate(faces) if BRep_Tool.Surface_s(f) is not None]
    box = Bnd_Box()
    # The exact box of the faces' surfaces (no control polygons, no tolerance padding; not
    # the wireframe or points a file may also hold): the model size scales the
    # cross-check's thresholds. Tessellation only where there is nothing else.
    if traceable:
        BRepBndLib.AddOptimal_s(_compound(faces[n - 1] for n in traceable), box, False, False)
    else:
        BRepBndLib.AddOptimal_s(shape, box, True, False)
    lo, hi = box.CornerMin().Coord(), box.CornerMax().Coord()
    return Model(path, writer, shape, faces, traceable, lo, hi)


def _compound(shapes):
    compound = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(compound)
    for shape in shapes:
        builder.Add(compound, shape)
    return compound


@contextlib.contextmanager
def console_to(path):
    """OpenCASCADE writes its messages to the process's stdout; this sends them (and
    anything else written to file descriptors 1 and 2) to `path` for the duration."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    target = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(target, 1)
    os.dup2(target, 2)
    os.close(target)
    try:
        yield
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(saved[0])
        os.close(saved[1])


def _reader(path):
    lower = path.lower()
    if lower.endswith(STEP_SUFFIXES):
        return STEPControl_Reader()
    if lower.endswith(IGES_SUFFIXES):
        return IGESControl_Reader()
    raise ReadError(f"not a STEP or IGES file name: {os.path.basename(path)}")


def _writer(reader):
    """The writing system named in the file's header: STEP FILE_NAME originating_system
    (ISO 10303-21 §8.2.2), or the IGES Global section's parameter 5, native system ID."""
    try:
        if isinstance(reader, STEPControl_Reader):
            name = APIHeaderSection_MakeHeader(reader.StepModel()).OriginatingSystem()
        else:
            name = reader.IGESModel().GlobalSection().SystemId()
        return name.ToCString().strip() if name is not None else ""
    except Exception:  # a header OpenCASCADE could not decode names no writer
        return ""
