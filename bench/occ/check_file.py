"""One file's cross-check: read with OpenCASCADE, make the rays, answer them with
OpenCASCADE and with patchtrace, classify, and leave the evidence in the file's folder:

- rays.txt: every ray, as given to patchtrace;
- occ.csv: OpenCASCADE's answers in the `trace` CSV layout (object = face number);
- patchtrace.csv, patchtrace.stderr: patchtrace's answers and messages;
- differences.tsv: every ray on which the two disagree (near-edge ones included, marked);
- rays/ray_NNNNNN.txt: each failing ray alone, for `patchtrace trace FILE --rays ...`;
- summary.json: the row, the counts per ray kind, the settings.
"""

import collections
import json
import os
import shutil
import time

import compare
import occ_model
import patchtrace
import rays as raygen
import reference
from edges import EdgeIndex


def check(path, folder, args):
    name = os.path.basename(path)
    row = {"file": name}
    start = time.monotonic()
    try:
        model = occ_model.read_model(path)
    except occ_model.ReadError as e:
        row["note"] = str(e)
        return _finish(row, folder, {})
    read_seconds = time.monotonic() - start
    row["written by"] = model.writer
    row["faces"] = len(model.faces)
    if not model.traceable:
        row["note"] = f"OpenCASCADE cannot trace it: its {len(model.faces)} faces are tessellated only"
        return _finish(row, folder, {})
    notes = []
    if len(model.traceable) < len(model.faces):
        notes.append(f"{len(model.faces) - len(model.traceable)} faces tessellated only, not traced")

    ray_list = raygen.make_rays(model, args.rays, raygen.seed_for(args.seed, name))
    rays_path = os.path.join(folder, "rays.txt")
    raygen.write_rays(
        rays_path,
        ray_list,
        [
            f"{name}: {len(ray_list)} rays (ox oy oz dx dy dz, millimetres), seed {args.seed}",
            f"kinds in order: {dict(collections.Counter(r.kind for r in ray_list))}",
        ],
    )

    start = time.monotonic()
    tolerance = args.occ_tolerance or reference.DEFAULT_TOLERANCE
    occ = reference.Reference(model, tolerance)
    occ_hits = [occ.trace(r) for r in ray_list]
    row["OCC s"] = read_seconds + time.monotonic() - start
    normals = [occ.normal(h) if h else None for h in occ_hits]
    with open(os.path.join(folder, "occ.csv"), "w") as f:
        f.write(reference.CSV_HEADER + "\n")
        f.writelines(reference.csv_row(i, h, n) + "\n" for i, (h, n) in enumerate(zip(occ_hits, normals)))

    csv_path = os.path.join(folder, "patchtrace.csv")
    run = patchtrace.run(args.patchtrace, path, rays_path, csv_path, len(ray_list), args.pt_arg, args.timeout)
    row["patchtrace s"] = run.seconds
    with open(os.path.join(folder, "patchtrace.stderr"), "w") as f:
        f.write(run.stderr)
    if run.hits is None:
        row["note"] = "; ".join([_clip(run.error.replace(f"{path}:", f"{name}:"), 160)] + notes)
        return _finish(row, folder, {"occ_hits": sum(1 for h in occ_hits if h)})

    edges = EdgeIndex(model.faces[n - 1] for n in model.traceable)
    counts = collections.Counter()
    by_kind = collections.defaultdict(collections.Counter)
    evidence = []
    replay = os.path.join(folder, "rays")
    shutil.rmtree(replay, ignore_errors=True)
    for i, (ray, o, p) in enumerate(zip(ray_list, occ_hits, run.hits)):
        category, kind = compare.classify(o, p, model.size, edges)
        counts[category] += 1
        by_kind[ray.kind][category] += 1
        if kind is None:
            continue
        evidence.append(compare.evidence(i, category, kind, ray, o, normals[i], p, occ, edges))
        if category in compare.FAILURES:
            os.makedirs(replay, exist_ok=True)
            raygen.write_rays(
                os.path.join(replay, f"ray_{i:06d}.txt"),
                [ray],
                [
                    f"ray {i} of {name} ({ray.kind}): {category}",
                    f"patchtrace trace {path} --rays <this file>",
                ],
            )
    with open(os.path.join(folder, "differences.tsv"), "w") as f:
        f.writelines("\t".join(line) + "\n" for line in [compare.EVIDENCE_HEADER] + evidence)

    row["rays"] = len(ray_list)
    row["near edge"] = counts["near edge"]
    for failure, column in compare.FAILURES.items():
        row[column] = counts[failure]
    said = [line for line in run.stderr.splitlines() if line.strip()]
    if said:
        first = said[0].replace(f"{path}: ", "")
        more = f" (+{len(said) - 1} lines)" if len(said) > 1 else ""
        notes.append(f"patchtrace said: {_clip(first)}{more}")
    if edges.failed:
        notes.append(f"{edges.failed} edge distances OpenCASCADE could not compute")
    row["note"] = "; ".join(notes)
    detail = {
        "settings": {
            "rays": args.rays,
            "seed": args.seed,
            "patchtrace": args.patchtrace,
            "patchtrace arguments": args.pt_arg,
            "occ tolerance mm": tolerance,
            "wrong gap (model sizes)": compare.WRONG_GAP,
            "near edge (model sizes)": compare.NEAR_EDGE,
        },
        "model size mm": model.size,
        "box": [model.lo, model.hi],
        "edges": len(edges),
        "occ hits": sum(1 for h in occ_hits if h),
        "patchtrace hits": sum(1 for h in run.hits if h),
        "by ray kind": {k: dict(v) for k, v in by_kind.items()},
    }
    return _finish(row, folder, detail)


def _clip(text, limit=110):
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _finish(row, folder, detail):
    with open(os.path.join(folder, "summary.json"), "w") as f:
        json.dump({"row": row, **detail}, f, indent=1)
    return row
