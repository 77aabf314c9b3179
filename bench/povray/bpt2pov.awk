# Converts a .bpt file (patch count, then per patch "3 3" and 16 control points, u
# fastest) into POV-Ray bicubic_patch objects with the settings of BENCHMARKS.md:
# type 1 (pre-subdivided, POV-Ray's fast and memory-hungry kind), flatness 0,
# u_steps / v_steps 4 (2^4 = 16 pieces per direction, a per-ray tessellation).
NR == 1 { next }
NF == 2 { if (n > 0) print "}"; printf "bicubic_patch { type 1 flatness 0 u_steps 4 v_steps 4\n"; n = 0; next }
NF == 3 { printf "  %s<%s, %s, %s>\n", (n > 0 ? "," : ""), $1, $2, $3; n++ }
END { if (n > 0) print "}" }
