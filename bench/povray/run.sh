#!/bin/sh
# patchtrace against POV-Ray 3.7 (Debian package `povray`) on the teapot scenes, one
# thread each, whole process, runs interleaved so that both see the same machine load.
# Usage: bench/povray/run.sh [RUNS] [PATCHTRACE] [SIZE]   (from the repository root;
# defaults: 5, target/release/patchtrace, 512 for SIZE² images). Prints one line per run
# (wall, user, sys seconds) and the medians of wall and CPU time (user + sys); on a shared
# machine compare CPU times, wall times only when it is idle.
set -eu
runs=${1:-5}
pt=${2:-target/release/patchtrace}
size=${3:-512}
here=$(dirname "$0")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$here/common.inc" "$here/teapot.pov" "$here/glass_teapot.pov" "$work/"
awk -f "$here/bpt2pov.awk" testdata/teapot.bpt > "$work/teapot.inc"
timed() { # label, command...
    label=$1
    shift
    /usr/bin/time -f "$label %e %U %S" -a -o "$work/times" "$@" > /dev/null 2>&1
}
i=0
while [ "$i" -lt "$runs" ]; do
    for scene in teapot glass_teapot; do
        timed "$scene patchtrace" "$pt" render "testdata/$scene.ron" -o "$work/$scene.png" \
            --threads 1 --width "$size" --height "$size" -q
        (cd "$work" && timed "$scene povray" povray "+I$scene.pov" "+O$scene-pov.png" \
            +W"$size" +H"$size" +WT1 -D -V -GA +FN)
    done
    i=$((i + 1))
done
cat "$work/times"
echo "median wall / CPU (user + sys) (s):"
for key in "teapot patchtrace" "teapot povray" "glass_teapot patchtrace" "glass_teapot povray"; do
    wall=$(grep "^$key " "$work/times" | awk '{print $3}' | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    cpu=$(grep "^$key " "$work/times" | awk '{print $4 + $5}' | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    echo "$key $wall / $cpu"
done
