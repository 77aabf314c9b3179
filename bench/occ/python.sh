#!/bin/sh
# Runs Python with OpenCASCADE (package OCP) on the given arguments:
#   bench/occ/python.sh bench/occ/mesh.py FILE -o OUT.stl
# The interpreter is $OCC_PYTHON when set; otherwise a virtual environment kept outside
# the repository, in ${XDG_CACHE_HOME:-$HOME/.cache}/patchtrace-occ/venv, made on first
# use with `pip install cadquery-ocp-novtk numpy` (about 150 MB, needs the network once).
# Exits 3, saying why, when no such Python can be had.
set -eu
# No __pycache__ inside the repository.
export PYTHONDONTWRITEBYTECODE=1
if [ -n "${OCC_PYTHON:-}" ]; then
    if ! "$OCC_PYTHON" -c 'import OCP, numpy' 2>/dev/null; then
        echo "occ: OCC_PYTHON=$OCC_PYTHON cannot import OCP and numpy (pip install cadquery-ocp-novtk numpy)" >&2
        exit 3
    fi
    exec "$OCC_PYTHON" "$@"
fi
venv=${XDG_CACHE_HOME:-$HOME/.cache}/patchtrace-occ/venv
# `.ready` is written last: a venv whose installation was interrupted is made again.
if [ ! -f "$venv/.ready" ]; then
    if ! command -v python3 > /dev/null; then
        echo "occ: no python3 to make $venv with (or set OCC_PYTHON)" >&2
        exit 3
    fi
    echo "occ: making $venv (pip install cadquery-ocp-novtk numpy), once" >&2
    rm -rf "$venv"
    mkdir -p "$(dirname "$venv")"
    if ! { python3 -m venv "$venv" &&
        "$venv/bin/python" -m pip install --quiet --upgrade pip &&
        "$venv/bin/python" -m pip install --quiet cadquery-ocp-novtk numpy &&
        "$venv/bin/python" -c 'import OCP, numpy'; }; then
        echo "occ: could not install OpenCASCADE into $venv (or set OCC_PYTHON)" >&2
        rm -rf "$venv"
        exit 3
    fi
    touch "$venv/.ready"
fi
exec "$venv/bin/python" "$@"
