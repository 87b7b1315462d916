#!/usr/bin/env bash
# Renders a path-traced scene on a Slurm cluster: a job array whose tasks render sample ranges
# (render --sample-range A..B), and a merge job that runs once every task has succeeded.
#
#   scripts/slurm-render.sh SCENE --spp N --tasks K [--partition P] [--time T]
#       [sbatch options...] -o OUT.exr [-- render options...]
#
# sbatch options are given as --name=value (or a bare --flag), for example --account=A,
# --cpus-per-task=8, --gres=gpu:1, --mem=4G; they go to both jobs, except the CPUs and GPUs,
# which only the render tasks get. Each task gets 2 CPUs unless --cpus-per-task says otherwise,
# and runs lavapipe (the CPU's Vulkan driver, where there is no GPU) on that many threads
# (LP_NUM_THREADS). Render options after `--` (for example --width 1024 --bounces 4) go to every
# task; the samples are those of one `render SCENE --spp N` with the same options.
#
# The samples 0..N are split into K ranges that start on multiples of 16, the chunk the GPU sums
# samples in, so that the merged image equals one render of N spp (within 1e-12 relative); only
# the last range may end inside a chunk. Next to OUT.exr it writes OUT.farm/: the two job
# scripts (render.sbatch, merge.sbatch), parts/ (one checkpoint per task) and logs/. A task
# stopped before its end (its time limit, scancel) leaves its part as a checkpoint and the merge
# job is cancelled; the script prints the two commands that finish the task and merge.
#
# The render and merge programs: $ILLUM_RENDER and $ILLUM_MERGE if set, else this checkout's
# target/release/examples/ (cargo build --release --example render --example merge), else
# `render` and `merge` on PATH. The paths in the job scripts are absolute: the cluster's nodes
# must see this folder and OUT's at the same paths (a shared file system).
# --dry-run writes OUT.farm/ and prints the sbatch commands without running them.
set -euo pipefail

usage="usage: scripts/slurm-render.sh SCENE --spp N --tasks K [--partition P] [--time T] [sbatch options...] -o OUT.exr [-- render options...]"
fail() {
    echo "error: $*" >&2
    exit 2
}

# The chunk of sample indices the GPU sums (illum_pathtrace::CHUNK_SAMPLES).
chunk=16
repo="$(cd "$(dirname "$0")/.." && pwd)"

scene="" spp="" tasks="" out="" dry_run=0 cpus=""
sbatch_options=()
render_options=()
while [ $# -gt 0 ]; do
    case "$1" in
        --spp) [ $# -ge 2 ] || fail "--spp needs a value: $usage"; spp="$2"; shift 2 ;;
        --spp=*) spp="${1#*=}"; shift ;;
        --tasks) [ $# -ge 2 ] || fail "--tasks needs a value: $usage"; tasks="$2"; shift 2 ;;
        --tasks=*) tasks="${1#*=}"; shift ;;
        --partition|-p) [ $# -ge 2 ] || fail "$1 needs a value: $usage"; sbatch_options+=("--partition=$2"); shift 2 ;;
        --time|-t) [ $# -ge 2 ] || fail "$1 needs a value: $usage"; sbatch_options+=("--time=$2"); shift 2 ;;
        -o|--output) [ $# -ge 2 ] || fail "$1 needs a file name: $usage"; out="$2"; shift 2 ;;
        --output=*) out="${1#*=}"; shift ;;
        --cpus-per-task=*) cpus="${1#*=}"; shift ;;
        --dry-run) dry_run=1; shift ;;
        -h|--help) echo "$usage"; exit 0 ;;
        --) shift; render_options=("$@"); break ;;
        --array*|--dependency*|-a|-d)
            fail "$1: the script sets the array and the dependency itself" ;;
        --*) sbatch_options+=("$1"); shift ;;
        -*) fail "$1: give sbatch options as --name=value (the script cannot tell a short option's value from the scene); $usage" ;;
        *)
            [ -z "$scene" ] || fail "two scenes given ($scene and $1): $usage"
            scene="$1"; shift ;;
    esac
done

[ -n "$scene" ] || fail "no scene given: $usage"
[ -f "$scene" ] || fail "scene $scene: no such file"
[[ "$spp" =~ ^[1-9][0-9]*$ ]] || fail "--spp ${spp:-(missing)}: give a whole number of samples per pixel, at least 1"
[[ "$tasks" =~ ^[1-9][0-9]*$ ]] || fail "--tasks ${tasks:-(missing)}: give a whole number of tasks, at least 1"
[ ${#spp} -le 10 ] && [ "$spp" -le 4294967295 ] || fail "--spp $spp: at most 4294967295"
[ -n "$out" ] || fail "no output given (-o OUT.exr): $usage"
[[ "$out" == *.exr ]] || fail "-o $out: the merged render is an EXR (.exr)"
[ -z "$cpus" ] || [[ "$cpus" =~ ^[1-9][0-9]*$ ]] || fail "--cpus-per-task=$cpus: give a whole number, at least 1"
chunks=$(( (spp + chunk - 1) / chunk ))
[ "$tasks" -le "$chunks" ] ||
    fail "--tasks $tasks: $spp spp are $chunks chunks of $chunk samples, and every task needs at least one: give at most $chunks tasks"
for option in "${render_options[@]}"; do
    case "$option" in
        --spp|--spp=*|--sample-range*|--resume*|-o|--output*|--target-error*|--time-budget*|--adaptive)
            fail "render option $option: the script sets the samples, the ranges and the outputs itself" ;;
    esac
done

find_program() { # name, environment variable's value
    if [ -n "$2" ]; then
        command -v "$2" >/dev/null || fail "$2 (from ILLUM_${1^^}): not an executable program"
        realpath "$(command -v "$2")"
    elif [ -x "$repo/target/release/examples/$1" ]; then
        echo "$repo/target/release/examples/$1"
    elif command -v "$1" >/dev/null; then
        realpath "$(command -v "$1")"
    else
        fail "no $1 program: build it with \`cargo build --release --example render --example merge\` (or set ILLUM_${1^^})"
    fi
}
render=$(find_program render "${ILLUM_RENDER:-}")
merge=$(find_program merge "${ILLUM_MERGE:-}")
if [ "$dry_run" = 0 ]; then
    command -v sbatch >/dev/null || fail "sbatch not found: this script submits jobs to Slurm (--dry-run only writes them)"
fi

scene=$(realpath "$scene")
out=$(realpath -m "$out")
farm="${out%.exr}.farm"
mkdir -p "$farm/parts" "$farm/logs"
if compgen -G "$farm/parts/*.exr" >/dev/null; then
    fail "$farm/parts/ holds parts of an earlier run: merge them (sbatch $farm/merge.sbatch) or remove the folder, or choose another -o"
fi

# K ranges of whole chunks, the first (chunks mod K) one chunk longer; the last ends at N.
ranges=() starts=()
start_chunk=0
for ((i = 0; i < tasks; i++)); do
    n=$(( chunks / tasks + (i < chunks % tasks ? 1 : 0) ))
    a=$(( start_chunk * chunk ))
    b=$(( (start_chunk + n) * chunk ))
    [ "$b" -le "$spp" ] || b=$spp
    ranges+=("$a..$b")
    starts+=("$a")
    start_chunk=$(( start_chunk + n ))
done

task_options=() merge_options=()
for option in "${sbatch_options[@]}"; do
    case "$option" in
        --gres*|--gpus*|--gpu-*|--cpus-per-gpu*|--mem-per-gpu*) task_options+=("$option") ;;
        *) task_options+=("$option"); merge_options+=("$option") ;;
    esac
done
task_options+=("--cpus-per-task=${cpus:-2}")
checkpoint=(--checkpoint-seconds 600)
for option in "${render_options[@]}"; do
    case "$option" in --checkpoint-seconds*) checkpoint=() ;; esac
done

# Written to a temporary file, then renamed: a job script is whole or absent.
write() { # file; the content on standard input
    cat >"$1.tmp"
    mv "$1.tmp" "$1"
}
quoted() { [ $# -eq 0 ] || printf ' %q' "$@"; }
{
    echo "#!/bin/bash"
    echo "# Written by scripts/slurm-render.sh: task i renders the samples RANGES[i] of $(basename "$scene"), $spp spp in all."
    echo "#SBATCH --job-name=illum-render"
    echo "#SBATCH --array=0-$((tasks - 1))"
    echo "#SBATCH --output=$farm/logs/render-%A_%a.log"
    for option in "${task_options[@]}"; do echo "#SBATCH $option"; done
    echo "RANGES=(${ranges[*]})"
    echo 'RANGE=${RANGES[$SLURM_ARRAY_TASK_ID]}'
    echo "PART=$(printf %q "$farm/parts")/\${RANGE%%..*}.exr"
    echo "# lavapipe (Vulkan on the CPU, where there is no GPU): one thread per CPU of the task."
    echo 'export LP_NUM_THREADS=${LP_NUM_THREADS:-${SLURM_CPUS_PER_TASK:-2}}'
    echo "# exec: the task is the render, so that scancel --signal and the time limit's SIGTERM reach it."
    echo 'if [ -e "$PART" ]; then'
    echo "    # Stopped before (its time limit, scancel): go on from its checkpoint."
    echo "    exec$(quoted "$render" "$scene") --resume \"\$PART\" --sample-range \"\$RANGE\"$(quoted "${checkpoint[@]}" "${render_options[@]}")"
    echo "fi"
    echo "exec$(quoted "$render" "$scene") --sample-range \"\$RANGE\" -o \"\$PART\"$(quoted "${checkpoint[@]}" "${render_options[@]}")"
} | write "$farm/render.sbatch"
parts=()
for a in "${starts[@]}"; do parts+=("$farm/parts/$a.exr"); done
{
    echo "#!/bin/bash"
    echo "# Written by scripts/slurm-render.sh: merges the $tasks parts into $(basename "$out")."
    echo "#SBATCH --job-name=illum-merge"
    echo "#SBATCH --output=$farm/logs/merge-%j.log"
    for option in "${merge_options[@]}"; do echo "#SBATCH $option"; done
    echo "exec$(quoted "$merge" "${parts[@]}") -o $(printf %q "$out")"
} | write "$farm/merge.sbatch"

if [ "$dry_run" = 1 ]; then
    echo "would submit: sbatch --parsable $farm/render.sbatch"
    echo "then:         sbatch --parsable --dependency=afterok:RENDER_JOB --kill-on-invalid-dep=yes $farm/merge.sbatch"
    echo "ranges: ${ranges[*]}"
    exit 0
fi
# --parsable prints "id" or "id;cluster".
array_job=$(sbatch --parsable "$farm/render.sbatch")
array_job=${array_job%%;*}
# A task that fails (or is stopped) cancels the merge instead of leaving it pending forever.
merge_job=$(sbatch --parsable --dependency="afterok:$array_job" --kill-on-invalid-dep=yes "$farm/merge.sbatch")
merge_job=${merge_job%%;*}
echo "render job $array_job: $tasks tasks of $(basename "$scene"), samples ${ranges[*]}"
echo "merge job $merge_job: writes $out once every task has succeeded"
echo "watch:  squeue -j $array_job,$merge_job    logs: $farm/logs/"
echo "a task stopped early (time limit, scancel) keeps its checkpoint in $farm/parts/ and the merge"
echo "is cancelled; finish task I from its checkpoint, then merge:"
echo "  fix=\$(sbatch --parsable --array=I $farm/render.sbatch)"
echo "  sbatch --dependency=afterok:\$fix $farm/merge.sbatch"
