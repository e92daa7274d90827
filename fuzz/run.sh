#!/usr/bin/env bash
# Fuzz one format for a while: run.sh FUZZER SEED_DIR SECONDS. The corpus grows in a copy under
# the build folder (fuzz-corpus/NAME), never in the seeds; a crash, leak, timeout (10 s an
# input) or memory over 1 GB fails the run and leaves the input as crash-*/timeout-*/oom-*.
set -euo pipefail
fuzzer=$1 seeds=$2 seconds=$3
name=$(basename "$fuzzer")
corpus="fuzz-corpus/$name"
mkdir -p "$corpus" "fuzz-artifacts"
cp -n "$seeds"/* "$corpus"/ 2>/dev/null || true
exec "$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=1024 -print_final_stats=1 \
  -artifact_prefix="fuzz-artifacts/$name-" "$corpus"
