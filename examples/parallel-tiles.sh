#!/bin/sh
# Render one image in N tiles with GNU parallel, on this machine or over ssh (add
# `--sshloginfile hosts` to spread them; each host needs patchtrace and the scene files
# at the same path), then merge them:
#
#   examples/parallel-tiles.sh testdata/teapot.ron teapot.png 8
#
# The merged image is byte for byte the image a single `patchtrace render` writes.
set -eu

scene=${1:?usage: parallel-tiles.sh SCENE OUT.exr|OUT.png [TILES]}
out=${2:?usage: parallel-tiles.sh SCENE OUT.exr|OUT.png [TILES]}
tiles=${3:-8}
spp=${SPP:-16}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

seq 0 $((tiles - 1)) | parallel --halt now,fail=1 \
    patchtrace render "$scene" -o "$dir/tile-{}.exr" --quiet --threads 1 \
    --spp "$spp" --tile "{}/$tiles"
patchtrace merge "$dir"/tile-*.exr -o "$out"
