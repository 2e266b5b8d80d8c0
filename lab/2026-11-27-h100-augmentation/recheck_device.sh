#!/usr/bin/env bash
# The second lease of the augmentation issue (one GPU, run's carry [".deps"]), after the first showed DrAC's raw
# value term collapsing every seed and random_conv and gaussian_noise under their speed floors:
# - PART=speed: the build, tests/gpu/test_augment_gpu.py, and kage.bench speed --packs 16 with the table's flags
#   for the plain path, random_conv and gaussian_noise under update and drac (their rollout rows met the floor);
# - PART=learn: IMAGE_SKELETON with color_jitter under drac (G_V in units of the returns' standard deviation),
#   seeds 1-4 in one pack, STEPS steps (4 M by default), evaluated on filters/1's eval config; the learning summary
#   and the runs' logs come back.
set -uo pipefail
source lab/tools/device_build.sh
export TRITON_CACHE_DIR=${TRITON_CACHE_DIR:-/tmp/kage-triton-cache}
FAST="--bf16 --fused-input --cuda-graph --triton-conv"
RUNS=${RUNS:-/tmp/kage-augment-recheck}
mkdir -p "$RUNS"
if [ "${PART:?PART=speed or PART=learn}" = speed ]; then
  python3 -m pytest -q -p no:cacheprovider tests/gpu/test_augment_gpu.py 2>&1 | tail -3 | tee "$OUT/gpu_tests.txt"
  for flags in "" "--augment kage.ppo.augment:random_conv --augment-mode update" \
      "--augment kage.ppo.augment:random_conv --augment-mode drac" \
      "--augment kage.ppo.augment:gaussian_noise --augment-mode update" \
      "--augment kage.ppo.augment:gaussian_noise --augment-mode drac"; do
    # shellcheck disable=SC2086
    python3 -m kage.bench speed --packs 16 --device cuda $FAST --json "$OUT/speed.jsonl" $flags 2>&1 | grep '^| 16'
  done
  exit 0
fi
python3 -m kage.bench run kage_bench --pairs filters/1 --seeds 1-4 --share-training --pack 4 --device cuda $FAST \
  --total-timesteps "${STEPS:-4000000}" --augment kage.ppo.augment:color_jitter --augment-mode drac \
  --out "$RUNS/drac" 2>&1 | grep -v '^iteration' | tail -3
python3 lab/tools/learning_summary.py "$RUNS/drac" | tee "$OUT/drac_summary.txt"
tar -czf "$OUT/drac.tar.gz" -C "$RUNS" --exclude checkpoints --exclude tensorboard drac
