#!/usr/bin/env bash
# One device-machine call for kage.jax on the GPU (issue 23, item 4): build (lab/tools/device_build.sh;
# the package gets kage.jax where the device's python3 has JAX), then the parts in PARTS, and a summary:
#   equal   kage.jax's jitted scan = make_vec(device="cuda"), byte for byte, 600 steps (past the reset at
#           500): simplest, hardest, filters/7-eval (pixelate: the frame-pass path), filters/6-eval (noise)
#   speed   a random-action lax.scan beside `kagec bench --gpu`, same config and batch (2^14 environments)
#   trace   that scan under the profiler: GPU events per step, host copies and synchronisations
#   train1  examples/jax_ppo.py on shape_black, 1 seed, TIMESTEPS steps
#   train8  the same, 8 seeds vmapped
#   torch   the PyTorch trainer's lone and packed (K = 8) rates on the same card (kage.bench speed)
# Each part fits well within one call; a warm machine keeps the build. Make .deps first
# (lab/tools/make_deps.sh), then with run's carry [".deps"]:
#   PARTS="equal speed trace" bash lab/tools/jax_device.sh
#   PARTS="train1 train8 torch" bash lab/tools/jax_device.sh
set -uo pipefail
source lab/tools/device_build.sh
PARTS=${PARTS:-equal speed trace}
# 104 iterations of 128 x 128 steps: the length of the lone PyTorch run of shape_black that reached train
# success_once 0.96 (lab/2026-11-23-h100-lone-run-background-1).
TIMESTEPS=${TIMESTEPS:-1703936}
SHAPE=configs/kage_bench/bases/shape_black.yaml
check() { python3 lab/tools/jax_check.py "$@"; }
python3 -c 'import jax; print("jax", jax.__version__, jax.devices())' 2>&1 | tee -a "$OUT/gpu.txt"
git rev-parse HEAD 2>/dev/null | tee -a "$OUT/gpu.txt"
: >"$OUT/summary.txt"
for part in $PARTS; do
  case $part in
    equal)
      check equal configs/throughput/simplest.yaml configs/throughput/hardest.yaml \
        configs/kage_bench/filters/7-eval.yaml configs/kage_bench/filters/6-eval.yaml 2>&1 | tee "$OUT/equal.log"
      grep -E '^equal|Error' "$OUT/equal.log" >>"$OUT/summary.txt" ;;
    speed)
      for c in simplest hardest; do
        check speed configs/throughput/$c.yaml --envs 16384 --steps 200
        "$BUILD/kagec" bench configs/throughput/$c.yaml --gpu --min-log2 14 --max-log2 14
      done 2>&1 | tee "$OUT/speed.log"
      grep -E '^speed|^\| [a-z]|Error' "$OUT/speed.log" >>"$OUT/summary.txt" ;;
    trace)
      check trace configs/throughput/simplest.yaml --envs 16384 --steps 20 2>&1 | tee "$OUT/trace.log"
      grep -E '^trace|Error' "$OUT/trace.log" >>"$OUT/summary.txt" ;;
    train1 | train8)
      seeds=${part#train}
      python3 examples/jax_ppo.py --config "$SHAPE" --num-seeds "$seeds" --total-timesteps "$TIMESTEPS" \
        >"$OUT/$part.jsonl" 2>"$OUT/$part.err" || tail -20 "$OUT/$part.err"
      check train "$OUT/$part.jsonl" 2>&1 | tee -a "$OUT/summary.txt" ;;
    torch)
      python3 -m kage.bench speed --packs 1,8 --device cuda --json "$OUT/torch_speed.jsonl" 2>&1 |
        grep -v '^iteration\|^kage.ppo.train' | tee "$OUT/torch_speed.log"
      tail -n 4 "$OUT/torch_speed.log" >>"$OUT/summary.txt" ;;
    *) echo "unknown part '$part' (equal speed trace train1 train8 torch)" | tee -a "$OUT/summary.txt" ;;
  esac
done
echo "== summary"
cat "$OUT/summary.txt"
