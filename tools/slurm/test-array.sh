#!/usr/bin/env bash
# CI test of campaigns on Slurm: starts a one-node cluster on loopback (one-node-cluster.sh),
# submits explain-eval-array.sbatch as a 4-task array (2 cases of 300 s each, seed 7), waits,
# checks each task's peak memory against the 256 MB the script asks Slurm for, merges the
# shards with `explain-eval --merge` and checks the result equals one whole run of the same 8
# cases (every field of cases.json and eval.json but the wall times and the command line).
#
#   tools/slurm/test-array.sh SINSMODEL_BINARY
set -euo pipefail
bin=$(cd "$(dirname "${1:?the sinsmodel binary}")" && pwd)/$(basename "$1")
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d /tmp/sinsmodel-slurm.XXXXXX)
cleanup() {
  "$here/one-node-cluster.sh" stop "$work/cluster" || true
  if [ -n "${KEEP_SLURM_TEST:-}" ]; then
    echo "kept $work"
  else
    rm -rf "$work"
  fi
}
trap cleanup EXIT
eval "$("$here/one-node-cluster.sh" start "$work/cluster")"
run=$work/run
mkdir -p "$run"
echo "slurm: submitting a 4-task array (SLURM_CONF=$SLURM_CONF)"
sbatch --wait --array=0-3 --chdir="$run" \
  --export=ALL,SINSMODEL="$bin",EVAL_OUT="$run",EVAL_SEED=7,EVAL_CASES_PER_TASK=2,EVAL_SECONDS=300 \
  "$here/explain-eval-array.sbatch"
granted_kib=$((256 * 1024))
for k in 0 1 2 3; do
  log=$(ls "$run"/explain-eval-*_"$k".log)
  if [ ! -f "$run/shard-$k/cases.json" ]; then
    echo "test-array: task $k wrote no shard; its log:" >&2
    cat "$log" >&2
    exit 1
  fi
  peak=$(sed -n 's/^peak-rss-kib //p' "$log")
  if [ -z "$peak" ] || [ "$peak" -gt "$granted_kib" ]; then
    echo "test-array: task $k peak memory ${peak:-unknown} KiB, beyond the ${granted_kib} KiB granted" >&2
    exit 1
  fi
  echo "task $k: peak ${peak} KiB of ${granted_kib} KiB granted"
done
"$bin" explain-eval --merge "$run"/shard-0 "$run"/shard-1 "$run"/shard-2 "$run"/shard-3 --out "$run/merged"
"$bin" explain-eval --seed 7 --cases 8 --seconds 300 --out "$run/whole"
python3 - "$run/merged" "$run/whole" <<'PY'
import json, sys
timing = {"seconds_taken", "seconds_taken_setup", "seconds_taken_explain", "seconds_per_case",
          "seconds_per_case_setup", "seconds_per_case_explain", "seconds_wall", "command"}
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in timing}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
merged, whole = sys.argv[1], sys.argv[2]
for name in ("cases.json", "eval.json"):
    a = strip(json.load(open(f"{merged}/{name}")))
    b = strip(json.load(open(f"{whole}/{name}")))
    if a != b:
        keys = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k)) if isinstance(a, dict) else []
        diff = "; ".join(f"{k}: {str(a.get(k))[:300]} | {str(b.get(k))[:300]}" for k in keys)
        sys.exit(f"test-array: the merged {name} differs from one whole run's: {diff or 'the case lists differ'}")
print("slurm: the merged shards equal one whole run (cases.json, eval.json)")
PY
