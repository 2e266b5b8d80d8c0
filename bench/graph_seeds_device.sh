source bench/device_build.sh >/dev/null
python3 -m pytest -q -p no:cacheprovider tests/gpu/test_rollout_graph.py 2>&1 | tail -2
d=/tmp/kage-graph-seeds; rm -rf $d
for s in 2 3 4; do for g in no-cuda-graph cuda-graph; do
python3 -m kage.train --train-config-path configs/kage_bench/bases/shape_black.yaml --eval-config-path configs/kage_bench/background/1-eval.yaml --seed $s --out $d/$g-$s --device cuda --total-timesteps 983040 --run-eval-every 30 --$g > $d-$g-$s.log 2>&1 &
done; done; wait
python3 - <<'PY'
import glob,json,os
for p in sorted(glob.glob('/tmp/kage-graph-seeds/*/metrics.jsonl')):
    e=[json.loads(l) for l in open(p) if '"kind": "eval"' in l]; t=[json.loads(l) for l in open(p) if '"kind": "train"' in l]
    kl=sum(x['losses/approx_kl'] for x in t)/len(t); cf=sum(x['losses/clipfrac'] for x in t)/len(t)
    print(os.path.basename(os.path.dirname(p)), ' '.join(f"{r['iteration']}:{r['train']['return']:.0f}({r['train']['success_once']:.2f})" for r in e), f'kl {kl:.4f} clip {cf:.3f}')
PY
