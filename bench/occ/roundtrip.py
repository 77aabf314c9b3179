"""One file's conversion check: `patchtrace convert` writes the file's trimmed Bézier patches
as IGES 5.3 and as OBJ free-form, and the same rays as the cross-check go through

- patchtrace on the original, on the written `.igs` and on the written `.obj`: the three
  answers must agree (a hit on one and a miss on another, or hit points farther apart than
  SAME_POINT model sizes, is a disagreement);
- OpenCASCADE on the original and on the written `.igs`: classified as the cross-check
  classifies patchtrace against OpenCASCADE (holes, false and wrong hits of the written
  file, near-edge rays apart), with OpenCASCADE's reading of the original as the reference.

Evidence in the file's folder: the written files, rays.txt, occ.csv and occ_igs.csv,
patchtrace_{original,igs,obj}.csv, differences.tsv (every ray on which any two disagree),
summary.json.
"""

import collections
import json
import math
import os
import subprocess
import time

import compare
import occ_model
import patchtrace
import rays as raygen
import reference
from edges import EdgeIndex

# Two patchtrace answers are the same hit when their points lie this close, in model sizes:
# the patches are the same after exact knot insertion; the written decimal numbers and the
# f32 search each round a little.
SAME_POINT = 1e-6

COLUMNS = [
    "file", "written by", "faces", "rays", "igs differ", "obj differ", "largest gap",
    "OCC near edge", "OCC holes", "OCC false", "OCC wrong", "convert s", "note",
]  # fmt: skip
COUNTS = ("faces", "rays", "igs differ", "obj differ", "OCC near edge", "OCC holes", "OCC false", "OCC wrong")


def check(path, folder, args):
    name = os.path.basename(path)
    stem = os.path.splitext(name)[0]
    row = {"file": name}
    try:
        model = occ_model.read_model(path)
    except occ_model.ReadError as e:
        row["note"] = str(e)
        return _finish(row, folder, {})
    row["written by"] = model.writer
    row["faces"] = len(model.faces)
    if not model.traceable:
        row["note"] = f"OpenCASCADE cannot trace it: its {len(model.faces)} faces are tessellated only"
        return _finish(row, folder, {})

    written = {ext: os.path.join(folder, f"{stem}.{ext}") for ext in ("igs", "obj")}
    start = time.monotonic()
    for out in written.values():
        command = [args.patchtrace, "convert", path, "-o", out, "-q"]
        done = subprocess.run(command, capture_output=True, text=True, timeout=args.timeout, check=False)
        if done.returncode != 0:
            first = next((line for line in done.stderr.splitlines() if line.strip()), "")
            row["note"] = f"convert to {os.path.basename(out)} failed (exit {done.returncode}): {first}"
            return _finish(row, folder, {})
    row["convert s"] = time.monotonic() - start

    ray_list = raygen.make_rays(model, args.rays, raygen.seed_for(args.seed, name))
    rays_path = os.path.join(folder, "rays.txt")
    raygen.write_rays(rays_path, ray_list, [f"{name}: {len(ray_list)} rays, seed {args.seed}"])
    row["rays"] = len(ray_list)

    answers = {}
    for label, file in (("original", path), ("igs", written["igs"]), ("obj", written["obj"])):
        csv_path = os.path.join(folder, f"patchtrace_{label}.csv")
        run = patchtrace.run(args.patchtrace, file, rays_path, csv_path, len(ray_list), args.pt_arg, args.timeout)
        if run.hits is None:
            row["note"] = f"patchtrace on the {label}: {run.error}"
            return _finish(row, folder, {})
        answers[label] = run.hits

    tolerance = args.occ_tolerance or reference.DEFAULT_TOLERANCE
    occ = reference.Reference(model, tolerance)
    occ_hits = [occ.trace(r) for r in ray_list]
    try:
        converted = occ_model.read_model(written["igs"])
    except occ_model.ReadError as e:
        row["note"] = f"OpenCASCADE on the written IGES: {e}"
        return _finish(row, folder, {})
    occ_igs_hits, thrown = _trace_robustly(converted, tolerance, ray_list)
    for label, hits in (("occ", occ_hits), ("occ_igs", occ_igs_hits)):
        with open(os.path.join(folder, f"{label}.csv"), "w") as f:
            f.write(reference.CSV_HEADER + "\n")
            f.writelines(reference.csv_row(i, h, None) + "\n" for i, h in enumerate(hits))

    differences = []
    largest = 0.0
    for label in ("igs", "obj"):
        count = 0
        for i, (a, b) in enumerate(zip(answers["original"], answers[label])):
            gap = _gap(a, b)
            if gap is not None:
                largest = max(largest, gap)
            if gap is None or gap > SAME_POINT * model.size:
                count += 1
                differences.append([str(i), f"patchtrace {label}", ray_list[i].kind, _show(a), _show(b)])
        row[f"{label} differ"] = count
    row["largest gap"] = f"{largest / model.size:.1e}"

    edges = EdgeIndex(model.faces[n - 1] for n in model.traceable)
    counts = collections.Counter()
    for i, (o, w) in enumerate(zip(occ_hits, occ_igs_hits)):
        category, kind = compare.classify(o, w, model.size, edges)
        counts[category] += 1
        if kind is not None:
            differences.append([str(i), f"OpenCASCADE igs: {category}", ray_list[i].kind, _show(o), _show(w)])
    row["OCC near edge"] = counts["near edge"]
    for failure, column in compare.FAILURES.items():
        row[f"OCC {column}"] = counts[failure]
    with open(os.path.join(folder, "differences.tsv"), "w") as f:
        header = ["ray", "between", "aimed", "reference", "written"]
        f.writelines("\t".join(line) + "\n" for line in [header, *differences])
    notes = []
    if thrown:
        notes.append(f"OpenCASCADE's intersector throws on written face(s) {sorted(thrown)}, left out")
    if len(converted.faces) != len(model.faces):
        notes.append(f"written IGES read as {len(converted.faces)} faces")
    row["note"] = "; ".join(notes)
    return _finish(row, folder, {"model size mm": model.size, "settings": {"rays": args.rays, "seed": args.seed}})


def _trace_robustly(model, tolerance, ray_list):
    """OpenCASCADE's answers on `model`, leaving out the faces on which its intersector
    throws (it does on some faces BRepCheck_Analyzer calls invalid): the hits and the
    faces left out."""
    left_out = set()
    while True:
        occ = reference.Reference(model, tolerance, left_out)
        try:
            return [occ.trace(r) for r in ray_list], left_out
        except Exception:  # OCP raises its own exception types; find the faces to blame
            pass
        before = len(left_out)
        for number in occ.traced:
            one = reference.Reference(model, tolerance, set(occ.traced) - {number})
            try:
                for r in ray_list:
                    one.trace(r)
            except Exception:
                left_out.add(number)
        if len(left_out) == before:
            raise RuntimeError("OpenCASCADE's intersector throws on the whole shape, not on any one face")


def _gap(a, b):
    """Distance between two answers' hit points; 0 when both miss, None when one misses."""
    if a is None and b is None:
        return 0.0
    if a is None or b is None:
        return None
    return math.dist(a.point, b.point)


def _show(hit):
    return "miss" if hit is None else " ".join(f"{c:.9g}" for c in hit.point)


def _finish(row, folder, detail):
    with open(os.path.join(folder, "summary.json"), "w") as f:
        json.dump({"row": row, **detail}, f, indent=1)
    return row


def markdown(rows, seconds, args):
    out = [
        f"`patchtrace convert` to IGES and OBJ, read back: {args.rays} rays per file, seed {args.seed}, "
        f"{args.patchtrace}\n\n"
    ]
    out.append("| " + " | ".join(COLUMNS) + " |\n")
    out.append("|" + "|".join("---" if c in ("file", "written by", "note") else "--:" for c in COLUMNS) + "|\n")
    for row in rows:
        cells = [f"`{row['file']}`"] + [compare.cell(row, c) for c in COLUMNS[1:]]
        out.append("| " + " | ".join(c.replace("|", "/") for c in cells) + " |\n")
    measured = [r for r in rows if "OCC wrong" in r]
    totals = {k: sum(r[k] for r in measured) for k in COUNTS}
    clean = sum(
        1 for r in measured if r["igs differ"] == r["obj differ"] == r["OCC holes"] == r["OCC false"] == r["OCC wrong"] == 0
    )
    out.append(
        f"| **total** ({len(measured)} of {len(rows)} files compared) | | "
        + " | ".join(str(totals[k]) for k in COUNTS[:4])
        + " | | "
        + " | ".join(str(totals[k]) for k in COUNTS[4:])
        + f" | | {clean} files with no difference |\n"
    )
    out.append(f"\nWhole run: {seconds:.0f} s.\n")
    return "".join(out)
