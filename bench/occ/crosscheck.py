"""patchtrace against OpenCASCADE on STEP and IGES files: the same rays through both,
nearest hits compared (see README.md). Run through run.sh, which provides the Python with
OpenCASCADE (package OCP).

    crosscheck.py [FILES or FOLDERS...] [--rays N] [--seed S] [--patchtrace PATH] [--out DIR]
    crosscheck.py --roundtrip ...   # `patchtrace convert` to IGES and OBJ, read back (roundtrip.py)
"""

import argparse
import multiprocessing
import os
import subprocess
import sys
import time
import traceback

import check_file  # loads OpenCASCADE once, before any fork
import compare
import occ_model
import roundtrip

DEFAULT_FOLDER = "../shared/testdata/external/cad"
COLUMNS = [
    "file", "written by", "faces", "rays", "near edge", "holes", "false", "wrong",
    "OCC s", "patchtrace s", "note",
]  # fmt: skip
UNAVAILABLE = 3  # cannot run at all (run.sh and python.sh use it too): a bench skips


def main():
    args = parse_args()
    files = cad_files(args.paths) if args.paths else default_files()
    if not os.access(args.patchtrace, os.X_OK):
        sys.exit(f"crosscheck: no patchtrace binary at {args.patchtrace} (build it: cargo build --release)")
    os.makedirs(args.out, exist_ok=True)
    check, table_of = (roundtrip.check, roundtrip.markdown) if args.roundtrip else (check_file.check, markdown)
    start = time.monotonic()
    rows = []
    for path in files:
        row = check_in_child(path, args, check)
        rows.append(row)
        print(one_line(row), flush=True)
    seconds = time.monotonic() - start
    table = table_of(rows, seconds, args)
    with open(os.path.join(args.out, "summary.md"), "w") as f:
        f.write(table)
    print()
    print(table, end="")
    print(f"\nevidence: {args.out}/<file>/differences.tsv, one-ray files in {args.out}/<file>/rays/")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("paths", nargs="*", help=f"STEP/IGES files or folders (default {DEFAULT_FOLDER})")
    p.add_argument("--rays", type=int, default=1000, help="rays per file (default 1000)")
    p.add_argument("--seed", type=int, default=1, help="ray seed (default 1); mixed with each file's name")
    p.add_argument(
        "--patchtrace", default="target/release/patchtrace", help="binary (default target/release/patchtrace)"
    )
    p.add_argument(
        "--out", default="target/occ-crosscheck", help="evidence folder (default target/occ-crosscheck)"
    )
    p.add_argument(
        "--occ-tolerance",
        type=float,
        default=None,
        help="IntCurvesFace_ShapeIntersector::Load tolerance (default 1e-7)",
    )
    p.add_argument(
        "--occ-iges-curves",
        choices=sorted(occ_model.IGES_CURVE_MODES),
        default="file",
        help="which trim curves OpenCASCADE reads from IGES 142/141 (read.surfacecurve.mode): "
        "as each file prefers (default), or parameter-space (2d) or model-space (3d) forced",
    )
    p.add_argument(
        "--timeout", type=float, default=1800, help="seconds per file for each program (default 1800)"
    )
    p.add_argument(
        "--roundtrip",
        action="store_true",
        help="check `patchtrace convert` instead: each file written as IGES and OBJ, the rays through "
        "patchtrace on all three and through OpenCASCADE on the original and the written IGES",
    )
    p.add_argument(
        "--pt-arg",
        action="append",
        default=[],
        metavar="ARG",
        help="extra argument for patchtrace trace (repeatable, e.g. --pt-arg=--precision --pt-arg=f64)",
    )
    args = p.parse_args()
    if args.rays < 1:
        p.error("--rays must be at least 1")
    return args


def default_files():
    """The files in DEFAULT_FOLDER, relative to the current directory or, in a linked git
    worktree, to the main checkout (where ../shared sits beside the repository)."""
    places = [DEFAULT_FOLDER]
    try:
        common = subprocess.run(
            ["git", "rev-parse", "--path-format=absolute", "--git-common-dir"],
            capture_output=True, text=True, check=True,
        ).stdout.strip()  # fmt: skip
        places.append(os.path.join(os.path.dirname(common), DEFAULT_FOLDER))
    except (OSError, subprocess.CalledProcessError):
        pass
    for place in places:
        if os.path.isdir(place):
            return cad_files([os.path.normpath(place)])
    print(
        f"crosscheck: the default folder {DEFAULT_FOLDER} (the real CAD files) is absent;"
        " name files or folders to check",
        file=sys.stderr,
    )
    sys.exit(UNAVAILABLE)


def cad_files(paths):
    files = []
    for path in paths:
        if os.path.isdir(path):
            found = sorted(os.path.join(path, n) for n in os.listdir(path) if occ_model.is_cad_file(n))
            if not found:
                sys.exit(f"crosscheck: no .step/.stp/.igs/.iges files in {path}")
            files += found
        elif os.path.isfile(path):
            files.append(path)
        else:
            sys.exit(f"crosscheck: no such file or folder: {path}")
    return files


def check_in_child(path, args, check):
    """Checks one file in a forked child, so that OpenCASCADE crashing on a file or
    taking too long costs that file's row, not the run. OpenCASCADE's console messages
    go to the file's occ.log."""
    name = os.path.basename(path)
    folder = os.path.join(args.out, os.path.splitext(name)[0])
    ctx = multiprocessing.get_context("fork")
    receive, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_child, args=(send, check, path, folder, args))
    child.start()
    send.close()
    row = None
    if receive.poll(2 * args.timeout + 600):
        try:
            row = receive.recv()
        except EOFError:
            pass
    else:
        child.kill()
    child.join()
    if row is None:
        how = f"signal {-child.exitcode}" if (child.exitcode or 0) < 0 else f"exit {child.exitcode}"
        row = {"file": name, "note": f"OpenCASCADE side crashed or hung ({how}); see {folder}/occ.log"}
    return row


def _child(send, check, path, folder, args):
    os.makedirs(folder, exist_ok=True)
    with occ_model.console_to(os.path.join(folder, "occ.log")):
        try:
            occ_model.use_iges_curves(args.occ_iges_curves)
            row = check(path, folder, args)
        except Exception as e:  # a bug in the checker: the row says so, the run goes on
            traceback.print_exc()
            row = {"file": os.path.basename(path), "note": f"checker error: {e!r}; see {folder}/occ.log"}
    send.send(row)
    send.close()
    os._exit(0)




def one_line(row):
    figures = " ".join(f"{k} {compare.cell(row, k)}" for k in row if k not in ("file", "written by", "note"))
    writer = row.get("written by") or "(writer unknown)"
    return "  ".join(x for x in (row["file"], writer, figures, row.get("note", "")) if x)


def markdown(rows, seconds, args):
    out = [
        f"patchtrace against OpenCASCADE: {args.rays} rays per file, seed {args.seed}, {args.patchtrace}\n\n"
    ]
    out.append("| " + " | ".join(COLUMNS) + " |\n")
    out.append(
        "|" + "|".join("---" if c in ("file", "written by", "note") else "--:" for c in COLUMNS) + "|\n"
    )
    for row in rows:
        cells = [f"`{row['file']}`"] + [compare.cell(row, c) for c in COLUMNS[1:]]
        out.append("| " + " | ".join(c.replace("|", "/") for c in cells) + " |\n")
    measured = [r for r in rows if "wrong" in r]
    totals = {
        k: sum(r[k] for r in measured) for k in ("faces", "rays", "near edge", "holes", "false", "wrong")
    }
    clean = sum(1 for r in measured if r["holes"] == r["false"] == r["wrong"] == 0)
    times = {k: sum(r.get(k) or 0.0 for r in rows) for k in ("OCC s", "patchtrace s")}
    out.append(
        f"| **total** ({len(measured)} of {len(rows)} files compared) | | {totals['faces']} | {totals['rays']}"
        f" | {totals['near edge']} | {totals['holes']} | {totals['false']} | {totals['wrong']}"
        f" | {times['OCC s']:.1f} | {times['patchtrace s']:.1f} | {clean} files with 0 / 0 / 0 |\n"
    )
    out.append(f"\nWhole run: {seconds:.0f} s.\n")
    return "".join(out)


if __name__ == "__main__":
    main()
