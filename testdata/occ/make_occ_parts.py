from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeSphere, BRepPrimAPI_MakeTorus, BRepPrimAPI_MakeCone
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
from OCP.TopExp import TopExp_Explorer
from OCP.TopAbs import TopAbs_EDGE
from OCP.gp import gp_Pnt, gp_Ax2, gp_Dir
from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
from OCP.IGESControl import IGESControl_Writer
from OCP.Interface import Interface_Static
from OCP.TopoDS import TopoDS
import sys

box = BRepPrimAPI_MakeBox(gp_Pnt(-20,-15,0), 40, 30, 10).Shape()
hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0,0,-1), gp_Dir(0,0,1)), 6, 12).Shape()
part = BRepAlgoAPI_Cut(box, hole).Shape()
hole2 = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(13,8,-1), gp_Dir(0,0,1)), 2.5, 12).Shape()
part = BRepAlgoAPI_Cut(part, hole2).Shape()
boss = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(-12,0,10), gp_Dir(0,0,1)), 4, 6).Shape()
part = BRepAlgoAPI_Fuse(part, boss).Shape()
dome = BRepPrimAPI_MakeSphere(gp_Pnt(12,-7,10), 4).Shape()
part = BRepAlgoAPI_Fuse(part, dome).Shape()
# fillet the vertical edges of the box
f = BRepFilletAPI_MakeFillet(part)
exp = TopExp_Explorer(part, TopAbs_EDGE)
n=0
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.GeomAbs import GeomAbs_Line
seen=set()
while exp.More():
    e = TopoDS.Edge(exp.Current())
    c = BRepAdaptor_Curve(e)
    if c.GetType() == GeomAbs_Line:
        p0 = c.Value(c.FirstParameter()); p1 = c.Value(c.LastParameter())
        if abs(p0.X()-p1.X())<1e-9 and abs(p0.Y()-p1.Y())<1e-9 and abs(abs(p0.X())-20)<1e-9:
            key=(round(p0.X()),round(p0.Y()))
            if key not in seen:
                seen.add(key); f.Add(3.0, e); n+=1
    exp.Next()
part = f.Shape()
print("filleted", n)
w = STEPControl_Writer()
Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
w.Transfer(part, STEPControl_AsIs)
w.Write("/tmp/occparts/bracket_occ.step")
for mode, name in [(0,"faces"),(1,"brep")]:
    Interface_Static.SetIVal_s("write.iges.brep.mode", mode)
    iw = IGESControl_Writer("MM", mode)
    iw.AddShape(part)
    iw.ComputeModel()
    iw.Write(f"/tmp/occparts/bracket_occ_{name}.igs")
# the same part in inches, as STEP (a CONVERSION_BASED_UNIT 'INCH') and IGES faces
# (Global parameters 14, 15: 4, INCH)
Interface_Static.SetCVal_s("write.step.unit", "INCH")
w = STEPControl_Writer()
w.Transfer(part, STEPControl_AsIs)
w.Write("/tmp/occparts/bracket_occ_inch.step")
Interface_Static.SetCVal_s("write.step.unit", "MM")
iw = IGESControl_Writer("IN", 0)
iw.AddShape(part)
iw.ComputeModel()
iw.Write("/tmp/occparts/bracket_occ_inch.igs")
# a torus and a cone as their own files
t = BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(0,0,0), gp_Dir(0,0,1)), 10, 3).Shape()
c = BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(30,0,0), gp_Dir(0,0,1)), 6, 2, 8).Shape()
both = BRepAlgoAPI_Fuse(t, c).Shape()
w = STEPControl_Writer(); w.Transfer(both, STEPControl_AsIs); w.Write("/tmp/occparts/torus_cone_occ.step")
iw = IGESControl_Writer("MM", 0); iw.AddShape(both); iw.ComputeModel(); iw.Write("/tmp/occparts/torus_cone_occ.igs")
# and as an IGES B-rep (186 solids over 198 torus and 194 cone entities)
Interface_Static.SetIVal_s("write.iges.brep.mode", 1)
iw = IGESControl_Writer("MM", 1); iw.AddShape(both); iw.ComputeModel(); iw.Write("/tmp/occparts/torus_cone_occ_brep.igs")
# an assembly: the bracket used three times (XCAF components with their own locations), as
# a CAD system writes a product structure; STEP and IGES (308/408 subfigures) from it
from OCP.TDocStd import TDocStd_Document
from OCP.TCollection import TCollection_ExtendedString
from OCP.XCAFDoc import XCAFDoc_DocumentTool
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.IGESCAFControl import IGESCAFControl_Writer
from OCP.TopLoc import TopLoc_Location
from OCP.gp import gp_Trsf, gp_Vec, gp_Ax1
import math
doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
asm = tool.NewShape()
bracket = tool.AddShape(part, False)
for k, (dx, dy, angle) in enumerate([(0, 0, 0), (60, 0, 90), (0, 50, 180)]):
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(angle))
    m = gp_Trsf(); m.SetTranslation(gp_Vec(dx, dy, 0))
    tool.AddComponent(asm, bracket, TopLoc_Location(m.Multiplied(t)))
tool.UpdateAssemblies()
sw = STEPCAFControl_Writer()
sw.Transfer(doc, STEPControl_AsIs)
sw.Write("/tmp/occparts/brackets3_occ.step")
