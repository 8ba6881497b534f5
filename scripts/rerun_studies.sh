#!/usr/bin/env bash
# Rerun every study in experiments/ after a change to lv3d's code, retraining only the lv3d systems, with the
# systems and conditions of the committed reports in experiments/results/, and the seed protocol's four
# replicates (its lv3d systems on data seeds 1-4; scripts/pooled_replicates.py pools them) and the real-objects
# study's lv3d systems on perception seeds 1 and 2 (real_objects_pseed1, _pseed2), and the ten-class study's
# depth systems without arbiters (ten_classes_no_arbiters) and on data seeds 1 and 2 (ten_classes_seed1, _seed2;
# pooled_replicates.py pools them too). The ten-class learning curve shares the ten-class study's images and
# facts. Each study's
# baseline fold files are restored from its committed results.csv first (scripts/restore_baselines.py), then
# `lv3d experiment run` computes the lv3d folds and rewrites the report.
#
#   bash scripts/rerun_studies.sh [RUNS_DIR]     # default: runs/rerun
#
# What the committed reports hold, and so what is passed here: the seed protocol and its replicates at the
# clean and realsense presets; the few-shot study with the lv3d systems, cnn-rgbd, the pretrained networks and
# the tree; the real-objects study with the tuned CNN at every size (its two parts are joined by
# `lv3d experiment report`); the ablations on real frames, lv3d systems only; the real-objects study on each
# folder alone (real_objects_osd, real_objects_ycb: boxes and cylinders, no tuned CNN); the real objects across
# sensors (real_across_sensors: learned in one folder, tested in the other; its baselines are trained anew, a
# few minutes, so that its report keeps their answers' calibration and confusions). Three lanes run at once on two
# cores; the studies of the seed protocol's images share one data cache, which the seed protocol fills before the ablations start. About 75 min on two cores with the facts
# cached, 100 where a change to perception or grounding has the facts computed anew, and
# up to 18 more for the ten-class learning curve (its time alone on two free cores) in the third lane; the two
# ten-class replicates add about 6 min each (alone on two cores).
#
# Then copy each run's results.{csv,md} and plots into experiments/results/<study>/ (the script prints the
# commands), rewrite the tables of experiments/README.md (scripts/readme_tables.py --write) and its text.
# What each report's rerun moved: scripts/compare_reports.py experiments/results/<study>/results.csv
# RUNS_DIR/<study>/results.csv. Whether the facts are those of the previous code, byte for byte:
# scripts/compare_facts.py RUNS_DIR OLD NEW (the two facts versions).
# Resumable: rerunning skips finished folds. Into the RUNS_DIR of the previous rerun, a change that leaves every
# fact as it was computes the facts anew and keeps every lv3d fold (their key is their facts' content and the
# learning code's version). Progress: RUNS_DIR/progress, one line per finished study.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-runs/rerun}
PY=.venv/bin/python
LV3D=.venv/bin/lv3d
mkdir -p "$RUNS"
CACHE="data.cache=$RUNS/cache"           # the seed protocol's images (and the ten-class ones, which two studies share)
NOISE_CACHE="data.cache=$RUNS/noise_cache"
REAL_CACHE="data.cache=$RUNS/real_cache"
TWO_PRESETS="sweep={param: data.noise, values: [clean, realsense]}"
LV3D_ONLY="systems=[lv3d-rgb,lv3d-depth,lv3d-rgbd]"

log() { echo "$(date +%T) $*" | tee -a "$RUNS/progress"; }

run_logged() {  # run_logged NAME [--set ...]: run the study, appending to RUNS/NAME.log, and log its line
    local name=$1; shift
    OMP_NUM_THREADS=1 $LV3D experiment run "experiments/$name.yaml" --out "$RUNS/$name" "$@" >> "$RUNS/$name.log" 2>&1
    log "$name: $(grep -a 'fold results computed' "$RUNS/$name.log" | tail -1)"
}

study() {  # study NAME [--set ...]: restore the baselines, then run, logged to RUNS/NAME.log
    $PY scripts/restore_baselines.py "experiments/$1.yaml" "experiments/results/$1/results.csv" \
        --out "$RUNS/$1" "${@:2}" > "$RUNS/$1.log" 2>&1
    run_logged "$@"
}

whole_study() {  # whole_study NAME [--set ...]: run with its baselines trained too (their answers' calibration
    : > "$RUNS/$1.log"  # and confusions stay in the report; restored baselines carry their scores only)
    run_logged "$@"
}

replicate() {  # replicate SEED: the seed protocol's lv3d systems on images of another data seed (no baselines)
    OMP_NUM_THREADS=1 $LV3D experiment run experiments/seed_protocol.yaml --out "$RUNS/seed_protocol_seed$1" \
        --set seed="$1" --set "$CACHE" --set "$LV3D_ONLY" --set "$TWO_PRESETS" > "$RUNS/seed_protocol_seed$1.log" 2>&1
    log "seed_protocol_seed$1: $(grep -a 'fold results computed' "$RUNS/seed_protocol_seed$1.log" | tail -1)"
}

ten_replicate() {  # ten_replicate SEED: the ten-class study's depth systems on images of another data seed (no baselines)
    OMP_NUM_THREADS=1 $LV3D experiment run experiments/ten_classes.yaml --out "$RUNS/ten_classes_seed$1" \
        --set seed="$1" --set "$CACHE" --set "systems=[lv3d-depth,lv3d-rgbd]" > "$RUNS/ten_classes_seed$1.log" 2>&1
    log "ten_classes_seed$1: $(grep -a 'fold results computed' "$RUNS/ten_classes_seed$1.log" | tail -1)"
}

no_arbiters() {  # the ten-class study's depth systems without arbiters (docs/learner.md, "Arbiters"; no baselines)
    OMP_NUM_THREADS=1 $LV3D experiment run experiments/ten_classes.yaml --out "$RUNS/ten_classes_no_arbiters" \
        --set "$CACHE" --set "systems=[lv3d-depth,lv3d-rgbd]" --set lv3d.settings.arbiters=false \
        > "$RUNS/ten_classes_no_arbiters.log" 2>&1
    log "ten_classes_no_arbiters: $(grep -a 'fold results computed' "$RUNS/ten_classes_no_arbiters.log" | tail -1)"
}

perception_seed() {  # perception_seed S: the real-objects study's lv3d systems with perception's seed S (no baselines)
    OMP_NUM_THREADS=1 $LV3D experiment run experiments/real_objects.yaml --out "$RUNS/real_objects_pseed$1" \
        --set "$REAL_CACHE" --set "$LV3D_ONLY" --set lv3d.perception_seed="$1" > "$RUNS/real_objects_pseed$1.log" 2>&1
    log "real_objects_pseed$1: $(grep -a 'fold results computed' "$RUNS/real_objects_pseed$1.log" | tail -1)"
}

per_folder() {  # per_folder NAME FOLDER: the real-objects study on one folder's boxes and cylinders (its baselines restored)
    local out=$RUNS/real_objects_$1
    local sets=(--set "$REAL_CACHE" --set "data.folders=[../shared/data/real/$2]" --set "data.classes=[box, cylinder]"
                --set "systems=[lv3d-rgb,lv3d-depth,lv3d-rgbd,effnet-rgb,effnet-depth,effnet-rgbd,tree-rgbd]"
                --set baselines.tune=false)
    {
        $PY scripts/restore_baselines.py experiments/real_objects.yaml "experiments/results/real_objects_$1/results.csv" \
            --out "$out" "${sets[@]}"
        OMP_NUM_THREADS=1 $LV3D experiment run experiments/real_objects.yaml --out "$out" "${sets[@]}"
    } > "$RUNS/real_objects_$1.log" 2>&1
    log "real_objects_$1: $(grep -a 'fold results computed' "$RUNS/real_objects_$1.log" | tail -1)"
}

real_objects() {  # the lv3d systems, the pretrained networks, the tree and the tuned CNN at every size
    local out=$RUNS/real_objects
    local csv=experiments/results/real_objects/results.csv
    {
        $PY scripts/restore_baselines.py experiments/real_objects.yaml $csv --out "$out" --set "$REAL_CACHE"
        OMP_NUM_THREADS=1 $LV3D experiment run experiments/real_objects.yaml --out "$out" --set "$REAL_CACHE" \
            --set "$LV3D_ONLY"
        $LV3D experiment report experiments/real_objects.yaml --out "$out" --set "$REAL_CACHE"
    } > "$RUNS/real_objects.log" 2>&1
    log "real_objects: report joined"
}

FEW_SHOT="systems=[lv3d-rgb,lv3d-depth,lv3d-rgbd,cnn-rgbd,effnet-rgb,effnet-depth,effnet-rgbd,tree-rgbd]"
rm -f "$RUNS/.seed_protocol_done"
pids=()
( study seed_protocol --set "$CACHE" --set "$TWO_PRESETS"; touch "$RUNS/.seed_protocol_done"
  study learning_curve --set "$CACHE"; study few_shot --set "$CACHE" --set "$FEW_SHOT"; replicate 1; replicate 2
  ten_replicate 1 ) & pids+=($!)
( for n in noise_depth noise_color noise_occlusion noise_clutter noise_lighting; do study $n --set "$NOISE_CACHE"; done
  real_objects; study real_ablations --set "$REAL_CACHE"; per_folder osd osd-learn; per_folder ycb ycb-realsense
  whole_study real_across_sensors --set "$REAL_CACHE"
  perception_seed 1; perception_seed 2 ) & pids+=($!)
( study ten_classes --set "$CACHE"; study ten_classes_curve --set "$CACHE"
  until [ -e "$RUNS/.seed_protocol_done" ]; do sleep 10; done
  study ablations --set "$CACHE"; replicate 3; replicate 4; no_arbiters; ten_replicate 2 ) & pids+=($!)
failed=0
for p in "${pids[@]}"; do wait "$p" || failed=1; done
[ "$failed" = 0 ] || { echo "a lane stopped: see $RUNS/progress and the last log it names" >&2; exit 1; }

for d in "$RUNS"/*/results.csv; do
    name=$(basename "$(dirname "$d")")
    echo "mkdir -p experiments/results/$name; cp $RUNS/$name/results.{csv,md} $RUNS/$name/*.png experiments/results/$name/"
done
