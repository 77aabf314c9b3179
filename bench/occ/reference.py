"""OpenCASCADE's answer to a ray: IntCurvesFace_ShapeIntersector, the exact intersection
of a line with every trimmed face (the face's surface intersected, each point classified
against the face's wires), nearest point with W in [0, +inf)."""

import math
from dataclasses import dataclass

from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.gp import gp_Dir, gp_Lin, gp_Pnt
from OCP.IntCurvesFace import IntCurvesFace_ShapeIntersector
from OCP.Precision import Precision
from OCP.TopAbs import TopAbs_REVERSED

# Precision::Confusion, OpenCASCADE's own distance below which two points are one.
DEFAULT_TOLERANCE = 1e-7

CSV_HEADER = "ray,hit,t,object,patch,u,v,px,py,pz,nx,ny,nz"


@dataclass
class Hit:
    t: float
    point: tuple
    face: int  # face number (occ_model)
    u: float  # the face surface's own parameters
    v: float
    state: str  # IN, or ON (within tolerance of the face's boundary)


class Reference:
    def __init__(self, model, tolerance=DEFAULT_TOLERANCE, leave_out=()):
        """`leave_out`: face numbers not traced (faces on which OpenCASCADE's intersector
        throws), besides the tessellated-only ones."""
        self.model = model
        self.traced = [n for n in model.traceable if n not in leave_out]
        self.numbers = ShapeMap()
        for number in self.traced:
            self.numbers.Add(model.faces[number - 1])
        self.shape = model.shape_of(self.traced)
        self.intersector = IntCurvesFace_ShapeIntersector()
        self.intersector.Load(self.shape, tolerance)

    def trace(self, ray):
        line = gp_Lin(gp_Pnt(*ray.origin), gp_Dir(*ray.direction))
        x = self.intersector
        x.Perform(line, 0.0, Precision.Infinite_s())
        if not x.IsDone() or x.NbPnt() == 0:
            return None
        i = min(range(1, x.NbPnt() + 1), key=x.WParameter)
        index = self.numbers.FindIndex(x.Face(i))
        return Hit(
            t=x.WParameter(i),
            point=x.Pnt(i).Coord(),
            face=self.traced[index - 1] if index > 0 else 0,
            u=x.UParameter(i),
            v=x.VParameter(i),
            state=x.State(i).name.removeprefix("TopAbs_"),
        )

    def distance_to_shape(self, point):
        """How far a point (patchtrace's hit) is from every face: ~0 when patchtrace hit a
        face OpenCASCADE has too, only another one than OpenCASCADE's nearest."""
        d = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*point)).Vertex(), self.shape)
        return d.Value() if d.IsDone() else math.nan

    def normal(self, hit):
        """The face's outward unit normal at the hit, or None where it is undefined."""
        face = self.model.faces[hit.face - 1]
        props = GeomLProp_SLProps(BRep_Tool.Surface_s(face), hit.u, hit.v, 1, 1e-9)
        if not props.IsNormalDefined():
            return None
        n = props.Normal().Coord()
        return tuple(-c for c in n) if face.Orientation() == TopAbs_REVERSED else n


def csv_row(index, hit, normal):
    """A row in the `trace` CSV layout: object is the OpenCASCADE face number, patch 0,
    (u, v) the face surface's own parameters."""
    if hit is None:
        return f"{index},0,,,,,,,,,,,"
    n = normal or (math.nan,) * 3
    fields = [hit.t, hit.face, 0, hit.u, hit.v, *hit.point, *n]
    return f"{index},1," + ",".join(repr(f) if isinstance(f, float) else str(f) for f in fields)
