#!/usr/bin/env bash
# Rerun every study in experiments/ after a change to lv3d's code, retraining only the lv3d systems, and the seed
# protocol's four replicates (its lv3d systems on data seeds 1-4; scripts/pooled_replicates.py pools them):
# each study's baseline fold files are restored from its committed results.csv first
# (scripts/restore_baselines.py), then `lv3d experiment run` computes the lv3d folds and rewrites the report.
# Two studies run at a time (one per core). The seed protocol, learning curve, ablations and few-shot study
# share one data cache (the same images), which the seed protocol fills before the others start.
#
#   bash scripts/rerun_studies.sh [RUNS_DIR]     # default: runs/rerun
#
# Then copy each run's results.{csv,md} and plots into experiments/results/<study>/ (the script prints the
# commands), rewrite the tables of experiments/README.md (scripts/readme_tables.py --write) and its text.
# Resumable: rerunning skips finished folds.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-runs/rerun}
PY=.venv/bin/python
LV3D=.venv/bin/lv3d
mkdir -p "$RUNS"

study() {  # study NAME [--set ...]: restore the baselines, run, log to RUNS/NAME.log
    local name=$1; shift
    $PY scripts/restore_baselines.py "experiments/$name.yaml" "experiments/results/$name/results.csv" \
        --out "$RUNS/$name" "$@" > "$RUNS/$name.log" 2>&1
    OMP_NUM_THREADS=1 $LV3D experiment run "experiments/$name.yaml" --out "$RUNS/$name" "$@" >> "$RUNS/$name.log" 2>&1
    echo "$(date +%T) $name: $(grep -a 'fold results computed' "$RUNS/$name.log" | tail -1)"
}

CACHE=(--set "data.cache=$RUNS/cache")
study seed_protocol "${CACHE[@]}"
study learning_curve "${CACHE[@]}" & study ablations "${CACHE[@]}"; wait
study few_shot "${CACHE[@]}" & study noise_depth; wait
study noise_color & study noise_occlusion; wait
study noise_clutter & study noise_lighting; wait

replicate() {  # replicate SEED: the seed protocol's lv3d systems on images of another data seed (no baselines)
    OMP_NUM_THREADS=1 $LV3D experiment run experiments/seed_protocol.yaml --out "$RUNS/seed_protocol_seed$1" \
        --set seed="$1" --set "systems=[lv3d-rgb,lv3d-depth,lv3d-rgbd]" > "$RUNS/seed_protocol_seed$1.log" 2>&1
    echo "$(date +%T) seed_protocol_seed$1: $(grep -a 'fold results computed' "$RUNS/seed_protocol_seed$1.log" | tail -1)"
}
replicate 1 & replicate 2; wait
replicate 3 & replicate 4; wait

for d in "$RUNS"/*/results.csv; do
    name=$(basename "$(dirname "$d")")
    echo "mkdir -p experiments/results/$name; cp $RUNS/$name/results.{csv,md} $RUNS/$name/*.png experiments/results/$name/"
done
