#!/usr/bin/env python3
"""Writes the USD test stages with Pixar's own library (`pip install usd-core`).

Run from anywhere: `python3 testdata/usd/make_usd.py`. It writes, beside itself:

- `part.usda`, `part.usdc`: a referenced layer, one small trimmed bicubic NURBS patch
  under `/Part`;
- `lights.usda`: a sublayer with a distant light and a sphere light;
- `stage.usda`, `stage.usdc`: the same stage as text and as a crate file, each
  referencing the part layer of its own kind and sublayering `lights.usda`;
- `stage.usdz`: `stage.usdc` packaged with the layers it uses;
- `bad.usda`: an unclosed tuple on line 5, for the located-error test;
- `many.usda` (not kept in git, see below) only with `--many N`: N instances of the part.

The stage (z up, metres) holds:

- `/World/Trimmed`: a bicubic patch over [0, 1]^2 (z = a bump) with an outer loop (the
  domain's square, counter-clockwise) and a hole (a circle of radius 0.25 about
  (0.5, 0.5), clockwise, exact rational quadratic with homogeneous (w u, w v, w) points);
- `/World/Rational`: a quarter cylinder of radius 1 (rational quadratic in u, weights
  1, sqrt(2)/2, 1), linear in v, translated to x = 3;
- `/World/Periodic`: a closed uniform cubic B-spline tube (uForm periodic: 8 distinct
  points and the first 3 repeated, unclamped uniform knots), linear in v, at y = 3;
- `/World/Cube`: a Catmull-Clark cube (the default scheme) with one crease, at x = -3;
- `/World/Tris`: two triangles with subdivisionScheme none, at y = -3, and a quad beside
  them (x in [1, 2]) that holeIndices drops;
- `/World/Holed`: the cube again, at (-3, -3, 0), its -y face in holeIndices;
- `/World/Ranged`: a bicubic patch over knots [0, 2] x [0, 1] (two u spans) with
  uRange (0.5, 1.6) and vRange (0.2, 0.9), and a hole trimmed about (1, 0.5), at
  x in [-6, -4], y in [2, 3];
- `/World/Scatter`: a PointInstancer at y = 8 placing the trimmed patch (prototype 0)
  and the trimmed patch raised by its own translate (prototype 1) three times, by
  protoIndices, positions, orientations (half quaternions) and scales;
- `/World/ScatterF`: a PointInstancer at y = 14 placing prototype 0 once, turned by its
  float `orientationsf`, which is read instead of its half `orientations`;
- `/World/Copies/A`, `B`, `C`: instanceable prims referencing `/Part`, placed by
  translate / rotateZ / scale ops, at z = 3;
- `/World/Cam`: a camera at (0, -12, 4) looking at the origin;
- a UsdPreviewSurface material bound to `/World/Trimmed`; displayColor on the cube.
"""

import math
import os
import shutil
import sys

from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade, UsdUtils, Vt

HERE = os.path.dirname(os.path.abspath(__file__))


def path(name):
    return os.path.join(HERE, name)


def circle_loop(cu, cv, r):
    """A clockwise circle of radius r about (cu, cv): the 9-point rational quadratic
    (Piegl & Tiller 7.5), points premultiplied by their weights."""
    s = math.sqrt(0.5)
    unit = [(1, 0, 1), (1, -1, s), (0, -1, 1), (-1, -1, s), (-1, 0, 1),
            (-1, 1, s), (0, 1, 1), (1, 1, s), (1, 0, 1)]
    return [Gf.Vec3d((cu + r * x) * w, (cv + r * y) * w, w) for x, y, w in unit]


CIRCLE_KNOTS = [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4]


def trimmed_patch(stage, prim_path):
    """The bicubic bump patch with a square outer loop and a circular hole."""
    p = UsdGeom.NurbsPatch.Define(stage, prim_path)
    pts = []
    for j in range(4):
        for i in range(4):
            z = 0.6 if (i in (1, 2) and j in (1, 2)) else 0.0
            pts.append(Gf.Vec3f(i / 3.0, j / 3.0, z))
    p.CreateUVertexCountAttr(4)
    p.CreateVVertexCountAttr(4)
    p.CreateUOrderAttr(4)
    p.CreateVOrderAttr(4)
    p.CreateUKnotsAttr([0, 0, 0, 0, 1, 1, 1, 1])
    p.CreateVKnotsAttr([0, 0, 0, 0, 1, 1, 1, 1])
    p.CreateURangeAttr(Gf.Vec2d(0, 1))
    p.CreateVRangeAttr(Gf.Vec2d(0, 1))
    p.CreatePointsAttr(pts)
    # Loop 1: the square, one degree-1 curve of 5 points, counter-clockwise.
    square = [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0)]
    # Loop 2: the circle of radius 0.25 about (0.5, 0.5), clockwise.
    p.CreateTrimCurveCountsAttr([1, 1])
    p.CreateTrimCurveOrdersAttr([2, 3])
    p.CreateTrimCurveVertexCountsAttr([5, 9])
    p.CreateTrimCurveKnotsAttr([0, 0, 1, 2, 3, 4, 4] + CIRCLE_KNOTS)
    p.CreateTrimCurveRangesAttr([Gf.Vec2d(0, 4), Gf.Vec2d(0, 4)])
    p.CreateTrimCurvePointsAttr(
        [Gf.Vec3d(u, v, 1) for u, v in square] + circle_loop(0.5, 0.5, 0.25))
    return p


def ranged_patch(stage, prim_path):
    """A bicubic patch over two u spans, its uRange and vRange inside the knots' domain,
    with a hole of radius 0.2 about (1, 0.5) cut by a clockwise circle alone."""
    p = UsdGeom.NurbsPatch.Define(stage, prim_path)
    heights = [0.0, 0.5, -0.3, 0.4, 0.1]
    pts = [Gf.Vec3f(-6 + 0.5 * i, 2 + j / 3.0, heights[i] * (1 + 0.5 * j))
           for j in range(4) for i in range(5)]
    p.CreateUVertexCountAttr(5)
    p.CreateVVertexCountAttr(4)
    p.CreateUOrderAttr(4)
    p.CreateVOrderAttr(4)
    p.CreateUKnotsAttr([0, 0, 0, 0, 1, 2, 2, 2, 2])
    p.CreateVKnotsAttr([0, 0, 0, 0, 1, 1, 1, 1])
    p.CreateURangeAttr(Gf.Vec2d(0.5, 1.6))
    p.CreateVRangeAttr(Gf.Vec2d(0.2, 0.9))
    p.CreatePointsAttr(pts)
    p.CreateTrimCurveCountsAttr([1])
    p.CreateTrimCurveOrdersAttr([3])
    p.CreateTrimCurveVertexCountsAttr([9])
    p.CreateTrimCurveKnotsAttr(CIRCLE_KNOTS)
    p.CreateTrimCurveRangesAttr([Gf.Vec2d(0, 4)])
    p.CreateTrimCurvePointsAttr(circle_loop(1.0, 0.5, 0.2))
    return p


def cube_mesh(stage, prim_path, translate):
    """The unit cube's cage (the tests' Catmull-Clark reference cube), translated."""
    cube = UsdGeom.Mesh.Define(stage, prim_path)
    corners = [Gf.Vec3f(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
    cube.CreatePointsAttr(corners)
    cube.CreateFaceVertexCountsAttr([4] * 6)
    cube.CreateFaceVertexIndicesAttr(
        [0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5])
    UsdGeom.XformCommonAPI(cube).SetTranslate(Gf.Vec3d(*translate))
    return cube


def scatter(stage, prim_path):
    """A PointInstancer of the trimmed patch (prototype 0) and the same patch raised by
    its own translate (prototype 1)."""
    inst = UsdGeom.PointInstancer.Define(stage, prim_path)
    UsdGeom.XformCommonAPI(inst).SetTranslate(Gf.Vec3d(0, 8, 0))
    UsdGeom.Scope.Define(stage, f"{prim_path}/Protos")
    plain = trimmed_patch(stage, f"{prim_path}/Protos/Plain")
    raised = trimmed_patch(stage, f"{prim_path}/Protos/Raised")
    UsdGeom.XformCommonAPI(raised).SetTranslate(Gf.Vec3d(0, 0, 0.25))
    inst.CreatePrototypesRel().SetTargets([plain.GetPath(), raised.GetPath()])
    inst.CreateProtoIndicesAttr([0, 1, 0])
    inst.CreatePositionsAttr([Gf.Vec3f(0, 0, 0), Gf.Vec3f(3, 3, 0), Gf.Vec3f(6, 0, 1)])
    # Identity; 120 degrees about (1, 1, 1) (x to y, y to z, z to x); 180 degrees about
    # z. Each component is exact in half precision.
    inst.CreateOrientationsAttr([Gf.Quath(1, 0, 0, 0), Gf.Quath(0.5, 0.5, 0.5, 0.5),
                                 Gf.Quath(0, 0, 0, 1)])
    inst.CreateScalesAttr([Gf.Vec3f(1, 1, 1), Gf.Vec3f(1, 1, 1), Gf.Vec3f(2, 1, 0.5)])


def scatter_float(stage, prim_path, prototype):
    """A PointInstancer at y = 14 whose float orientationsf (120 degrees about (1, 1, 1))
    is to be read instead of its half orientations (none)."""
    inst = UsdGeom.PointInstancer.Define(stage, prim_path)
    UsdGeom.XformCommonAPI(inst).SetTranslate(Gf.Vec3d(0, 14, 0))
    inst.CreatePrototypesRel().SetTargets([prototype])
    inst.CreateProtoIndicesAttr([0])
    inst.CreatePositionsAttr([Gf.Vec3f(0, 0, 0)])
    inst.CreateOrientationsAttr([Gf.Quath(1, 0, 0, 0)])
    inst.CreateOrientationsfAttr([Gf.Quatf(0.5, 0.5, 0.5, 0.5)])


def build_part(fmt):
    stage = Usd.Stage.CreateNew(path(f"part.{fmt}"))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/Part")
    stage.SetDefaultPrim(root.GetPrim())
    trimmed_patch(stage, "/Part/Patch")
    stage.GetRootLayer().Save()


def build_lights():
    stage = Usd.Stage.CreateNew(path("lights.usda"))
    sun = UsdLux.DistantLight.Define(stage, "/World/Sun")
    sun.CreateIntensityAttr(2.0)
    sun.CreateColorAttr(Gf.Vec3f(1.0, 0.9, 0.8))
    # The light shines down its local -z axis; tilt it.
    UsdGeom.XformCommonAPI(sun).SetRotate(Gf.Vec3f(30, 0, 0))
    bulb = UsdLux.SphereLight.Define(stage, "/World/Bulb")
    bulb.CreateIntensityAttr(5.0)
    bulb.CreateRadiusAttr(0.1)
    UsdGeom.XformCommonAPI(bulb).SetTranslate(Gf.Vec3d(4, -4, 6))
    stage.GetRootLayer().Save()


def build_stage(fmt):
    stage = Usd.Stage.CreateNew(path(f"stage.{fmt}"))
    stage.GetRootLayer().subLayerPaths.append("./lights.usda")
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())

    trimmed = trimmed_patch(stage, "/World/Trimmed")

    # Quarter cylinder: u rational quadratic (angle 0..90 degrees), v linear (z 0..1).
    r = UsdGeom.NurbsPatch.Define(stage, "/World/Rational")
    s = math.sqrt(0.5)
    arc = [(1, 0, 1), (1, 1, s), (0, 1, 1)]
    pts, wts = [], []
    for z in (0.0, 1.0):
        for x, y, w in arc:
            pts.append(Gf.Vec3f(x, y, z))
            wts.append(w)
    r.CreateUVertexCountAttr(3)
    r.CreateVVertexCountAttr(2)
    r.CreateUOrderAttr(3)
    r.CreateVOrderAttr(2)
    r.CreateUKnotsAttr([0, 0, 0, 1, 1, 1])
    r.CreateVKnotsAttr([0, 0, 1, 1])
    r.CreatePointsAttr(pts)
    r.CreatePointWeightsAttr(wts)
    UsdGeom.XformCommonAPI(r).SetTranslate(Gf.Vec3d(3, 0, 0))

    # Periodic tube: 8 points on a circle of radius 1, the first 3 repeated (order 4).
    pr = UsdGeom.NurbsPatch.Define(stage, "/World/Periodic")
    ring = [(math.cos(2 * math.pi * k / 8), math.sin(2 * math.pi * k / 8)) for k in range(8)]
    ring = ring + ring[:3]
    pts = [Gf.Vec3f(x, y, z) for z in (0.0, 1.0) for x, y in ring]
    pr.CreateUVertexCountAttr(11)
    pr.CreateVVertexCountAttr(2)
    pr.CreateUOrderAttr(4)
    pr.CreateVOrderAttr(2)
    pr.CreateUKnotsAttr([float(k) for k in range(-3, 12)])
    pr.CreateVKnotsAttr([0, 0, 1, 1])
    pr.CreateUFormAttr(UsdGeom.Tokens.periodic)
    pr.CreateURangeAttr(Gf.Vec2d(0, 8))
    pr.CreatePointsAttr(pts)
    UsdGeom.XformCommonAPI(pr).SetTranslate(Gf.Vec3d(0, 3, 0))

    cube = cube_mesh(stage, "/World/Cube", (-3, 0, 0))
    cube.CreateCreaseIndicesAttr([4, 5])
    cube.CreateCreaseLengthsAttr([2])
    cube.CreateCreaseSharpnessesAttr([2.0])
    cube.CreateDisplayColorAttr([Gf.Vec3f(0.2, 0.4, 0.9)])

    # Face 2, (0, 1, 5, 4), is the cube's -y side.
    cube_mesh(stage, "/World/Holed", (-3, -3, 0)).CreateHoleIndicesAttr([2])

    tris = UsdGeom.Mesh.Define(stage, "/World/Tris")
    tris.CreatePointsAttr([Gf.Vec3f(0, 0, 0), Gf.Vec3f(1, 0, 0), Gf.Vec3f(1, 0, 1), Gf.Vec3f(0, 0, 1),
                           Gf.Vec3f(2, 0, 0), Gf.Vec3f(2, 0, 1)])
    tris.CreateFaceVertexCountsAttr([3, 3, 4])
    tris.CreateFaceVertexIndicesAttr([0, 1, 2, 0, 2, 3, 1, 4, 5, 2])
    tris.CreateHoleIndicesAttr([2])
    tris.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    UsdGeom.XformCommonAPI(tris).SetTranslate(Gf.Vec3d(0, -3, 0))

    ranged_patch(stage, "/World/Ranged")
    scatter(stage, "/World/Scatter")
    scatter_float(stage, "/World/ScatterF", "/World/Scatter/Protos/Plain")

    UsdGeom.Xform.Define(stage, "/World/Copies")
    placements = {
        "A": ((0, 0, 3), 0, 1.0),
        "B": ((2, 0, 3), 90, 1.0),
        "C": ((4, 0, 3), 0, 2.0),
    }
    for name, (t, rz, sc) in placements.items():
        x = UsdGeom.Xform.Define(stage, f"/World/Copies/{name}")
        x.GetPrim().GetReferences().AddReference(f"./part.{fmt}")
        x.GetPrim().SetInstanceable(True)
        x.AddTranslateOp().Set(Gf.Vec3d(*t))
        x.AddRotateZOp().Set(rz)
        x.AddScaleOp().Set(Gf.Vec3f(sc, sc, sc))

    cam = UsdGeom.Camera.Define(stage, "/World/Cam")
    cam.CreateFocalLengthAttr(35.0)
    cam.CreateHorizontalApertureAttr(36.0)
    cam.CreateVerticalApertureAttr(24.0)
    # A USD camera looks down its local -z with +y up: turn it to look along +y from
    # (0, -12, 4), then tilt it down toward the origin.
    tilt = math.degrees(math.atan2(4, 12))
    xf = UsdGeom.Xformable(cam)
    xf.AddTranslateOp().Set(Gf.Vec3d(0, -12, 4))
    xf.AddRotateXOp().Set(90 - tilt)

    mat = UsdShade.Material.Define(stage, "/World/Looks/Red")
    shader = UsdShade.Shader.Define(stage, "/World/Looks/Red/Surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.8, 0.1, 0.1))
    shader.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.3)
    shader.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(1.0)
    shader.CreateInput("ior", Sdf.ValueTypeNames.Float).Set(1.5)
    mat.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(trimmed.GetPrim()).Bind(mat)

    stage.GetRootLayer().Save()


def build_many(n):
    """`n` instanceable references to the part on a grid: the shared-instance measure."""
    stage = Usd.Stage.CreateNew(path("many.usda"))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    side = math.ceil(math.sqrt(n))
    for k in range(n):
        x = UsdGeom.Xform.Define(stage, f"/World/P{k}")
        x.GetPrim().GetReferences().AddReference("./part.usda")
        x.GetPrim().SetInstanceable(True)
        x.AddTranslateOp().Set(Gf.Vec3d(1.5 * (k % side), 1.5 * (k // side), 0))
    stage.GetRootLayer().Save()


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--many":
        build_many(int(sys.argv[2]))
        return
    for name in ("part.usda", "part.usdc", "lights.usda", "stage.usda", "stage.usdc", "stage.usdz"):
        if os.path.exists(path(name)):
            os.remove(path(name))
    build_part("usda")
    build_part("usdc")
    build_lights()
    build_stage("usda")
    build_stage("usdc")
    # The package holds stage.usdc and the layers it uses, paths rewritten inside it.
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(path("stage.usdc")), path("stage.usdz"))
    with open(path("bad.usda"), "w") as f:
        f.write('#usda 1.0\n\ndef Xform "World"\n{\n    double3 xformOp:translate = (1, 2\n}\n')


if __name__ == "__main__":
    main()
