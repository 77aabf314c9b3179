"""The rays of a cross-check: three kinds, about a third each.

- `inside`: aimed at a point strictly inside a face: (u, v) uniform in the face's
  parameter box, kept when OpenCASCADE's face classifier says IN. The ray comes from the
  side the face's outward normal points to, cosine-distributed about it, so that it meets
  the face rather than grazing it.
- `trimmed`: aimed at a point of a face's underlying surface that the face's trims cut
  away (classifier OUT), from the face's parameter box widened by a tenth on each side
  (holes, corners of a non-rectangular trim, a little beyond its outer loop); from either
  side, cosine-distributed about the surface normal.
- `random`: from a random point of the origin sphere toward a uniform point of the
  bounding box.

Origins lie on the sphere of radius twice the model size about the box centre, so every
origin is outside the model. Faces are drawn uniformly, so small faces (fillets, chamfers)
get as many rays as large ones; when FACES_PER_RAY faces in a row give no target (a model
of untrimmed faces has no trimmed-away points), the ray is made `random` instead, and its
kind says so. Directions are unit vectors, so `t` is a distance in mm.
Everything is drawn from one `random.Random` seeded from the seed and the file's name:
the same seed, file and OpenCASCADE version give the same rays.
"""

import math
import random
import zlib
from dataclasses import dataclass

from OCP.BRep import BRep_Tool
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepTools import BRepTools
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.gp import gp_Pnt2d
from OCP.TopAbs import TopAbs_IN, TopAbs_OUT, TopAbs_REVERSED

KINDS = ("inside", "trimmed", "random")
ORIGIN_RADIUS = 2.0  # origin sphere radius, in model sizes
TRIM_MARGIN = 0.1  # widening of the parameter box for `trimmed` targets, per side
SAMPLES_PER_FACE = 40  # (u, v) draws before another face is tried
FACES_PER_RAY = 40  # faces tried before a face-aimed ray falls back to `random`
CLASSIFIER_TOLERANCE = 1e-9  # parametric (Precision::PConfusion): IN/OUT means strictly


@dataclass
class Ray:
    origin: tuple
    direction: tuple
    kind: str
    face: int | None = None  # the face aimed at (inside/trimmed)

    def line(self):
        """The ray as a `trace` input line; repr() round-trips every f64 exactly."""
        return " ".join(repr(float(x)) for x in self.origin + self.direction)


def seed_for(seed, path_name):
    return seed * 1_000_003 + zlib.crc32(path_name.encode())


def make_rays(model, count, seed):
    rng = random.Random(seed)
    sampler = _FaceSampler(model, rng)
    counts = {"inside": round(count / 3), "trimmed": round(count / 3)}
    counts["random"] = count - counts["inside"] - counts["trimmed"]
    rays = []
    for kind in KINDS:
        for _ in range(counts[kind]):
            ray = sampler.aimed(kind) if kind != "random" else None
            rays.append(ray or _random_ray(model, rng))
    return rays


def write_rays(path, rays, comments):
    with open(path, "w") as out:
        out.writelines(f"# {c}\n" for c in comments)
        out.writelines(r.line() + "\n" for r in rays)


class _FaceSampler:
    def __init__(self, model, rng):
        self.model = model
        self.rng = rng
        self.classifier = BRepClass_FaceClassifier()
        self.radius = ORIGIN_RADIUS * model.size

    def aimed(self, kind):
        for _ in range(FACES_PER_RAY):
            number = self.rng.choice(self.model.traceable)
            face = self.model.faces[number - 1]
            surface = BRep_Tool.Surface_s(face)
            box = BRepTools.UVBounds_s(face)
            if kind == "trimmed":
                box = _widened(box, surface)
            want = TopAbs_IN if kind == "inside" else TopAbs_OUT
            for _ in range(SAMPLES_PER_FACE):
                u = self.rng.uniform(box[0], box[1])
                v = self.rng.uniform(box[2], box[3])
                self.classifier.Perform(face, gp_Pnt2d(u, v), CLASSIFIER_TOLERANCE)
                if self.classifier.State() != want:
                    continue
                ray = self._toward(face, surface, u, v, kind, number)
                if ray is not None:
                    return ray
        return None

    def _toward(self, face, surface, u, v, kind, number):
        try:
            target = surface.Value(u, v).Coord()
            props = GeomLProp_SLProps(surface, u, v, 1, 1e-9)
            normal = props.Normal().Coord() if props.IsNormalDefined() else None
        except Exception:  # a surface that cannot be evaluated there (offset at a cusp)
            return None
        if normal is None:
            w = _unit_sphere(self.rng)
        else:
            if kind == "inside":
                if face.Orientation() == TopAbs_REVERSED:
                    normal = tuple(-x for x in normal)
            elif self.rng.random() < 0.5:
                normal = tuple(-x for x in normal)
            w = _cosine_about(normal, self.rng)
        origin = _on_sphere_from(target, w, self.model.centre, self.radius)
        if origin is None:
            return None
        return Ray(origin, tuple(-x for x in w), kind, number)


def _random_ray(model, rng):
    origin = _add(model.centre, _scale(_unit_sphere(rng), ORIGIN_RADIUS * model.size))
    target = tuple(rng.uniform(a, b) for a, b in zip(model.lo, model.hi))
    return Ray(origin, _normalize(_sub(target, origin)), "random")


def _widened(box, surface):
    """The parameter box grown by TRIM_MARGIN per side, within the surface's own bounds and,
    in a periodic direction, within one period (beyond it the same points come back)."""
    u0, u1, v0, v1 = box
    su0, su1, sv0, sv1 = surface.Bounds()
    du = _margin(u1 - u0, surface.UPeriod() if surface.IsUPeriodic() else None)
    dv = _margin(v1 - v0, surface.VPeriod() if surface.IsVPeriodic() else None)
    return (max(u0 - du, su0), min(u1 + du, su1), max(v0 - dv, sv0), min(v1 + dv, sv1))


def _margin(width, period):
    m = TRIM_MARGIN * width
    return m if period is None else max(0.0, min(m, (period - width) / 2))


def _on_sphere_from(point, w, centre, radius):
    """point + s w with s > 0 on the sphere |x - centre| = radius, if point is inside it."""
    rel = _sub(point, centre)
    b = _dot(w, rel)
    c = _dot(rel, rel) - radius * radius
    if c >= 0:
        return None
    return _add(point, _scale(w, -b + math.sqrt(b * b - c)))


def _unit_sphere(rng):
    z = rng.uniform(-1.0, 1.0)
    phi = rng.uniform(0.0, 2 * math.pi)
    r = math.sqrt(max(0.0, 1 - z * z))
    return (r * math.cos(phi), r * math.sin(phi), z)


def _cosine_about(n, rng):
    """A unit vector in n's hemisphere, density proportional to the cosine with n."""
    n = _normalize(n)
    a = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    t = _normalize(_cross(n, a))
    b = _cross(n, t)
    r2 = rng.random()
    phi = rng.uniform(0.0, 2 * math.pi)
    s, c = math.sqrt(r2), math.sqrt(1 - r2)
    return _normalize(
        tuple(s * math.cos(phi) * ti + s * math.sin(phi) * bi + c * ni for ti, bi, ni in zip(t, b, n))
    )


def _add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def _scale(a, s):
    return tuple(x * s for x in a)


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _normalize(a):
    n = math.sqrt(_dot(a, a))
    return tuple(x / n for x in a)
