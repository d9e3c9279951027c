#!/usr/bin/env bash
# The rig's mount identified on the paper's 512 training trajectories (docs/rig-agreement.md):
# the L0 wing without the chordwise Kirchhoff force on the coarse grid and on the fine one, and
# the same L0 with that force on the coarse grid, for comparison. The printed results go to
# OUT/fit-mount.txt, each fit's whole surface to OUT/fit-*.json.
#
#   bash scripts/rig/fit_mount.sh OUT       # 5–10 min on 2 cores
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: bash scripts/rig/fit_mount.sh OUT}
flapssm=${FLAPSSM:-target/release/flapssm}
reference=${REFERENCE:-../shared/reference/bayiz2021-prssm/reference.npz}
mkdir -p "$out"
fit() {
  local name=$1 config=$2
  shift 2
  echo "## $name: --wing-config $config $*"
  "$flapssm" rig fit-mount --reference "$reference" --wing-config "$config" --quiet \
    --out "$out/fit-$name.json" "$@"
  echo
}
{
  fit coarse scripts/rig/ablation/l0-no-chordwise-added-mass.json
  fit fine scripts/rig/ablation/l0-no-chordwise-added-mass.json --plate-deg 2:7:0.5 --sensor-deg -3:3:0.5
  fit coarse-with-kirchhoff scripts/rig/ablation/l0.json
} | tee "$out/fit-mount.txt"
