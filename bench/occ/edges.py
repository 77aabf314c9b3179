"""Distance from a point to the nearest boundary edge of a model's faces.

A ray whose hit lies this close to where one face ends is ambiguous: both programs may
rightly put it on either side within their tolerances. Seam edges (an edge used twice by
the same face, the closing line of a periodic surface) and degenerate edges (a pole,
no 3D curve) bound nothing in space and are left out.

Speed: every edge's box (BRepBndLib, which contains the edge) goes into one numpy array;
a query computes the distance to all boxes at once and measures exactly
(BRepExtrema_DistShapeShape, the point against the bounded edge, end points included)
only the edges whose box is within reach, nearest box first. About 1 ms per query on a
2,000-face, 5,500-edge model.
"""

import math

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS


class EdgeIndex:
    def __init__(self, faces):
        seen = ShapeMap()
        self.edges = []
        boxes = []
        for face in faces:
            explorer = TopExp_Explorer(face, TopAbs_EDGE)
            while explorer.More():
                edge = TopoDS.Edge(explorer.Current())
                explorer.Next()
                if seen.Contains(edge):
                    continue
                seen.Add(edge)
                if BRep_Tool.Degenerated_s(edge) or BRep_Tool.IsClosed_s(edge, face):
                    continue
                box = Bnd_Box()
                BRepBndLib.Add_s(edge, box)
                if box.IsVoid():  # no 3D curve: nothing in space to be near
                    continue
                self.edges.append(edge)
                boxes.append(box.CornerMin().Coord() + box.CornerMax().Coord())
        self.boxes = np.array(boxes, dtype=float).reshape(-1, 6)
        self.failed = 0  # exact distances OpenCASCADE could not compute

    def __len__(self):
        return len(self.edges)

    def nearest(self, point, reach=math.inf):
        """Distance from `point` to the nearest edge, or infinity if none is within `reach`."""
        if not self.edges:
            return math.inf
        p = np.array(point, dtype=float)
        outside = np.maximum(self.boxes[:, :3] - p, 0) + np.maximum(p - self.boxes[:, 3:], 0)
        bound = np.sqrt((outside * outside).sum(axis=1))  # no edge is nearer than its box
        vertex = BRepBuilderAPI_MakeVertex(gp_Pnt(*point)).Vertex()
        best = math.inf
        for k in np.argsort(bound):
            if bound[k] > min(best, reach):
                break
            d = BRepExtrema_DistShapeShape(vertex, self.edges[k])
            if d.IsDone():
                best = min(best, d.Value())
            else:
                self.failed += 1
        return best if best <= reach else math.inf
