#!/usr/bin/env bash
# Train on a bare GPU machine for a few minutes, continuing a run brought along, and hand
# back what a later machine needs to continue it: a run that spans many short GPU loans.
#
#   scripts/gpu_resume.sh train RUN MINUTES [TRAIN ARGS...]   (on the GPU machine)
#   scripts/gpu_resume.sh collect FILES RUN                   (here, after the call)
#
# train: installs the wheels in .whl/ when gymnasium is missing (the machine reaches no
# registry; see docs/guide.md for fetching them), then runs `neurosym train --device auto`
# (the GPU; the CPU where there is none, or $DEVICE)
# in RUN for MINUTES: `--resume` when RUN holds a checkpoint.pt, else a new run with TRAIN
# ARGS (e.g. --env boxworld --module predinet --algo ppo --init-from checkpoints/bw3-predinet.pt).
# Every 20 s, and at the end, the latest checkpoint (split into parts under 16 MiB),
# metrics.csv, the TensorBoard events (one tar) and train.out (the command's output) are in $OUT
# atomically, so a call cut at any minute hands back its last checkpoint (the trainer writes
# one every --checkpoint-interval seconds, 60 by default).
# collect: puts those files back into RUN (checkpoint joined, events unpacked), ready to be
# carried to the next machine with `carry: [RUN]` and trained on with the same command.
set -euo pipefail

USAGE="usage: $0 train RUN MINUTES [TRAIN ARGS...] | collect FILES RUN | --help"

usage_error() {  # MESSAGE: one line on stderr, then exit 2
    echo "$0: $1; $USAGE" >&2
    exit 2
}

names() {  # COMMAND COUNT ARGS...: the command's first COUNT arguments are names, not options
    local command=$1 count=$2 name
    shift 2
    (($# >= count)) || usage_error "$command needs $count names, got $#"
    for name in "${@:1:count}"; do
        [[ -n $name ]] || usage_error "$command: an empty name"
        [[ $name != -* ]] || usage_error "$command: $name is not a name (names come first, without '-')"
    done
}

handback() {  # RUN OUT: the run's files into OUT, each replaced whole
    local run=$1 out=$2 tmp
    tmp=$(mktemp -d "$out/.handback.XXXX")
    if [[ -f $run/checkpoint.pt ]]; then
        cp "$run/checkpoint.pt" "$tmp/ckpt"
        split -b 15M -d "$tmp/ckpt" "$tmp/checkpoint.pt.part"
        rm "$tmp/ckpt"
    fi
    [[ -f $run/metrics.csv ]] && cp "$run/metrics.csv" "$tmp/"
    [[ -d $run/tensorboard ]] && tar -cf "$tmp/tensorboard.tar" -C "$run" tensorboard
    rm -f "$out"/checkpoint.pt.part*
    mv -f "$tmp"/* "$out"/ 2>/dev/null || true
    rmdir "$tmp"
}

train() {
    names train 2 "$@"
    local run=$1 minutes=$2
    shift 2
    [[ $minutes =~ ^[0-9]+([.][0-9]+)?$ ]] && [[ ! $minutes =~ ^0+([.]0+)?$ ]] \
        || usage_error "train: MINUTES must be a positive number, got $minutes"
    : "${OUT:?OUT must name the folder that comes back (the device tool sets it)}"
    local python=${PYTHON:-python3}
    if ! "$python" -c "import gymnasium" 2>/dev/null; then
        "$python" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir \
            --upgrade --target /tmp/site .whl/*.whl
        export PYTHONPATH=/tmp/site
    fi
    export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1
    local args=(--out "$run" --minutes "$minutes" --device "${DEVICE:-auto}" --quiet)
    if [[ -f $run/checkpoint.pt ]]; then
        args+=(--resume)
    else
        mkdir -p "$(dirname "$run")"
        args+=(--tensorboard "$@")
    fi
    "$python" -m neurosym train "${args[@]}" >"$OUT/train.out" 2>&1 &
    local pid=$!
    while kill -0 "$pid" 2>/dev/null; do
        sleep 20
        [[ -d $run ]] && handback "$run" "$OUT"
    done
    local rc=0
    wait "$pid" || rc=$?
    handback "$run" "$OUT"
    cat "$OUT/train.out"
    return "$rc"
}

collect() {
    names collect 2 "$@"
    local files=$1 run=$2
    (($# == 2)) || usage_error "collect takes FILES and RUN only, got $# arguments"
    [[ -d $files ]] || { echo "$0: collect: FILES folder $files does not exist (the folder the device tool handed back)" >&2; exit 1; }
    mkdir -p "$run"
    if compgen -G "$files/checkpoint.pt.part*" >/dev/null; then
        cat "$files"/checkpoint.pt.part* >"$run/.checkpoint.pt.tmp"
        mv -f "$run/.checkpoint.pt.tmp" "$run/checkpoint.pt"
    fi
    [[ -f $files/metrics.csv ]] && cp "$files/metrics.csv" "$run/"
    [[ -f $files/tensorboard.tar ]] && tar -xf "$files/tensorboard.tar" -C "$run"
    echo "$run: $(ls "$run" | tr '\n' ' ')"
}

case ${1:-} in
    train) shift; train "$@" ;;
    collect) shift; collect "$@" ;;
    -h | --help) echo "$USAGE"; exit 0 ;;
    *) echo "$USAGE" >&2; exit 2 ;;
esac
