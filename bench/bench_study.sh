#!/usr/bin/env bash
# bench_study: a study's wall time on this machine (--cores N) and through a one-node Slurm
# cluster (tests/slurm_cluster.sh), one after the other on the same machine, and the cluster's
# overhead; then the per-stage costs from the tables. Needs root (munged), slurm-wlm, munge.
#   bench/bench_study.sh [STUDY.yaml]      (default samples/study_tiny.yaml)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tool=${VF_TOOL:-$here/build/vfcapture}
study=$(realpath "${1:-$here/samples/study_tiny.yaml}")
work=$(mktemp -d /tmp/vfbench-study-XXXXXX)
source "$here/tests/slurm_cluster.sh"
trap 'slurm_stop 2>/dev/null; rm -rf "$work"' EXIT
cd "$work"
out=$(python3 -c 'import sys,yaml; print(yaml.safe_load(open(sys.argv[1]))["out"])' "$study")
cores=$(nproc)

run() { # run NAME ARGS...: the study into NAME/, its wall time in seconds on stdout
  local name=$1 start
  shift
  mkdir -p "$name" && start=$(date +%s.%N)
  (cd "$name" && "$tool" study "$study" "$@" --quiet >/dev/null 2>"$work/$name.err") || true
  echo "$(date +%s.%N) - $start" | bc
}
local_s=$(run local --cores "$cores")
slurm_start
export USER=${USER:-root}
slurm_s=$(run cluster --slurm)
jobs=$(grep -l "^job [0-9]" cluster/"$out"/logs/*/*.log cluster/"$out"/logs/*.log 2>/dev/null | wc -l)
printf 'study %s: --cores %d %.1f s; through Slurm %.1f s (%d jobs); overhead %.1f s (%.1f%%)\n' \
  "$(basename "$study")" "$cores" "$local_s" "$slurm_s" "$jobs" "$(echo "$slurm_s - $local_s" | bc)" \
  "$(echo "100 * ($slurm_s - $local_s) / $local_s" | bc -l)"
cmp -s local/"$out"/tables/table1.csv cluster/"$out"/tables/table1.csv \
  && echo "Table 1 identical in both runs" || echo "Table 1 differs between the runs"
echo "wall seconds and peak memory per rule (--cores run):"
python3 - local/"$out"/tables/costs.csv <<'PY'
import csv, sys, collections
total = collections.defaultdict(float); count = collections.Counter(); rss = collections.defaultdict(float)
for row in csv.DictReader(open(sys.argv[1])):
    family = row["stage"].split("-")[0].split("/")[0]
    total[family] += float(row["seconds"]); count[family] += 1
    rss[family] = max(rss[family], float(row["max_rss_mb"] or 0))
for family in sorted(total, key=lambda f: -total[f]):
    print(f"  {family:10s} {count[family]:4d} jobs {total[family]:9.1f} s  ({total[family] / count[family]:.1f} s a job, peak {rss[family]:.0f} MB)")
PY
