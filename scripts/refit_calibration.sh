#!/usr/bin/env bash
# The calibration maps' recipe (lv3d/calibrate/fit.py's docstring) in one command: the candidate rows of seven
# rendered dev sets and of the labelled real folders, made by the code of this checkout, then the fit, which
# rewrites lv3d/data/calibration.json with its checks and its provenance.
#
#   bash scripts/refit_calibration.sh [OUT_DIR]      # default: out/calib
#   FIT_OUT=out/calib/check.json bash scripts/refit_calibration.sh   # the maps elsewhere, the shipped file kept
#
# Run it after any change to perception, grounding or the fact writer (lv3d calibrate check names what changed
# since the shipped fit), before rerunning the studies (scripts/rerun_studies.sh): the maps are part of every
# fact's confidence. Two lanes run at once on two cores; about 20 min of rows and 8 min of fit on two cores.
# The real folders are read from ../shared/data/real (REAL_DIR overrides it).
#
# Resumable: a row set is made again only where OUT_DIR/progress does not record it finished by the same code
# (lv3d's facts version); each set's log is OUT_DIR/<set>.log, the fit's OUT_DIR/fit.log. The pickles are written
# with --fresh, so that a set never mixes rows of two versions of the code.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/calib}
REAL_DIR=${REAL_DIR:-../shared/data/real}
FIT_OUT=${FIT_OUT:-lv3d/data/calibration.json}
LV3D=.venv/bin/lv3d
mkdir -p "$OUT"
touch "$OUT/progress"
VERSION=$(.venv/bin/python -c "from lv3d.experiment.code_version import facts_version; print(facts_version())")

done_by_this_code() { grep -qx "$1 0 $VERSION" "$OUT/progress"; }

rendered() {  # rendered SEED NAME PRESET PER_CLASS
    done_by_this_code "$2" && return 0
    local rc=0
    OMP_NUM_THREADS=1 $LV3D calibrate rows --fresh --seed "$1" --per-class "$4" --preset "$3" \
        --modalities rgbd,depth --out "$OUT/$2.pkl" > "$OUT/$2.log" 2>&1 || rc=$?
    echo "$2 $rc $VERSION" >> "$OUT/progress"
    echo "$(date +%T) $2: exit $rc"
    return "$rc"
}

real() {  # real FOLDER
    local name=real_$1 rc=0
    done_by_this_code "$name" && return 0
    OMP_NUM_THREADS=1 $LV3D calibrate real "$REAL_DIR/$1" --out "$OUT/$name.pkl" > "$OUT/$name.log" 2>&1 || rc=$?
    echo "$name $rc $VERSION" >> "$OUT/progress"
    echo "$(date +%T) $name: exit $rc"
    return "$rc"
}

for f in osd-learn ycb-realsense; do
    [ -f "$REAL_DIR/$f/objects.csv" ] || { echo "no labelled real folder $REAL_DIR/$f (objects.csv): the fit needs it" >&2; exit 2; }
done

pids=()
( rendered 30000 s30000 realsense 120; rendered 60000 s60000 realsense 120; rendered 80000 r80000 realistic 120
  rendered 110000 chk110000 clean 40 ) & pids+=($!)
( rendered 40000 s40000 realsense 120; rendered 70000 c70000 clean 120; rendered 100000 chk100000 realsense 40
  real osd-learn; real ycb-realsense ) & pids+=($!)
failed=0
for p in "${pids[@]}"; do wait "$p" || failed=1; done
[ "$failed" = 0 ] || { echo "a row set failed: see $OUT/progress and its log" >&2; exit 1; }

echo "$(date +%T) fit (log: $OUT/fit.log)"
OMP_NUM_THREADS=1 $LV3D calibrate fit "$OUT"/{s30000,s40000,s60000,c70000,r80000}.pkl \
    --real "$OUT/real_osd-learn.pkl" --real "$OUT/real_ycb-realsense.pkl" \
    --check "$OUT/chk100000.pkl" --check "$OUT/chk110000.pkl" --holdout --out "$FIT_OUT" > "$OUT/fit.log" 2>&1
echo "$(date +%T) $FIT_OUT written; the shipped one committed, rerun the studies (scripts/rerun_studies.sh)"
