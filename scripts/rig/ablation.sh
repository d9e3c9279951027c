#!/usr/bin/env bash
# The rig ablation (docs/rig-agreement.md): every wing configuration of scripts/rig/order.txt
# (files in scripts/rig/ablation/, each relative to the default wing; or those named) simulated noise-free on the paper's 548 measured trajectories and scored
# against the published model's prediction with `flapssm rig check`; one directory per
# configuration under OUT, then the tables (scripts/rig/table.py) in OUT/ablation.md.
#
#   bash scripts/rig/ablation.sh OUT [CONFIG.json ...]
#
# Needs the release binary (cargo build --release -p flapssm) and ../shared/reference beside
# the checkout. Wall time on 2 cores: about 2 s per L0/L1 configuration, 1.5–8 min per L2/L3
# one, plus 5 s per check.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: bash scripts/rig/ablation.sh OUT [CONFIG.json ...]}
shift
configs=("$@")
if [ ${#configs[@]} -eq 0 ]; then
  configs=()
  while read -r name; do configs+=("scripts/rig/ablation/$name.json"); done < scripts/rig/order.txt
fi
flapssm=${FLAPSSM:-target/release/flapssm}
reference=${REFERENCE:-../shared/reference/bayiz2021-prssm/reference.npz}
mkdir -p "$out"
[ -f "$out/order.txt" ] || cp scripts/rig/order.txt "$out/order.txt"
for cfg in "${configs[@]}"; do
  name=$(basename "$cfg" .json)
  dir="$out/$name"
  if [ -f "$dir/rig-check.json" ]; then
    echo "$name: done before"
    continue
  fi
  mkdir -p "$dir"
  start=$(date +%s.%N)
  "$flapssm" simulate --source paper --noise-free --wing-config "$cfg" --out "$dir/wing.npz" --quiet > /dev/null
  sim=$(echo "$(date +%s.%N) - $start" | bc)
  "$flapssm" rig check "$dir/wing.npz" --reference "$reference" --out "$dir" --quiet > /dev/null
  rm "$dir/wing.npz"
  cp "$cfg" "$dir/wing-config.json"
  printf '%s: simulated in %.1f s\n' "$name" "$sim" | tee "$dir/wall.txt"
done
python3 scripts/rig/table.py "$out" > "$out/ablation.md"
echo "wrote $out/ablation.md"
