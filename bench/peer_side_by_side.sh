#!/usr/bin/env bash
# Side-by-side timing of pfsph against SPlisHSPlasH (issue 13) on the peer kit's dam breaks
# (../shared/peers/splishsplash: identical fluid positions, kernel, support, viscosity).
# Runs are interleaved A B A B and each pair's ratio is printed, so load drifts cancel.
#
# usage: bench/peer_side_by_side.sh SPHSimulator KIT_DIR PFSPH [case ...]
#   KIT_DIR holds the kit's sp_*.json (with @SPL@ replaced) and pf_*.json.
#   cases: step7k step59k step493k tts7k tts59k  (default: all); REPS (default 2), THREADS (2),
#   WAIT=passive (default, the kit's setting: OMP_WAIT_POLICY=passive for both codes) or
#   WAIT=default (each program's own: libgomp's spinning for SPlisHSPlasH, pfsph's
#   GOMP_SPINCOUNT=1000).
# Per step (WCSPH, fixed dt): (wall of N steps - wall of 1 step) / (N - 1) for both codes, so
# set-up (sampling walls, SPlisHSPlasH's volume maps) is not counted.
# Time to solution: 3 s of dam break, pfsph DFSPH (its defaults) against SPlisHSPlasH DFSPH
# with Akinci walls (the kit's settings: max density error 0.05 %, divergence 0.1 %).
set -euo pipefail
SPL=$1 KIT=$2 PF=$3
shift 3
cases=${*:-step7k step59k step493k tts7k tts59k}
REPS=${REPS:-2}
if [ "${WAIT:-passive}" = passive ]; then export OMP_WAIT_POLICY=passive; else unset OMP_WAIT_POLICY GOMP_SPINCOUNT; fi
work=$(mktemp -d)
mkdir -p "$work/spl" "$work/pf"
trap 'rm -rf "$work"' EXIT

# wall seconds and peak RSS (kB) of a command, as "wall rss"
timed() {
    /usr/bin/time -f "%e %M" -o "$work/t" "$@" >"$work/log" 2>&1 || { tail -5 "$work/log" >&2; exit 1; }
    cat "$work/t"
}
spl() { # spl SCENE T THREADS
    OMP_NUM_THREADS=$3 timed "$SPL" --no-gui --stopAt "$2" --output-dir "$work/spl" "$1"
}
pf() { # pf SCENE THREADS
    OMP_NUM_THREADS=$2 timed "$PF" run "$1" -o "$work/pf" --quiet --force
}
# the pfsph DFSPH scene of a kit PCISPH scene: same geometry, DFSPH with its own defaults
dfsph_scene() {
    jq '.solver = {"type": "dfsph"}' "$1" >"$2"
}

step_case() { # step_case TAG N DT THREADS
    local tag=$1 n=$2 dt=$3 th=$4
    local tN t1
    tN=$(python3 -c "print($n * $dt)")
    t1=$dt
    for r in $(seq "$REPS"); do
        read -r sN rN < <(spl "$KIT/sp_wcsph_$tag.json" "$tN" "$th")
        read -r s1 _ < <(spl "$KIT/sp_wcsph_$tag.json" "$t1" "$th")
        read -r pN qN < <(pf "$KIT/pf_wcsph_$tag.json" "$th")
        read -r p1 _ < <(pf "$KIT/pf_wcsph_${tag}_1step.json" "$th")
        python3 - "$tag" "$n" "$th" "$sN" "$s1" "$pN" "$p1" "$rN" "$qN" <<'EOF'
import sys
tag, n, th = sys.argv[1], int(sys.argv[2]), sys.argv[3]
sN, s1, pN, p1 = map(float, sys.argv[4:8])
rs, rp = int(sys.argv[8]), int(sys.argv[9])
ss, ps = (sN - s1) / (n - 1), (pN - p1) / (n - 1)
print(f"step {tag} threads {th}: SPlisHSPlasH {1e3*ss:.2f} ms/step, pfsph {1e3*ps:.2f} ms/step, "
      f"ratio {ps/ss:.3f}; peak RSS SPL {rs/1024:.0f} MiB, pfsph {rp/1024:.0f} MiB")
EOF
    done
}

tts_case() { # tts_case TAG THREADS
    local tag=$1 th=$2
    dfsph_scene "$KIT/pf_pcisph_${tag}_3s.json" "$work/pf_dfsph_${tag}_3s.json"
    for r in $(seq "$REPS"); do
        read -r s _ < <(spl "$KIT/sp_dfsph_${tag}_akinci.json" 3 "$th")
        read -r p _ < <(pf "$work/pf_dfsph_${tag}_3s.json" "$th")
        python3 -c "print('tts $tag 3 s threads $th: SPlisHSPlasH DFSPH %.1f s, pfsph DFSPH %.1f s, ratio %.3f' % ($s, $p, $p / $s))"
    done
}

TH=${THREADS:-2}
for c in $cases; do
    case $c in
    step7k) step_case 7k 500 4e-4 1 ;;
    step59k) step_case 59k 100 2e-4 "$TH" ;;
    step493k) step_case 493k 20 1e-4 "$TH" ;;
    tts7k) tts_case 7k "$TH" ;;
    tts59k) tts_case 59k "$TH" ;;
    *) echo "unknown case $c" >&2; exit 2 ;;
    esac
done
