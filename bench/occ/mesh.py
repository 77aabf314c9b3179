"""OpenCASCADE's tessellation of a STEP or IGES file, as STL or OBJ, in millimetres.

    mesh.py FILE -o OUT.stl|OUT.obj [--deflection D] [--angle A] [--ascii]

BRepMesh_IncrementalMesh with linear deflection D (mm; default a thousandth of the model
size, the bounding-box diagonal) and angular deflection A (degrees; default 0.5 rad,
OpenCASCADE's own default). STL through StlAPI_Writer, binary unless --ascii; OBJ written
here, one group `face_N` per face (N as in the cross-check's reports), triangles wound so
that their normals follow the face's orientation. Run with the Python that has OCP:
`bench/occ/python.sh bench/occ/mesh.py ...`.
"""

import argparse
import math
import os
import sys
import tempfile
import time

from OCP.BRep import BRep_Tool
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.StlAPI import StlAPI_Writer
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopLoc import TopLoc_Location

import occ_model

DEFAULT_DEFLECTION = 1e-3  # of the model size
DEFAULT_ANGLE = math.degrees(0.5)  # BRepMesh_IncrementalMesh's default, 0.5 rad


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("file")
    p.add_argument("-o", "--output", required=True, help="OUT.stl or OUT.obj")
    p.add_argument(
        "--deflection", type=float, help="linear deflection in mm (default 1e-3 of the model size)"
    )
    p.add_argument(
        "--angle", type=float, default=DEFAULT_ANGLE, help="angular deflection in degrees (default 28.65)"
    )
    p.add_argument("--ascii", action="store_true", help="ASCII STL (default binary)")
    args = p.parse_args()
    suffix = os.path.splitext(args.output)[1].lower()
    if suffix not in (".stl", ".obj"):
        p.error("the output must end in .stl or .obj")

    start = time.monotonic()
    log = os.path.join(tempfile.gettempdir(), f"patchtrace-occ-mesh-{os.getpid()}.log")
    try:
        with occ_model.console_to(log):
            model = occ_model.read_model(args.file)
    except occ_model.ReadError as e:
        sys.exit(f"mesh: {args.file}: {e}")
    finally:
        if os.path.exists(log):
            os.remove(log)
    deflection = args.deflection or DEFAULT_DEFLECTION * model.size
    if deflection <= 0 or args.angle <= 0:
        p.error("--deflection and --angle must be positive")
    BRepMesh_IncrementalMesh(model.shape, deflection, False, math.radians(args.angle), True)
    missing = [
        n for n, f in enumerate(model.faces, 1) if BRep_Tool.Triangulation_s(f, TopLoc_Location()) is None
    ]
    if missing:
        sys.exit(
            f"mesh: {args.file}: OpenCASCADE made no triangles for faces {missing[:20]}; nothing written"
        )

    tmp = f"{args.output}.tmp{os.getpid()}"
    try:
        if suffix == ".stl":
            writer = StlAPI_Writer()
            writer.ASCIIMode = args.ascii
            if not writer.Write(model.shape, tmp):
                sys.exit(f"mesh: StlAPI_Writer could not write {args.output}")
            triangles = sum(_triangulation(f)[0].NbTriangles() for f in model.faces)
        else:
            triangles = _write_obj(tmp, model)
        os.replace(tmp, args.output)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    print(
        f"{args.output}: {len(model.faces)} faces, {triangles} triangles, deflection {deflection:.6g} mm,"
        f" angle {args.angle:.4g} deg, {time.monotonic() - start:.2f} s"
    )


def _triangulation(face):
    location = TopLoc_Location()
    return BRep_Tool.Triangulation_s(face, location), location.Transformation()


def _write_obj(path, model):
    triangles = 0
    base = 1
    with open(path, "w") as out:
        out.write(f"# {os.path.basename(model.path)} tessellated by OpenCASCADE BRepMesh, millimetres\n")
        for number, face in enumerate(model.faces, 1):
            mesh, placement = _triangulation(face)
            out.write(f"g face_{number}\n")
            for i in range(1, mesh.NbNodes() + 1):
                x, y, z = mesh.Node(i).Transformed(placement).Coord()
                out.write(f"v {x!r} {y!r} {z!r}\n")
            reversed_ = face.Orientation() == TopAbs_REVERSED
            for i in range(1, mesh.NbTriangles() + 1):
                a, b, c = mesh.Triangle(i).Get()
                if reversed_:
                    b, c = c, b
                out.write(f"f {a + base - 1} {b + base - 1} {c + base - 1}\n")
            base += mesh.NbNodes()
            triangles += mesh.NbTriangles()
    return triangles


if __name__ == "__main__":
    main()
