#!/usr/bin/env bash
# A study through the shipped workflow (workflow/Snakefile), on this machine and through a real
# one-node Slurm cluster that the test starts and stops (tests/slurm_cluster.sh): a posed set
# (the chair) and a broken input x two classifiers x two attack settings at tiny budgets.
# Asserts: every stage ran as a Slurm job (job ids in the logs); the broken object fails alone
# and is named in the tables with its error; a training job cancelled with scancel is rerun
# (resuming its checkpoint) and the tables equal those of the same study run with --cores 2;
# a second run schedules nothing; errors in the study file are one line naming the key.
source "$(dirname "$0")/shell_checks.sh"
source "$(dirname "$0")/slurm_cluster.sh"
trap 'slurm_stop 2>/dev/null; rm -rf "$tmp"' EXIT

snakefile="$VF_SOURCE_DIR/workflow/Snakefile"
head -c 3000 "$shared/data/nerf_synthetic/lego/transforms_train.json" >"$tmp/broken.json"
study() { # study FILE OUT: the tiny study's description, its workspaces in OUT
  cat >"$1" <<EOF
out: $2
objects:
  chair:
    input: $shared/data/nerf_synthetic/chair/transforms_train.json
    labels: folding chair,rocking chair
  broken:
    input: $tmp/broken.json
    labels: thresher
classifiers: [mobilenet_v1_0.25_128_quant, mobilenet_v1_0.5_160_quant]
settings:
  nes-l0: --method nes --lambda 0
  random: --method random
budgets:
  train: --train-steps 200
  attack: --steps 1 --samples 4
EOF
}
cd "$tmp" || exit 1

# The study file: one line naming the key.
study "$tmp/bad.yaml" "$tmp/bad"
sed -i 's/^settings:/setings:/' "$tmp/bad.yaml"
expect 1 "a misspelt key" -- "$tool" study "$tmp/bad.yaml" --cores 2 --quiet
grep -q "^study: unknown key 'setings'" "$tmp/err" && ok || bad "the study file's error names the key: $(grep -v '^running' "$tmp/err" | head -3)"
expect 0 "study --help" -- "$tool" study --help
grep -q "usage: vfcapture study" "$tmp/out" && ok || bad "study --help prints its usage"

# On this machine.
study "$tmp/local.yaml" "$tmp/local"
start=$(date +%s.%N)
expect 1 "the study with --cores 2 (the broken object fails)" -- "$tool" study "$tmp/local.yaml" --cores 2
local_s=$(echo "$(date +%s.%N) - $start" | bc)
grep -q "running: VF_TOOL=.*snakemake -s .*Snakefile --configfile $tmp/local.yaml --cores 2 --keep-going" "$tmp/err" \
  && ok || bad "study prints the snakemake line it runs: $(head -1 "$tmp/err")"
[ -s local/tables/table1.csv ] && [ -s local/tables/tables.md ] && [ -s local/tables/table1.png ] \
  && ok || bad "the tables were written despite the failed object: $(ls local/tables 2>&1)"
grep -q "^broken,ingest,.*error" local/tables/failed.csv && ok || bad "the broken object is named with its error: $(cat local/tables/failed.csv)"
[ "$(grep -c '^chair,' local/tables/objects.csv)" -eq 4 ] && ok || bad "four attacks of the chair (2 classifiers x 2 settings): $(cat local/tables/objects.csv)"
[ -s local/chair/attack/mobilenet_v1_0.5_160_quant-random/attack.json ] && ok || bad "the attacks live side by side in one workspace: $(ls local/chair/attack)"

# Through Slurm; the training job is cancelled 2 s into its training (it checkpoints every
# 30 s: this one reruns from scratch; test_stage_resume covers the resume).
slurm_start && ok || bad "the one-node cluster came up"
export USER=${USER:-root}
study "$tmp/cluster.yaml" "$tmp/cluster"
start=$(date +%s.%N)
"$tool" study "$tmp/cluster.yaml" --slurm >"$tmp/cluster.out" 2>"$tmp/cluster.err" &
pid=$!
cancelled="" seen=0
for _ in $(seq 900); do
  # each job takes both CPUs, so the job running while train stages is the training job
  if [ -z "$cancelled" ] && [ -d cluster/chair/.train.partial ]; then
    seen=$((seen + 1))
    job=$(squeue -h -t R -o %i | head -1)
    [ "$seen" -ge 10 ] && [ -n "$job" ] && scancel "$job" && cancelled=$job
  fi
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.2
done
wait "$pid"
rc=$?
cluster_s=$(echo "$(date +%s.%N) - $start" | bc)
[ "$rc" -eq 1 ] && ok || bad "the Slurm study exits 1 (the broken object): $rc: $(tail -5 "$tmp/cluster.err")"
[ -n "$cancelled" ] && ok || bad "a training job was cancelled mid-way: $(ls -a cluster/chair 2>&1)"
grep -q "^job [0-9][0-9]* on" cluster/logs/chair/train.log && ok || bad "train ran as a Slurm job: $(head -1 cluster/logs/chair/train.log)"
nonslurm=$(grep -L "^job [0-9][0-9]* on" cluster/logs/*/*.log | grep -v tables.log)
[ -z "$nonslurm" ] && ok || bad "every stage ran as a Slurm job; not: $nonslurm"
[ "$(ls cluster/logs/chair/*.log | wc -l)" -eq 6 ] && ok || bad "ingest, train and four attacks logged: $(ls cluster/logs/chair)"
grep -qE "(Trying to restart|restart)" "$tmp/cluster.err" && ok || bad "the cancelled job was restarted: $(grep -i -m3 'error\|cancel' "$tmp/cluster.err")"
python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); assert m["stages"]["train"]["summary"]["steps"] == 200' cluster/chair/manifest.json \
  && ok || bad "the rerun training finished all 200 steps"

# The same numbers: attack success, natural accuracy, the samples' spread, per object and as
# Table 1 and 2 (the costs differ, and the failure's wording names the study's folder).
for t in table1 table2 objects; do
  cmp -s "local/tables/$t.csv" "cluster/tables/$t.csv" && ok || bad "$t equals the --cores 2 run: $(diff "local/tables/$t.csv" "cluster/tables/$t.csv" | head -6)"
done

# A second run of the finished study schedules nothing (the broken object stays out until
# its input or its entry changes).
expect 0 "second run, dry" -- "$tool" study "$tmp/cluster.yaml" --slurm --dry-run
grep -q "Nothing to be done" "$tmp/out" "$tmp/err" && ok || bad "a second run schedules nothing: $(grep -A12 'Job stats' "$tmp/out" | head -14)"
slurm_stop
printf 'study wall time: --cores 2 %.1f s, through Slurm (one train cancelled and rerun) %.1f s\n' "$local_s" "$cluster_s"
cli_finish
