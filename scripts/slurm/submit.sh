#!/usr/bin/env bash
# Submits a whole dataset to Slurm: an array job over the plan's sequences (at most K at a time),
# then the merge job after it (--dependency=afterok), which checks every sequence and writes the
# manifest. Prints the two job ids. Resubmitting after a failure or a pre-empted task completes the
# dataset: finished sequences are skipped.
# Usage: scripts/slurm/submit.sh [--throttle K] [--tasks N] [--logs DIR] [--sbatch "ARGS"]
#                                PLAN.yaml ROOT [generate options]
#   --throttle K   at most K tasks at once (default 16)
#   --tasks N      array tasks (default: one per sequence; fewer tasks take every N-th sequence each)
#   --logs DIR     where the tasks' logs go (default ROOT/logs)
#   --sbatch ARGS  extra sbatch options for both jobs, e.g. "--partition=gpu --mem=8G"
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
throttle=16 tasks="" logs="" extra=""
while [ $# -gt 0 ]; do
  case "$1" in
    --throttle) throttle=$2; shift 2 ;;
    --tasks) tasks=$2; shift 2 ;;
    --logs) logs=$2; shift 2 ;;
    --sbatch) extra=$2; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) break ;;
  esac
done
[ $# -ge 2 ] || { echo "usage: submit.sh [--throttle K] [--tasks N] [--logs DIR] [--sbatch ARGS] PLAN.yaml ROOT [generate options]" >&2; exit 2; }
plan=$(realpath "$1") root=$(realpath -m "$2")
shift 2
[ -f "$plan" ] || { echo "submit.sh: no plan $plan (generate --write-plan viper --plan $plan)" >&2; exit 2; }
command -v sbatch > /dev/null || { echo "submit.sh: sbatch not found (is this a Slurm login node?)" >&2; exit 2; }
# The jobs run the generate found here (sbatch passes the environment on; the job scripts run from
# slurmd's copy of them, where no file beside them can be sourced).
# shellcheck source=../package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_generate submit.sh  # $VIPER_GENERATE, else the package's generate
export VIPER_GENERATE=$generate
sequences=$("$py" -c 'import sys, yaml; print(len(yaml.safe_load(open(sys.argv[1]))["sequences"]))' "$plan") ||
  { echo "submit.sh: $plan is not a dataset plan" >&2; exit 2; }
tasks=${tasks:-$sequences}
[ "$tasks" -ge 1 ] && [ "$throttle" -ge 1 ] || { echo "submit.sh: --tasks and --throttle must be at least 1" >&2; exit 2; }
logs=$(realpath -m "${logs:-$root/logs}")
mkdir -p "$logs"
# shellcheck disable=SC2086  # extra holds several sbatch options
array=$(sbatch --parsable $extra --array="0-$((tasks - 1))%$throttle" --output="$logs/generate_%A_%a.log" \
  "$here/scripts/slurm/generate_array.sbatch" "$plan" "$root" "$@")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable $extra --dependency=afterok:"$array" --output="$logs/merge_%j.log" \
  "$here/scripts/slurm/merge.sbatch" "$plan" "$root")
merge=${merge%%;*}
echo "submitted $sequences sequences as array job $array ($tasks tasks, at most $throttle at a time) and merge job $merge"
echo "logs: $logs   progress: squeue -j $array,$merge   after: $root/manifest.md"
