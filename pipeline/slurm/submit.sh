#!/usr/bin/env bash
# Submit a rodstudy design sweep to Slurm: a job array with one task per shard, then a merge job.
#
#   pipeline/slurm/submit.sh --designs DIR --out DIR --shards N [--cpus C] [--mem MB] [--time MIN]
#                            [--partition P] [--rodstudy PATH] [--wait] [-- STUDY_ARGS...]
#
# Task K of the array (K = 1..N) runs
#   rodstudy study --designs DIR --out OUT/shards/shard-K --shard K/N --jobs C STUDY_ARGS...
# (--jobs C only when STUDY_ARGS has no --jobs of its own), and the merge job, which starts
# only when every task succeeded (--dependency=afterok, cancelled otherwise), runs
#   rodstudy merge OUT/shards/shard-1 ... OUT/shards/shard-N --out OUT
#
# The jobs run in the current folder with the current environment (so a rodstudy.toml here,
# RODSTUDY_ROOT and RODSTUDY_PYTHON apply as in a one-machine study). On a real cluster the
# current folder, DIR, OUT and the rodstudy binary must be on a file system the nodes share.
#
# Bookkeeping goes to OUT/.slurm/: shard-K.out / shard-K.err (the task's output), shard-K.exit
# (the study's own exit code), merge.out / merge.err / merge.exit, jobs (the job ids).
# A task succeeds when the study wrote its results: exit 0, or 1 (some designs failed; merge
# lists them); any other code (2 = nothing studied or bad usage) fails the task, and the merge
# is then cancelled.
#
# --wait polls squeue (accounting is off on the local cluster, so no sacct) until both jobs
# are gone, and exits with the merge's status; when the merge never ran it prints the failed
# shards' errors and exits 1.
#
# Slurm: the commands use SLURM_CONF when set; when it is unset and there is no system
# configuration, the local cluster's (pipeline/slurm/local-cluster.sh) is used.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)

usage() {
    sed -n '2,5p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
    echo "(defaults: --cpus 2 --mem 4000 --time 60 --rodstudy $repo/target/release/rodstudy)" >&2
    exit "${1:-2}"
}
die() { printf 'submit: error: %s\n' "$*" >&2; exit 2; }

designs="" out="" shards="" cpus=2 mem=4000 time_min=60 partition="" wait=0
rodstudy="$repo/target/release/rodstudy"
study_args=()
while [ $# -gt 0 ]; do
    case $1 in
        --designs) designs=${2:?--designs needs a folder}; shift 2 ;;
        --out) out=${2:?--out needs a folder}; shift 2 ;;
        --shards) shards=${2:?--shards needs a number}; shift 2 ;;
        --cpus) cpus=${2:?--cpus needs a number}; shift 2 ;;
        --mem) mem=${2:?--mem needs MB}; shift 2 ;;
        --time) time_min=${2:?--time needs minutes}; shift 2 ;;
        --partition) partition=${2:?--partition needs a name}; shift 2 ;;
        --rodstudy) rodstudy=${2:?--rodstudy needs a path}; shift 2 ;;
        --wait) wait=1; shift ;;
        --) shift; study_args=("$@"); break ;;
        -h|--help) usage 0 ;;
        *) echo "submit: unknown argument: $1" >&2; usage ;;
    esac
done

if [ -z "$designs" ] || [ -z "$out" ] || [ -z "$shards" ]; then usage; fi
for v in shards cpus mem time_min; do
    [[ ${!v} =~ ^[1-9][0-9]*$ ]] || die "--${v%_min} must be a positive whole number (got '${!v}')"
done
[ -d "$designs" ] || die "no designs folder: $designs"
designs=$(cd "$designs" && pwd)
if [[ $rodstudy != */* ]]; then
    rodstudy=$(command -v "$rodstudy") || die "rodstudy not found: $rodstudy"
fi
[ -x "$rodstudy" ] || die "rodstudy not executable: $rodstudy (build it: cargo build --release)"
rodstudy=$(cd "$(dirname "$rodstudy")" && pwd)/$(basename "$rodstudy")

if ! command -v sbatch >/dev/null 2>&1; then
    cat >&2 <<EOF
submit: error: sbatch not found: Slurm's commands are not installed.
  For a one-node Slurm on this machine (installs slurm-wlm and munge with apt-get):
    $here/local-cluster.sh start
    eval "\$($here/local-cluster.sh env)"   # optional: submit.sh finds the local cluster by itself
  On a cluster: load Slurm's module or install its client commands.
EOF
    exit 2
fi
if [ -z "${SLURM_CONF:-}" ] && [ ! -e /etc/slurm/slurm.conf ] && [ ! -e /etc/slurm-llnl/slurm.conf ]; then
    local_conf="${RODSTUDY_SLURM_DIR:-/tmp/rodstudy-slurm}/slurm.conf"
    if [ -e "$local_conf" ]; then
        export SLURM_CONF="$local_conf"
        echo "submit: SLURM_CONF unset: using the local cluster's $SLURM_CONF" >&2
    else
        die "no Slurm configuration (SLURM_CONF unset, no /etc/slurm/slurm.conf): start one with $here/local-cluster.sh start"
    fi
fi

mkdir -p "$out/shards" "$out/.slurm"
out=$(cd "$out" && pwd)
meta="$out/.slurm"
# Remove the previous sweep's bookkeeping, so that --wait reads only this sweep's.
rm -f "$meta"/shard-*.out "$meta"/shard-*.err "$meta"/shard-*.exit \
      "$meta"/merge.out "$meta"/merge.err "$meta"/merge.exit "$meta"/merge.exit.tmp "$meta"/jobs

# The study's --jobs: the task's CPUs (task/none does not confine a task to them), unless given.
jobs_args=("--jobs" "\"\${SLURM_CPUS_PER_TASK:-$cpus}\"")
for a in "${study_args[@]}"; do
    case $a in --jobs|--jobs=*) jobs_args=() ;; esac
done

q() { printf '%q' "$1"; }
quoted_study_args=""
for a in "${study_args[@]}"; do quoted_study_args+=" $(q "$a")"; done

cat > "$meta/shard.sh" <<EOF
#!/usr/bin/env bash
# One shard of the sweep: written by pipeline/slurm/submit.sh, run by Slurm as task K of the array.
set -u
k=\${SLURM_ARRAY_TASK_ID:?not in a job array}
shard_out=$(q "$out")/shards/shard-\$k
mkdir -p "\$shard_out"
echo "shard \$k/$shards on \$(hostname) (job \${SLURM_JOB_ID:-?}): study into \$shard_out"
$(q "$rodstudy") study --designs $(q "$designs") --out "\$shard_out" --shard "\$k/$shards" ${jobs_args[*]}$quoted_study_args
code=\$?
echo "\$code" > $(q "$meta")/"shard-\$k.exit"
case \$code in
    0) exit 0 ;;
    1) echo "shard \$k: the study exited 1 (some designs failed; results written, merge lists them)" >&2; exit 0 ;;
    *) echo "shard \$k: the study exited \$code (no results): this shard failed" >&2; exit "\$code" ;;
esac
EOF

shard_dirs=""
for ((k = 1; k <= shards; k++)); do shard_dirs+=" $(q "$out/shards/shard-$k")"; done
cat > "$meta/merge.sh" <<EOF
#!/usr/bin/env bash
# The merge of the sweep's shards: written by pipeline/slurm/submit.sh, run by Slurm after the array.
set -u
$(q "$rodstudy") merge$shard_dirs --out $(q "$out")
code=\$?
echo "\$code" > $(q "$meta")/merge.exit.tmp && mv $(q "$meta")/merge.exit.tmp $(q "$meta")/merge.exit
exit "\$code"
EOF
chmod +x "$meta/shard.sh" "$meta/merge.sh"

# The jobs run in the folder this script is called from, with its environment (sbatch's
# defaults), as a one-machine study would: rodstudy.toml, RODSTUDY_ROOT, RODSTUDY_PYTHON apply.
common=(--parsable --time="$time_min")
[ -n "$partition" ] && common+=(--partition="$partition")

array_id=$(sbatch "${common[@]}" --job-name=rodstudy-shard --array="1-$shards" \
    --cpus-per-task="$cpus" --mem="$mem" \
    --output="$meta/shard-%a.out" --error="$meta/shard-%a.err" \
    "$meta/shard.sh") || die "sbatch of the shard array failed (see above)"
array_id=${array_id%%;*}
# The merge needs little; --kill-on-invalid-dep: a failed shard cancels it instead of
# leaving it pending forever.
merge_id=$(sbatch "${common[@]}" --job-name=rodstudy-merge --cpus-per-task=1 --mem=1000 \
    --dependency="afterok:$array_id" --kill-on-invalid-dep=yes \
    --output="$meta/merge.out" --error="$meta/merge.err" \
    "$meta/merge.sh") || { scancel "$array_id" 2>/dev/null || true; die "sbatch of the merge job failed (shard array $array_id cancelled)"; }
merge_id=${merge_id%%;*}
printf 'array %s\nmerge %s\n' "$array_id" "$merge_id" > "$meta/jobs"
echo "array job: $array_id"
echo "merge job: $merge_id"

[ "$wait" -eq 1 ] || exit 0

# Wait until neither job is queued or running. squeue lists only live jobs (-r: one line per
# array task, ID_K). A controller that does not answer 30 times in a row is an error.
# Progress goes out when it changes, at most every 10 s.
t0=$SECONDS
misses=0 last_msg="" last_print=-100
while :; do
    if listing=$(squeue -h -r -o '%i %T %r' 2>/dev/null); then
        misses=0
        ours=$(printf '%s\n' "$listing" | grep -E "^(${array_id}_[0-9]+|${merge_id}) " || true)
        [ -z "$ours" ] && break
        msg=$(printf '%s\n' "$ours" | awk -v m="$merge_id" '
            $1 == m { merge = $2 " (" $3 ")"; next }
            { n[$2]++; if ($2 == "PENDING") why[$3] = 1 }
            END {
                s = ""
                for (st in n) s = s sprintf("%s%d %s", (s == "" ? "" : ", "), n[st], tolower(st))
                w = ""; for (r in why) w = w (w == "" ? "" : ",") r
                if (w != "") s = s " (" w ")"
                printf "shards: %s; merge: %s", (s == "" ? "done" : s), (merge == "" ? "gone" : merge)
            }')
        if [ "$msg" != "$last_msg" ] && [ $((SECONDS - last_print)) -ge 10 ]; then
            echo "waiting ($((SECONDS - t0)) s): $msg"
            last_msg=$msg last_print=$SECONDS
        fi
    else
        misses=$((misses + 1))
        [ "$misses" -ge 30 ] && die "squeue has not answered for 30 s: is slurmctld running?"
    fi
    sleep 1
done
echo "sweep done in $((SECONDS - t0)) s of waiting"

tail_of() {
    local f=$1
    if [ -s "$f" ]; then
        printf -- '--- %s (last lines)\n' "$f" >&2
        tail -n 20 "$f" >&2
    fi
}

if [ -f "$meta/merge.exit" ]; then
    code=$(cat "$meta/merge.exit")
    if [ "$code" -eq 0 ]; then
        echo "merge: ok, reports in $out"
    else
        echo "merge: exited $code" >&2
        tail_of "$meta/merge.err"
    fi
    exit "$code"
fi

echo "submit: the merge did not run (cancelled: a shard failed, or the jobs were cancelled)" >&2
failed=0
for ((k = 1; k <= shards; k++)); do
    if [ -f "$meta/shard-$k.exit" ]; then
        c=$(cat "$meta/shard-$k.exit")
        case $c in 0|1) continue ;; esac
        echo "shard $k failed: the study exited $c" >&2
    else
        echo "shard $k failed: no exit code recorded (not started, cancelled, killed, or out of time/memory)" >&2
    fi
    failed=$((failed + 1))
    tail_of "$meta/shard-$k.err"
done
[ "$failed" -eq 0 ] && { echo "submit: no shard failed: the merge was cancelled from outside" >&2; tail_of "$meta/merge.err"; }
exit 1
