"""Classifying a ray by the two answers, with OpenCASCADE as the reference.

- hole: OpenCASCADE hits, patchtrace misses;
- false: patchtrace hits, OpenCASCADE misses;
- wrong: both hit, the hit points farther apart than WRONG_GAP model sizes;
- near edge: one of those, but a hit point involved (OpenCASCADE's, or patchtrace's for a
  false or wrong hit) lies within NEAR_EDGE model sizes of a face boundary, where either
  answer is defensible; counted apart, not as a failure;
- agree: everything else (both miss, or both hit the same point).
"""

import math

# A hit point's error budget: f32 rounds coordinates to 6e-8 of their magnitude, and hits
# the two programs agree on lie 1e-8 to 1e-6 of the model size apart; 1e-5 leaves room for
# that yet catches a face 0.015 mm out of place on a part a metre across. Along a grazing
# ray the same rounding grows by 1 / cos(incidence): differences.tsv gives the cosine.
WRONG_GAP = 1e-5
# The boundary band: both programs approximate trims (patchtrace its loops, OpenCASCADE
# within the edges' own tolerances), so a hit this close to a face's edge may rightly fall
# on either side.
NEAR_EDGE = 1e-4

# The failures, and their column in the table.
FAILURES = {"hole": "holes", "false": "false", "wrong": "wrong"}


def classify(occ, pt, size, edges):
    """(category, disagreement): category is agree / near edge / hole / false / wrong;
    disagreement is hole / false / wrong, or None when the answers agree."""
    if occ is None and pt is None:
        return "agree", None
    if pt is None:
        kind, points = "hole", [occ.point]
    elif occ is None:
        kind, points = "false", [pt.point]
    elif math.dist(occ.point, pt.point) <= WRONG_GAP * size:
        return "agree", None
    else:
        kind, points = "wrong", [occ.point, pt.point]
    band = NEAR_EDGE * size
    if any(edges.nearest(p, band) <= band for p in points):
        return "near edge", kind
    return kind, kind


EVIDENCE_HEADER = [
    "ray", "verdict", "aimed", "aimed_face", "ray_line",
    "occ_t", "occ_point", "occ_face", "occ_surface", "occ_state", "occ_edge_distance",
    "pt_t", "pt_point", "pt_object", "pt_patch", "pt_uv", "pt_edge_distance", "pt_to_occ_faces",
    "gap", "cos_incidence",
]  # fmt: skip


def evidence(index, category, kind, ray, occ, occ_normal, pt, reference, edges):
    """One row of differences.tsv: what each program answered, how far each point is from
    an edge, and how far patchtrace's point is from OpenCASCADE's faces (about 0: it hit a
    face that exists, behind or in front of OpenCASCADE's; large: geometry out of place
    or not in the file as OpenCASCADE reads it)."""

    def point(p):
        return " ".join(f"{c:.9g}" for c in p)

    def g(x):
        return f"{x:.6g}"

    row = [
        str(index),
        kind if category != "near edge" else f"near-edge {kind}",
        ray.kind,
        str(ray.face or ""),
        ray.line(),
    ]
    if occ:
        cos = abs(sum(a * b for a, b in zip(ray.direction, occ_normal))) if occ_normal else math.nan
        row += [g(occ.t), point(occ.point), str(occ.face), reference.model.surface_type(occ.face), occ.state]
        row += [g(edges.nearest(occ.point))]
    else:
        cos = math.nan
        row += [""] * 6
    if pt:
        row += [g(pt.t), point(pt.point), str(pt.object), str(pt.patch), f"{pt.u:.6g} {pt.v:.6g}"]
        row += [g(edges.nearest(pt.point)), g(reference.distance_to_shape(pt.point))]
    else:
        row += [""] * 7
    row += [g(math.dist(occ.point, pt.point)) if occ and pt else "", g(cos)]
    return row


def cell(row, key):
    """A table cell: blank for no value, floats to two decimals."""
    value = row.get(key)
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.2f}"
    return str(value)
