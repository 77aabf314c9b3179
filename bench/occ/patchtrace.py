"""patchtrace's answer to the same rays: `patchtrace trace FILE --rays RAYS -o OUT.csv`
(the `trace` contract: header `ray,hit,t,object,patch,u,v,px,py,pz,nx,ny,nz`, one row per
ray in input order, hit points in millimetres for CAD files)."""

import csv
import subprocess
import time
from dataclasses import dataclass

EXPECTED_HEADER = ["ray", "hit", "t", "object", "patch", "u", "v", "px", "py", "pz", "nx", "ny", "nz"]
REFUSED = 2  # patchtrace's exit code for input it will not read


@dataclass
class Hit:
    t: float
    point: tuple
    object: int
    patch: int
    u: float
    v: float


@dataclass
class Run:
    seconds: float
    hits: list | None  # one Hit or None per ray; None when the run failed
    error: str  # why there are no hits ("" when there are)
    stderr: str


def run(binary, cad, rays_path, csv_path, count, extra_args, timeout):
    command = [binary, "trace", cad, "--rays", rays_path, "-o", csv_path, *extra_args]
    start = time.monotonic()
    try:
        done = subprocess.run(command, check=False, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        stderr = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else e.stderr or ""
        return Run(time.monotonic() - start, None, f"patchtrace timed out after {timeout} s", stderr)
    seconds = time.monotonic() - start
    first = next((line for line in done.stderr.splitlines() if line.strip()), "")
    if done.returncode == REFUSED:
        return Run(seconds, None, f"refused: {first}", done.stderr)
    if done.returncode != 0:
        how = f"signal {-done.returncode}" if done.returncode < 0 else f"exit {done.returncode}"
        return Run(seconds, None, f"patchtrace failed ({how}): {first}", done.stderr)
    try:
        hits = read_csv(csv_path, count)
    except ValueError as e:
        return Run(seconds, None, f"patchtrace output unreadable: {e}", done.stderr)
    return Run(seconds, hits, "", done.stderr)


def read_csv(path, count):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or rows[0] != EXPECTED_HEADER:
        raise ValueError(f"header is {rows[0] if rows else 'missing'}")
    if len(rows) - 1 != count:
        raise ValueError(f"{len(rows) - 1} rows for {count} rays")
    hits = []
    for i, row in enumerate(rows[1:]):
        if int(row[0]) != i:
            raise ValueError(f"row {i + 1} is ray {row[0]}")
        if row[1] == "0":
            hits.append(None)
            continue
        t, obj, patch, u, v, px, py, pz = row[2:10]
        hits.append(
            Hit(float(t), (float(px), float(py), float(pz)), int(obj), int(patch), float(u), float(v))
        )
    return hits
