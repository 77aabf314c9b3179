#!/bin/sh
# patchtrace against OpenCASCADE on real STEP and IGES files (see bench/occ/README.md).
# Usage, from the repository root:
#   bench/occ/run.sh [FILES or FOLDERS...] [--rays N] [--seed S] [--patchtrace PATH] [--out DIR]
# Default folder ../shared/testdata/external/cad; default binary target/release/patchtrace.
# Python with OpenCASCADE: $OCC_PYTHON, or a cached virtual environment (python.sh).
# Exits 3 when it cannot run at all (no OpenCASCADE Python, default folder absent).
set -eu
here=$(dirname "$0")
exec "$here/python.sh" "$here/crosscheck.py" "$@"
