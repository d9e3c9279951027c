#!/usr/bin/env bash
# How close a wing without memory can come to the rig stand-in, and what the rig's chordwise
# channels are not (docs/rig-agreement.md): noise-free L0 datasets of the paper's 548 measured
# trajectories (the whole wing, without its rotational force, without its added mass), the plate's
# whole static and inertial loads as sensor residuals, the published model's prediction of the
# same trajectories, then scripts/rig/ceiling.py on them; the tables go to OUT/ceiling.md.
#
#   bash scripts/rig/ceiling.sh OUT        # about 40 s on 2 cores
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: bash scripts/rig/ceiling.sh OUT}
flapssm=${FLAPSSM:-target/release/flapssm}
reference=${REFERENCE:-../shared/reference/bayiz2021-prssm/reference.npz}
mkdir -p "$out"
sim() { "$flapssm" simulate --source paper --wing-config "$1" --out "$out/$2.npz" --quiet "${@:3}" > /dev/null; }
sim scripts/rig/ablation/l0.json l0 --noise-free
sim scripts/rig/ablation/l0-no-rotational.json l0-no-rotational --noise-free
sim scripts/rig/ablation/l0-no-added-mass.json l0-no-added-mass --noise-free
sim scripts/rig/ceiling/static-residual.json static-residual
sim scripts/rig/ceiling/inertial-residual.json inertial-residual
"$flapssm" model import-published "$reference" --out "$out/published.json" > /dev/null
"$flapssm" predict "$out/published.json" "$out/l0.npz" --particles 30 --seed 1 --out "$out/stand-in.npz" 2> /dev/null > /dev/null
python3 scripts/rig/ceiling.py "$out" > "$out/ceiling.md"
echo "wrote $out/ceiling.md"
