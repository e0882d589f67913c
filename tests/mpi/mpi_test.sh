#!/bin/sh
# MPI runs against serial ones (docs/cluster.md), byte for byte. Usage:
#   mpi_test.sh compare SCENE END NP...   frames/ and stats.csv of -np NP equal the serial run's, and
#                                          (NP > 1) every frame after frame 0 was written
#                                          collectively, the fluid never gathered to rank 0 (scenes
#                                          without surface meshes, which alone still gather)
#   mpi_test.sh gather SCENE END NP...    as compare with PFSPH_MPI_GATHER_FRAMES=1: every frame
#                                          gathered to rank 0, none written collectively
#   mpi_test.sh resume SCENE T1 T2 NP1 NP2 run to T1 on NP1 ranks, resume to T2 on NP2 ranks:
#                                          the same bytes as an uninterrupted serial run to T2
#   mpi_test.sh kill SCENE END NP1 NP2     kill -9 one rank of NP1 once checkpoints exist, resume on
#                                          NP2 ranks: the same bytes as an uninterrupted serial run
#   mpi_test.sh cutcheck SCENE END NP...  as compare, with the cut's coarse histogram cut to 16
#                                          buckets (every cut refined in a second round) and
#                                          checked against the dense histogram's every step
#   mpi_test.sh walls SCENE END NP...     as compare, with no slack in the wall windows (they move
#                                          every step): some rank holds fewer walls than the scene,
#                                          the root sent some windows, the fluid and walls a rank
#                                          holds stay under 1.5 N / NP + halo + walls of the scene
#   mpi_test.sh costskew SCENE END NP...  as compare, the cost cut fed a synthetic cost (half the
#                                          ranks, alternating every step, 8 times as costly: the
#                                          boundaries move by 10-30 % of the fluid every step), each cut
#                                          checked against the dense weighted one (16 coarse buckets);
#                                          every rank's owned count swung by at least 1.3x
#   mpi_test.sh diffuse SCENE END NP...   as compare, and the run made diffuse particles, some
#                                          died, and a rank other than the root held some
#   mpi_test.sh ckpt SCENE END NP...      as compare, and every checkpoint of -np NP holds the serial
#                                          run's bytes (but the stage seconds, timings, and the CRCs
#                                          over them), ranks other than the root wrote parts of it,
#                                          and the serial program loads the last one
#   mpi_test.sh refuse SCENE NP [STATUS [VAR=VALUE]]  refused or stopped with one message and exit
#                                          status STATUS (default 2) from mpirun; VAR=VALUE: set
#                                          in the environment, the message names VAR
#   mpi_test.sh collective SCENE END NP... as compare, the scene without checkpoints (no gather at
#                                          a frame: the fluid frames written collectively)
#   mpi_test.sh pieces SCENE END NP...    as collective with output.pieces: each frame's .pvtp names
#                                          NP pieces, which read back are the serial frame's particles
#   mpi_test.sh fault SCENE END NP FILE   a collective frame FILE that fails on rank 0's disk: exit
#                                          1, nothing under its name, no temporary left
# Environment: PFSPH_BIN (the program), PFSPH_MPI_BUILD (ON/OFF), PFSPH_MPIRUN (mpirun or empty).
# Exit 77 (skipped) when the build has no MPI or mpirun is missing.
set -u
[ "${PFSPH_MPI_BUILD:-OFF}" = ON ] || { echo "skipped: built without -DPFSPH_MPI=ON"; exit 77; }
MPIRUN=${PFSPH_MPIRUN:-}
[ -n "$MPIRUN" ] && [ -x "$MPIRUN" ] || { echo "skipped: no mpirun"; exit 77; }
BIN=${PFSPH_BIN:?PFSPH_BIN}
SRC=${PFSPH_SOURCE_DIR:?PFSPH_SOURCE_DIR}
ROOTOPT=""
[ "$(id -u)" = 0 ] && ROOTOPT="--allow-run-as-root"
export OMP_NUM_THREADS=1 # ranks share the machine's cores
TMP=$(mktemp -d "${TMPDIR:-/tmp}/pfsph_mpi.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
mode=$1
shift

mpi() { # NP args...
    np=$1
    shift
    "$MPIRUN" $ROOTOPT --oversubscribe -np "$np" "$BIN" "$@"
}

ckpt_same() { # A B: checkpoint files equal but for the CRC32s (bytes 33-40, 1-based) and the stage
    # seconds (wall-clock timings: 8 S bytes from byte 145, S the u32 at offset 140; docs/checkpoints.md)
    [ "$(wc -c <"$1")" = "$(wc -c <"$2")" ] || { echo "FAIL: $1 and $2 differ in length"; return 1; }
    S=$(od -An -tu4 -j140 -N4 "$1" | tr -d ' ')
    cmp -l "$1" "$2" | awk -v hi=$((144 + 8 * S)) -v a="$1" -v b="$2" '
        $1 < 33 || ($1 > 40 && $1 < 145) || $1 > hi { if (!bad) printf "FAIL: %s and %s differ at byte %d\n", a, b, $1; bad++ }
        END { exit bad > 0 }' || return 1
}

frames_path() { # DIR WANT: summary.json's frame path is WANT (collective or gather)
    fc=$(grep -Eo '"frames_written_collectively":[[:space:]]*[0-9]+' "$1/summary.json" | grep -Eo '[0-9]+$')
    fg=$(grep -Eo '"fluid_gathers":[[:space:]]*[0-9]+' "$1/summary.json" | grep -Eo '[0-9]+$')
    if [ "$2" = collective ]; then
        [ "${fc:-0}" -gt 0 ] && [ "${fg:-1}" = 0 ] ||
            { echo "FAIL: $1: not the collective path ($fc frames written collectively, $fg gathers)"; return 1; }
    else
        [ "${fc:-1}" = 0 ] && [ "${fg:-0}" -gt 0 ] ||
            { echo "FAIL: $1: not the gather ($fc frames written collectively, $fg gathers)"; return 1; }
    fi
    echo "ok: $1: $fc frames written collectively, $fg gathers"
}

same() { # DIR_A DIR_B: frames, stats.csv (and bodies.csv) byte for byte
    if ! diff -r "$1/frames" "$2/frames" >/dev/null; then
        echo "FAIL: $1/frames and $2/frames differ:"
        diff -rq "$1/frames" "$2/frames" | head -5
        return 1
    fi
    if ! cmp -s "$1/stats.csv" "$2/stats.csv"; then
        echo "FAIL: $1/stats.csv and $2/stats.csv differ:"
        diff "$1/stats.csv" "$2/stats.csv" | head -6
        return 1
    fi
    if [ -f "$1/bodies.csv" ] && ! cmp -s "$1/bodies.csv" "$2/bodies.csv"; then
        echo "FAIL: $1/bodies.csv and $2/bodies.csv differ:"
        diff "$1/bodies.csv" "$2/bodies.csv" | head -6
        return 1
    fi
    n=$(ls "$1/frames" | wc -l)
    echo "ok: $2 equals $1 ($n frame files and stats.csv)"
}

case $mode in
compare)
    scene=$SRC/$1 end=$2
    shift 2
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    for np in "$@"; do
        mpi "$np" run "$scene" -o "$TMP/np$np" --end "$end" --quiet || { echo "FAIL: -np $np exited $?"; exit 1; }
        same "$TMP/serial" "$TMP/np$np" || exit 1
        [ "$np" = 1 ] || grep -q '"ranks":' "$TMP/np$np/summary.json" ||
            { echo "FAIL: no per-rank figures in summary.json"; exit 1; }
        [ "$np" = 1 ] || frames_path "$TMP/np$np" collective || exit 1
    done
    ;;
gather)
    scene=$SRC/$1 end=$2
    shift 2
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    export PFSPH_MPI_GATHER_FRAMES=1
    for np in "$@"; do
        "$MPIRUN" $ROOTOPT --oversubscribe -x PFSPH_MPI_GATHER_FRAMES -np "$np" "$BIN" run "$scene" -o "$TMP/np$np" \
            --end "$end" --quiet || { echo "FAIL: -np $np exited $?"; exit 1; }
        same "$TMP/serial" "$TMP/np$np" || exit 1
        frames_path "$TMP/np$np" gather || exit 1
    done
    ;;
ckpt)
    scene=$SRC/$1 end=$2
    shift 2
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    nck=$(ls "$TMP/serial/checkpoints" | grep -c "^ckpt_")
    [ "$nck" -gt 0 ] || { echo "FAIL: the serial run wrote no checkpoint"; exit 1; }
    for np in "$@"; do
        mpi "$np" run "$scene" -o "$TMP/np$np" --end "$end" --quiet || { echo "FAIL: -np $np exited $?"; exit 1; }
        same "$TMP/serial" "$TMP/np$np" || exit 1
        [ "$(ls "$TMP/np$np/checkpoints")" = "$(ls "$TMP/serial/checkpoints")" ] ||
            { echo "FAIL: -np $np: checkpoints $(ls "$TMP/np$np/checkpoints" | tr '\n' ' ')"; exit 1; }
        for f in $(ls "$TMP/serial/checkpoints"); do
            ckpt_same "$TMP/serial/checkpoints/$f" "$TMP/np$np/checkpoints/$f" || exit 1
        done
        awk -F'[:,]' '/"rank":/ { r = $2 + 0 } /"checkpoint_bytes_written":/ { if (r > 0 && $2 > 0) w++ }
            END { if (!w) { print "FAIL: no rank but the root wrote a part of a checkpoint"; exit 1 }
                  printf "ok: %d ranks besides the root wrote parts of the checkpoints\n", w }' \
            "$TMP/np$np/summary.json" || exit 1
        # the serial reader checks every CRC and value of the last one (a resume with nothing to run)
        "$BIN" run --resume "$TMP/np$np" --quiet || { echo "FAIL: the serial program refuses -np $np's checkpoint"; exit 1; }
        echo "ok: -np $np: $nck checkpoints hold the serial run's bytes"
    done
    ;;
diffuse)
    scene=$SRC/$1 end=$2
    shift 2
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    live=$(grep -Eo '"diffuse":[[:space:]]*[0-9]+' "$TMP/serial/summary.json" | head -n 1 | grep -Eo '[0-9]+$')
    made=$(grep -Eo '"diffuse_created":[[:space:]]*[0-9]+' "$TMP/serial/summary.json" | grep -Eo '[0-9]+$')
    [ "${live:-0}" -gt 0 ] && [ "${made:-0}" -gt "$live" ] ||
        { echo "FAIL: the scene must make diffuse particles and see some die ($made made, $live live)"; exit 1; }
    for np in "$@"; do
        mpi "$np" run "$scene" -o "$TMP/np$np" --end "$end" --quiet || { echo "FAIL: -np $np exited $?"; exit 1; }
        same "$TMP/serial" "$TMP/np$np" || exit 1
        [ "$np" = 1 ] && continue
        awk -F'[:,]' '/"rank":/ { r = $2 + 0 } /"diffuse_held_at_frame":/ { if (r > 0) h += $2 }
            END { if (!h) { print "FAIL: only the root held diffuse particles"; exit 1 }
                  printf "ok: ranks 1.. held %d diffuse particles at the last frame\n", h }' \
            "$TMP/np$np/summary.json" || exit 1
    done
    echo "ok: $made diffuse particles made, $live live at the end"
    ;;
cutcheck)
    scene=$SRC/$1 end=$2
    shift 2
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    export PFSPH_MPI_CUT_BUCKETS=16 PFSPH_MPI_CHECK_CUT=1
    for np in "$@"; do
        "$MPIRUN" $ROOTOPT --oversubscribe -x PFSPH_MPI_CUT_BUCKETS -x PFSPH_MPI_CHECK_CUT -np "$np" "$BIN" run \
            "$scene" -o "$TMP/np$np" --end "$end" --quiet || { echo "FAIL: -np $np exited $?"; exit 1; }
        same "$TMP/serial" "$TMP/np$np" || exit 1
        grep -Eq '"reductions_last_step":[[:space:]]*2' "$TMP/np$np/summary.json" ||
            { echo "FAIL: the cut was not refined in a second round"; exit 1; }
        grep -Eq '"checked_against_dense":[[:space:]]*[1-9]' "$TMP/np$np/summary.json" ||
            { echo "FAIL: no cut was checked against the dense one"; exit 1; }
        echo "ok: -np $np: $(grep -Eo '"checked_against_dense":[[:space:]]*[0-9]+' "$TMP/np$np/summary.json")"
    done
    ;;
costskew)
    scene=$SRC/$1 end=$2
    shift 2
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    export PFSPH_MPI_COST_SKEW=8 PFSPH_MPI_CUT_BUCKETS=16 PFSPH_MPI_CHECK_CUT=1 PFSPH_MPI_CUT=cost
    for np in "$@"; do
        "$MPIRUN" $ROOTOPT --oversubscribe -x PFSPH_MPI_COST_SKEW -x PFSPH_MPI_CUT_BUCKETS -x PFSPH_MPI_CHECK_CUT \
            -x PFSPH_MPI_CUT -np "$np" "$BIN" run "$scene" -o "$TMP/np$np" --end "$end" --quiet ||
            { echo "FAIL: -np $np exited $?"; exit 1; }
        same "$TMP/serial" "$TMP/np$np" || exit 1
        grep -Eq '"weighted_cuts":[[:space:]]*[1-9]' "$TMP/np$np/summary.json" ||
            { echo "FAIL: no cut was weighted"; exit 1; }
        grep -Eq '"checked_against_dense":[[:space:]]*[1-9]' "$TMP/np$np/summary.json" ||
            { echo "FAIL: no cut was checked against the dense one"; exit 1; }
        # weights 8 and 1, each particle weighing as the rank that owned it: in the cycle this
        # settles into (a model with particles as a continuum) the owned fractions swing
        # 0.35-0.65 on 2 ranks (1.9x), on 3 ranks 0.29-0.42 at the ends (1.46x) and 0.17-0.43 in
        # the middle, on 4 ranks 3.6x to 6.6x: a boundary moves by 0.1-0.3 of all particles
        # every step. At least 1.3x for every rank (cuts fall on whole cells of a few particles);
        # the count cut: within 1 %.
        awk -v np="$np" -F'[:,]' '
            /"rank":/ { r = $2 + 0 }
            /"owned_min":/ { lo[r] = $2 + 0 }
            /"owned_max":/ { hi[r] = $2 + 0 }
            END {
                bad = 0
                for (q = 0; q < np; q++)
                    if (hi[q] < 1.3 * lo[q]) { bad = 1; printf "FAIL: rank %d owned %d to %d, not a 1.3x swing\n", q, lo[q], hi[q] }
                if (!bad) for (q = 0; q < np; q++) printf "ok: -np %d rank %d owned %d to %d\n", np, q, lo[q], hi[q]
                exit bad
            }' "$TMP/np$np/summary.json" || exit 1
    done
    ;;
walls)
    scene=$SRC/$1 end=$2
    shift 2
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    export PFSPH_MPI_WALL_SLACK=0
    for np in "$@"; do
        "$MPIRUN" $ROOTOPT --oversubscribe -x PFSPH_MPI_WALL_SLACK -np "$np" "$BIN" run \
            "$scene" -o "$TMP/np$np" --end "$end" --quiet || { echo "FAIL: -np $np exited $?"; exit 1; }
        same "$TMP/serial" "$TMP/np$np" || exit 1
        n=$(tail -n 1 "$TMP/serial/stats.csv" | cut -d, -f5)
        # per rank: walls held at most, walls of the scene, fetches, resident most, halo per step
        awk -v np="$np" -v n="$n" -F'[:,]' '
            /"rank":/ { r = $2 + 0 }
            /"walls_held_max":/ { wm[r] = $2 + 0 }
            /"walls_of_scene":/ { ws = $2 + 0 }
            /"wall_window_fetches":/ { fe += $2 }
            /"halo_particles_per_step":/ { h[r] = $2 + 0 }
            /"resident_particles_max":/ { res[r] = $2 + 0 }
            END {
                fewer = 0; bad = 0
                for (q = 1; q < np; q++) {
                    if (wm[q] < ws) fewer++
                    lim = 1.5 * n / np + 2 * h[q] + ws
                    if (res[q] > lim) { bad = 1; printf "FAIL: rank %d holds %d particles, over %d\n", q, res[q], lim }
                }
                if (!fewer) { print "FAIL: every rank holds every wall"; bad = 1 }
                if (!fe) { print "FAIL: the root sent no wall window"; bad = 1 }
                if (!bad) printf "ok: -np %d: %d ranks hold fewer walls than the %d of the scene, %d windows sent\n", np, fewer, ws, fe
                exit bad
            }' "$TMP/np$np/summary.json" || exit 1
    done
    ;;
collective | pieces)
    # the scene without a checkpoint a frame (no gather: every fluid frame written collectively
    # from the slices); pieces: also "output.pieces", each .pvtp's pieces read back and compared
    # with the serial frame (tests/mpi/pieces_check.c), the PLY frames byte for byte
    scene=$SRC/$1 end=$2
    shift 2
    sed 's/"checkpoint_interval": *[0-9]*/"checkpoint_interval": 0/' "$scene" >"$TMP/whole.json"
    grep -q '"checkpoint_interval": 0' "$TMP/whole.json" || { echo "FAIL: the scene sets no checkpoint_interval"; exit 1; }
    "$BIN" run "$TMP/whole.json" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    run=$TMP/whole.json
    if [ "$mode" = pieces ]; then
        sed 's/"output": *{/"output": {"pieces": true, /' "$TMP/whole.json" >"$TMP/pieces.json"
        run=$TMP/pieces.json
    fi
    for np in "$@"; do
        mpi "$np" run "$run" -o "$TMP/np$np" --end "$end" --quiet || { echo "FAIL: -np $np exited $?"; exit 1; }
        if ls "$TMP/np$np/frames" | grep -q '\.tmp\.'; then echo "FAIL: temporaries left"; exit 1; fi
        [ "$np" = 1 ] || grep -q 'written collectively' "$TMP/np$np/summary.json" ||
            { echo "FAIL: -np $np: the frames were not written collectively"; exit 1; }
        if [ "$mode" = collective ]; then
            same "$TMP/serial" "$TMP/np$np" || exit 1
            continue
        fi
        cmp -s "$TMP/serial/stats.csv" "$TMP/np$np/stats.csv" || { echo "FAIL: stats.csv differs"; exit 1; }
        for f in "$TMP/serial/frames/"fluid_*.ply; do
            [ -e "$f" ] || continue
            cmp -s "$f" "$TMP/np$np/frames/${f##*/}" || { echo "FAIL: -np $np: ${f##*/} differs"; exit 1; }
        done
        k=0
        for f in "$TMP/serial/frames/"fluid_*.vtp; do
            b=${f##*/}
            pv=$TMP/np$np/frames/${b%.vtp}.pvtp
            [ -f "$pv" ] || { echo "FAIL: -np $np: no ${b%.vtp}.pvtp"; exit 1; }
            want=$np # frame 0 is written before the first cut, by the root: one piece
            [ "$b" = fluid_00000.vtp ] && want=1
            [ "$(grep -c '<Piece Source=' "$pv")" = "$want" ] || { echo "FAIL: $pv names no $want pieces"; exit 1; }
            "${PFSPH_PIECES_CHECK:?PFSPH_PIECES_CHECK}" "$f" "$pv" >"$TMP/check" || { cat "$TMP/check"; exit 1; }
            grep -q "file=\"frames/${b%.vtp}.pvtp\"" "$TMP/np$np/fluid.pvd" ||
                { echo "FAIL: fluid.pvd does not list ${b%.vtp}.pvtp"; exit 1; }
            k=$((k + 1))
        done
        [ "$k" -gt 1 ] || { echo "FAIL: fewer than 2 VTP frames to compare"; exit 1; }
        echo "ok: -np $np: $k frames in $np pieces each equal the serial frames; $(tail -n 1 "$TMP/check")"
    done
    ;;
fault)
    # a collective frame that fails (the full-disk hook on rank 0, after every rank wrote its
    # part): exit status 1 with the one message, nothing under the frame's name, no temporary
    scene=$SRC/$1 end=$2 np=$3 frame=$4
    sed 's/"checkpoint_interval": *[0-9]*/"checkpoint_interval": 0/' "$scene" >"$TMP/nock.json"
    "$MPIRUN" $ROOTOPT --oversubscribe -x PFSPH_FAULT_WRITE="$frame" -np "$np" "$BIN" run "$TMP/nock.json" \
        -o "$TMP/f" --end "$end" --quiet 2>"$TMP/err"
    rc=$?
    [ "$rc" = 1 ] || { echo "FAIL: exit status $rc, not 1"; cat "$TMP/err"; exit 1; }
    grep -q "^pfsph: .*$frame: write failed: No space left on device" "$TMP/err" ||
        { echo "FAIL: no message naming $frame:"; cat "$TMP/err"; exit 1; }
    [ ! -e "$TMP/f/frames/$frame" ] || { echo "FAIL: $frame was renamed into place"; exit 1; }
    if ls "$TMP/f/frames" | grep -q '\.tmp\.'; then echo "FAIL: temporaries left"; exit 1; fi
    echo "ok: exit status 1, $frame not written, no temporary left"
    ;;
resume)
    scene=$SRC/$1 t1=$2 t2=$3 np1=$4 np2=$5
    "$BIN" run "$scene" -o "$TMP/serial" --end "$t2" --quiet || { echo "FAIL: the serial run"; exit 1; }
    mpi "$np1" run "$scene" -o "$TMP/r" --end "$t1" --quiet || { echo "FAIL: -np $np1 to $t1"; exit 1; }
    ls "$TMP/r/checkpoints" | grep -q . || { echo "FAIL: no checkpoint"; exit 1; }
    mpi "$np2" run --resume "$TMP/r" --end "$t2" --quiet || { echo "FAIL: resume on -np $np2"; exit 1; }
    grep -q '"resumed_from_frame"' "$TMP/r/summary.json" || { echo "FAIL: not resumed"; exit 1; }
    same "$TMP/serial" "$TMP/r" || exit 1
    ;;
kill)
    scene=$SRC/$1 end=$2 np1=$3 np2=$4
    "$BIN" run "$scene" -o "$TMP/serial" --end "$end" --quiet || { echo "FAIL: the serial run"; exit 1; }
    "$MPIRUN" $ROOTOPT --oversubscribe -np "$np1" "$BIN" run "$scene" -o "$TMP/k" --end "$end" --quiet \
        >"$TMP/k.log" 2>&1 &
    mpid=$!
    i=0
    while [ "$(ls "$TMP/k/checkpoints" 2>/dev/null | grep -c .)" -lt 2 ] && kill -0 $mpid 2>/dev/null; do
        sleep 0.2
        i=$((i + 1))
        [ $i -lt 1500 ] || break
    done
    victim=$(pgrep -P $mpid | tail -n 1) # the last rank mpirun started (not rank 0, which writes)
    [ -n "$victim" ] || { echo "FAIL: the run ended before it could be killed (make it longer)"; exit 1; }
    kill -9 "$victim"
    wait $mpid
    rc=$?
    [ "$rc" != 0 ] || { echo "FAIL: mpirun exited 0 after a rank was killed"; exit 1; }
    echo "killed rank pid $victim; mpirun exited $rc; checkpoints: $(ls "$TMP/k/checkpoints" | tr '\n' ' ')"
    mpi "$np2" run --resume "$TMP/k" --quiet || { echo "FAIL: resume on -np $np2"; exit 1; }
    grep -q '"resumed_from_frame"' "$TMP/k/summary.json" || { echo "FAIL: not resumed"; exit 1; }
    same "$TMP/serial" "$TMP/k" || exit 1
    ;;
refuse)
    scene=$SRC/$1 np=$2 want=${3:-2} env=${4:-}
    [ -z "$env" ] || export "${env?}" # a bad setting: the message must name the variable
    mpi "$np" run "$scene" -o "$TMP/bad" --end 0.04 --quiet 2>"$TMP/err"
    rc=$?
    [ "$rc" = "$want" ] || { echo "FAIL: exit status $rc, not $want"; cat "$TMP/err"; exit 1; }
    n=$(grep -c '^pfsph: ' "$TMP/err")
    [ "$n" = 1 ] || { echo "FAIL: $n messages, not 1:"; cat "$TMP/err"; exit 1; }
    [ -z "$env" ] || grep -q "^pfsph: ${env%%=*}: " "$TMP/err" || { echo "FAIL: the message names no ${env%%=*}"; exit 1; }
    echo "ok: exit status $rc and one message: $(grep '^pfsph: ' "$TMP/err")"
    ;;
*)
    echo "usage: mpi_test.sh compare|cutcheck|costskew|walls|collective|pieces|ckpt|resume|kill|refuse ..."
    exit 2
    ;;
esac
