#!/usr/bin/env bash
# Runs a sim-host campaign on a Slurm cluster as a job array of SHARDS tasks, waits for it,
# and merges the shards into OUT_DIR/merged.
#
#   sim-host/slurm/run-campaign.sh SHARDS OUT_DIR [sim-host campaign options]
#   SIM_HOST=$PWD/target/release/sim-host sim-host/slurm/run-campaign.sh 10 out/mc --runs 1000
#
# SBATCH_OPTS adds sbatch options (partition, account, time limit: `-p short -t 00:30:00`).
set -euo pipefail

if [ $# -lt 2 ]; then
  echo "usage: $0 SHARDS OUT_DIR [sim-host campaign options]" >&2
  exit 2
fi
shards=$1
out=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
sim_host=${SIM_HOST:-sim-host}
mkdir -p "$out/logs"
# --wait: sbatch returns when every task has ended, non-zero if any failed.
# shellcheck disable=SC2086
sbatch --wait --array="0-$((shards - 1))" --output="$out/logs/%A_%a.out" ${SBATCH_OPTS:-} \
  --export=ALL,SIM_HOST="$sim_host" "$here/campaign.sbatch" "$out" "$@"
dirs=()
for ((i = 0; i < shards; i++)); do
  dirs+=("$out/shard-$i")
done
"$sim_host" campaign merge "${dirs[@]}" --out "$out/merged"
