#!/usr/bin/env bash
# A sweep on the local one-node Slurm, end to end (for CI): start the cluster, submit the
# sweep and wait for it, stop the cluster again (also on failure), exit with the sweep's status.
#
#   pipeline/slurm/test-sweep.sh DESIGNS OUT [SUBMIT_OPTIONS...] [-- STUDY_ARGS...]
#
# runs   pipeline/slurm/submit.sh --designs DESIGNS --out OUT --shards 2 --cpus 1 --mem 2000 --wait \
#            SUBMIT_OPTIONS... -- STUDY_ARGS...
# SUBMIT_OPTIONS come after the defaults, so they override them (e.g. --shards 4, --rodstudy PATH);
# STUDY_ARGS default to --skip-fem when no `--` is given.
# A cluster that was already running is used and left running; one started here is stopped.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

if [ $# -lt 2 ]; then
    sed -n '2,10p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
designs=$1 out=$2
shift 2
submit_opts=() study_args=(--skip-fem)
while [ $# -gt 0 ]; do
    if [ "$1" = "--" ]; then
        shift
        study_args=("$@")
        break
    fi
    submit_opts+=("$1")
    shift
done

started=0
# shellcheck disable=SC2317  # (run by the EXIT trap)
cleanup() {
    local rc=$?
    if [ "$started" -eq 1 ]; then
        "$here/local-cluster.sh" stop || { [ "$rc" -ne 0 ] || rc=1; }
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

if "$here/local-cluster.sh" status >/dev/null 2>&1; then
    echo "test-sweep: the local cluster is already running: using it (left running afterwards)"
else
    started=1
    "$here/local-cluster.sh" start
fi
eval "$("$here/local-cluster.sh" env)"
export SLURM_CONF

t0=$SECONDS
rc=0
"$here/submit.sh" --designs "$designs" --out "$out" --shards 2 --cpus 1 --mem 2000 --wait \
    "${submit_opts[@]}" -- "${study_args[@]}" || rc=$?
echo "test-sweep: submit.sh exited $rc after $((SECONDS - t0)) s"
exit "$rc"
