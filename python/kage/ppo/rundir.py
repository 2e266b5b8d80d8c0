"""A training run's directory: what it was trained on, its log, its checkpoint and its summary.

    DIR/run.json                 arguments, code version, the configs' labels, paths and spec hashes, and for a
                                 mixture or schedule its stages (start, configs by label, weights)
    DIR/configs/<label>.json     every config's resolved Spec (kagec resolve); "train" is the train config (the
                                 first of a mixture or schedule, whose others are "train.1", "train.2", ...)
    DIR/certificates/<label>.json  the train/eval pair's certificate (kagec diff --certify)
    DIR/metrics.jsonl            one row per iteration ("kind": "train") and per evaluation ("kind": "eval")
    DIR/checkpoints/latest.pt    parameters, optimizer, random streams, environments' state, loop state: data
                                 only (kage.ppo.checkpoint), never unpickled
    DIR/summary.json             at the end: min, mean, median and max of every evaluated value (§3.4)
    DIR/run.lock                 while a trainer writes the directory: its host, process and start (kage.util.lock)

Nothing is lost when the process is killed: files are replaced atomically (written beside, then
renamed), log rows are flushed and synced one by one, and a rerun with the same arguments resumes from
the checkpoint, dropping the log rows written after it (and saying so), so the log has no gap and no
duplicate. A finished run (summary.json) is never touched again; a config whose Spec changed since the run
started is refused.

A resume proves that the checkpoint, the log and the arguments belong together, or refuses naming what
disagrees: the checkpoint's content hash (kage.ppo.checkpoint), the arguments and configs' spec hashes it
records against the command line's, and the SHA-256 of the log's bytes up to its iteration against
metrics.jsonl. A directory with a checkpoint or log rows but no run.json is refused. One trainer writes a run directory at a time: a second one refuses at once, naming the first.
"""
import contextlib
import dataclasses
import hashlib
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time
from typing import Dict, List, Optional, Tuple

import torch

from kage import front_end, resources
from kage.errors import ConfigError
from kage.fields import SUCCESS_SHOWN
from kage.ppo import checkpoint, plugins, schedule
from kage.ppo.args import DEFAULT_AUGMENT_MODE, configs_of, first_train_config, stages_of, training_label
from kage.util.files import atomic_write, named_errors, read_json_record, remove_strays, safe, write_json
from kage.util.lock import DirectoryLock, LockHeld

# Arguments that may differ on resume; a schedule file named by another path (cur.yaml, then /abs/cur.yaml) is
# held to the run by its configs and stages, which check_same_run compares themselves.
_RESUMABLE_CHANGES = {"out", "threads", "train_schedule"}
# Arguments added since runs were first written, with the value that means what a run without them did.
_ADDED_ARGUMENTS = {"agent": "kage.ppo.agent:nature_cnn", "augment": None, "video_every": 0, "drac_coef": 0.1,
                    "train_config_paths": [], "train_weights": [], "train_schedule": None}


def code_version() -> str:
    """The git commit of the sources this package was built from, with "+dirty" for local changes: read
    now from a build tree's checkout, or as an installed package's build recorded it."""
    root = resources.source_root()
    if root is None:
        from kage import _version  # written by CMake at the build's configure step

        return _version.commit
    try:
        commit = subprocess.run(["git", "-C", root, "rev-parse", "HEAD"], capture_output=True, text=True, check=True)
        dirty = subprocess.run(["git", "-C", root, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True)
        return commit.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown (no git checkout at the build's source root)"


def json_args(args) -> dict:
    """The arguments as JSON values (an infinite float as the string "inf" or "-inf")."""
    return {k: (str(v) if isinstance(v, float) and not math.isfinite(v) else v) for k, v in dataclasses.asdict(args).items()}


def default_dir(args) -> str:
    """runs/<exp-name>__<stem>__<seed>: the stem of the train config, of a schedule file, or of a mixture's first
    config followed by +<number of configs>."""
    named = args.train_schedule or first_train_config(args)
    stem = os.path.splitext(os.path.basename(named.rstrip("/")))[0]
    if args.train_config_paths and len(args.train_config_paths) > 1:
        stem += f"+{len(args.train_config_paths)}"
    return os.path.join("runs", f"{args.exp_name}__{stem}__{args.seed}")


def is_finished(path: str) -> bool:
    return os.path.exists(os.path.join(path, "summary.json"))


_held: List["RunDir"] = []  # the run directories this process has open, in opening order


@contextlib.contextmanager
def held_open():
    """Closes (and unlocks) the run directories opened inside the block, however it ends."""
    before = len(_held)
    try:
        yield
    finally:
        while len(_held) > before:
            _held.pop().close()


class RunDir:
    def __init__(self, path: str, specs: Dict[str, dict], lock: DirectoryLock, identity: Optional[dict] = None):
        self.path = path
        self.specs = specs
        self.lock = lock
        self.identity = identity  # {"args": json_args, "configs": {label: {"path", "spec_sha256"}}}, in checkpoints
        self._log = None
        self._log_digest, self._log_bytes, self._log_rows = hashlib.sha256(), 0, 0  # metrics.jsonl so far
        self._warned_not_finite = False
        _held.append(self)

    @property
    def finished(self) -> bool:
        return is_finished(self.path)

    def close(self) -> None:
        if self._log is not None:
            self._log.close()
            self._log = None
        self.lock.release()

    def _check_still_held(self) -> None:
        if self.lock.lost:
            raise SystemExit(f"kage.ppo.train: {self.path}: another process took this run directory over (this one "
                             "was taken for dead: no heartbeat); stopping without writing more")

    @classmethod
    def open(cls, args, configs: List[Tuple[str, str]], specs: Dict[str, dict]) -> "RunDir":
        """The run directory of `args`, which trains and evaluates on `configs` ((label, path): "train"
        first) whose resolved Specs are `specs`: locked, then created with its description, or checked against it."""
        path = args.out or default_dir(args)
        described = {label: {"path": config, "spec_sha256": specs[label]["sha256"]} for label, config in configs}
        stages = stages_description(args)
        os.makedirs(path, exist_ok=True)
        lock = DirectoryLock(path, "run", "kage.ppo.train")
        try:
            lock.acquire("Wait for it to end or stop it, or use another --out")
        except LockHeld as e:
            raise SystemExit(f"kage.ppo.train: {e}") from None
        try:
            describe_or_check(path, args, configs, specs, described, stages)
        except BaseException:
            lock.release()
            raise
        return cls(path, specs, lock, {"args": json_args(args), "configs": described, "stages": stages})


    # ---- the log ----

    def log(self, row: dict) -> dict:
        """Appends one row to metrics.jsonl, flushed and synced; returns it. A value that is not finite (a
        diverged run's losses, or approx_kl where a collapsed policy's probability ratio overflows) is
        written as null, with a warning the first time: the run's log stays valid JSON, and the other runs
        of its pack go on."""
        self._check_still_held()
        if self._log is None:
            self._log = open(os.path.join(self.path, "metrics.jsonl"), "ab")
        bad = sorted(k for k, v in row.items() if isinstance(v, float) and not math.isfinite(v))
        if bad:
            row = {k: None if k in bad else v for k, v in row.items()}
            if not self._warned_not_finite:
                print(f"kage.ppo.train: warning: {self.path}: {', '.join(bad)} not finite at iteration "
                      f"{row.get('iteration')}; such values are logged as null",
                      file=sys.stderr, flush=True)
                self._warned_not_finite = True
        line = (json.dumps(row, sort_keys=True, allow_nan=False) + "\n").encode()
        with named_errors(self._log.name):
            self._log.write(line)
            self._log.flush()
            os.fsync(self._log.fileno())
        self._log_digest.update(line)
        self._log_bytes, self._log_rows = self._log_bytes + len(line), self._log_rows + 1
        return row

    def _restart_log(self, recorded: Optional[dict], iteration: int) -> None:
        """Checks that metrics.jsonl begins with the bytes a checkpoint recorded (`recorded`: bytes, rows,
        sha256; None for no checkpoint), then drops what follows them, saying so: those rows are written again."""
        path = os.path.join(self.path, "metrics.jsonl")
        try:
            with open(path, "rb") as f:
                data = f.read()
        except FileNotFoundError:
            data = b""
        keep = recorded["bytes"] if recorded else 0
        if recorded and (len(data) < keep or hashlib.sha256(data[:keep]).hexdigest() != recorded["sha256"]):
            raise SystemExit(f"kage.ppo.train: {log_problem(path, data, keep, iteration)}; restore the log, or train "
                             "anew with another --out")
        dropped = data[keep:]
        if dropped:
            print(f"kage.ppo.train: {path}: {dropped_text(dropped)} written after "
                  f"{f'the checkpoint of iteration {iteration}' if recorded else 'the run started (no checkpoint yet)'} "
                  "dropped; this run writes them again", file=sys.stderr, flush=True)
            atomic_write(path, data[:keep])
        self._log_digest = hashlib.sha256(data[:keep])
        self._log_bytes, self._log_rows = keep, recorded["rows"] if recorded else 0

    # ---- checkpoints ----

    def checkpoint_snapshot(self, state: dict) -> dict:
        """`state` (copies of the run's tensors, not the ones training goes on changing) with what proves it this
        run's: its identity, and the log it ends (metrics.jsonl's bytes, rows and SHA-256 so far)."""
        self._check_still_held()
        return dict(state, identity=self.identity,
                    log={"bytes": self._log_bytes, "rows": self._log_rows, "sha256": self._log_digest.hexdigest()})

    def write_checkpoint(self, snapshot: dict) -> None:
        """checkpoints/latest.pt, and latest.json naming its iteration (read by kage.bench to pack runs
        that resume from the same iteration without loading the checkpoints); on the checkpoint writer's thread
        (kage.ppo.checkpoint_writer)."""
        self._check_still_held()
        atomic_write(os.path.join(self.path, "checkpoints", "latest.pt"), checkpoint.encode(snapshot))
        write_json(os.path.join(self.path, "checkpoints", "latest.json"), {"iteration": snapshot["iteration"]})

    def load_checkpoint(self) -> Optional[dict]:
        """The latest checkpoint, proven to be this run's (and the log cut back to it), or None for a fresh run
        (the log emptied)."""
        path = os.path.join(self.path, "checkpoints", "latest.pt")
        if not os.path.exists(path):
            self._restart_log(None, 0)
            return None
        try:
            state = checkpoint.load(path)
        except checkpoint.CheckpointError as e:
            raise SystemExit(f"kage.ppo.train: {e}; restore it, or train anew with another --out") from None
        self._check_identity(path, state)
        self._restart_log(state["log"], state["iteration"])
        return state

    def _check_identity(self, path: str, state: dict) -> None:
        """Refuses a checkpoint that records other arguments or configs than this run's (another seed's copied in,
        or one written before checkpoints recorded them)."""
        recorded, log = state.get("identity"), state.get("log")
        if not (isinstance(recorded, dict) and isinstance(recorded.get("args"), dict) and
                isinstance(recorded.get("configs"), dict) and isinstance(log, dict) and
                all(isinstance(log.get(k), int) and log[k] >= 0 for k in ("bytes", "rows")) and
                isinstance(log.get("sha256"), str)):
            raise SystemExit(f"kage.ppo.train: {path} does not record the arguments, configs and log it belongs to "
                             "(an earlier kage.ppo.train wrote it, or it was edited), so it cannot be proven to be this run's: finish "
                             "the run with that version, or train anew with another --out")
        problems = [f"{k}: {v!r} in the checkpoint, {self.identity['args'][k]!r} now"
                    for k, v in changed_arguments(recorded["args"], self.identity["args"])]
        for label, now in self.identity["configs"].items():
            before = recorded["configs"].get(label)
            if before != now:
                problems.append(f"config {label}: {before} in the checkpoint, {now} now")
        if recorded.get("stages") != self.identity["stages"]:
            problems.append(f"stages: {recorded.get('stages')} in the checkpoint, {self.identity['stages']} now")
        if problems:
            raise SystemExit(f"kage.ppo.train: {path} belongs to another run ({'; '.join(problems)}): restore this "
                             "run's checkpoint, or train anew with another --out")

    # ---- the summary ----

    def finish(self, history: List[dict]) -> None:
        """summary.json: per evaluated value, its min, mean, median and max over all evaluation points,
        iteration 0 and the final one included (§3.4); each statistic over the points that have a value."""
        self._check_still_held()
        write_json(os.path.join(self.path, "summary.json"), summarize(history))


def stages_description(args) -> Optional[List[dict]]:
    """A mixture's or schedule's stages as run.json records them (each config by its label), None for one config."""
    stages = stages_of(args)
    if not schedule.is_mixture(stages):
        return None
    label_of = {path: training_label(i) for i, path in enumerate(schedule.distinct_configs(stages))}
    return [dict(stage.describe(), configs=[label_of[c] for c in stage.configs]) for stage in stages]


def check_env(specs: Dict[str, dict], labels: List[str], env) -> None:
    """Refuses a batch that runs other Specs than those resolved for `labels` (its configs, one unless a
    mixture: a config file changed between the two reads)."""
    hashes = [specs[label]["sha256"] for label in labels]
    recorded = hashes[0] if isinstance(env.config, str) else front_end.mixture_hash(hashes, env.counts)
    if env.spec_hash != recorded:
        raise SystemExit(f"kage.ppo.train: config '{env.config}' ({label}) changed while the run was being opened "
                         f"(spec {recorded[:12]} resolved, {env.spec_hash[:12]} in the environment): run again")


def resolve_configs(configs: List[Tuple[str, str]], asset_root: Optional[str]) -> Tuple[Dict[str, dict], Dict[str, dict]]:
    """Each config's resolved Spec, and the run's description of them ({label: {"path", "spec_sha256"}})."""
    specs = {}
    for label, config in configs:
        if not os.path.exists(config):  # not a path, and (--flags resolved them) not a shipped name
            try:
                resources.config_path(config)
            except FileNotFoundError as e:  # names the shipped configs nearest to it
                raise SystemExit(f"kage.ppo.train: ({label}) {e}") from None
        try:
            specs[label] = front_end.resolve(config, asset_root)
        except ConfigError as e:
            raise SystemExit(f"{e}\nkage.ppo.train: config '{config}' ({label}) has the errors above: fix the config "
                             "first") from None
    return specs, {label: {"path": config, "spec_sha256": specs[label]["sha256"]} for label, config in configs}


def check_finished(path: str, args, configs: List[Tuple[str, str]]) -> None:
    """Refuses a finished run's directory to other arguments or changed configs, as a resume would (reads only)."""
    previous = read_run_json(os.path.join(path, "run.json"))
    check_same_run(path, previous, json_args(args), resolve_configs(configs, args.asset_root)[1],
                   stages_description(args))


def read_run_json(path: str) -> dict:
    """A run's run.json, refused by name where it is not JSON or lacks what a run records."""
    run, problem = read_json_record(path, run_json_problem)
    if problem:
        raise SystemExit(f"kage.ppo.train: {path}: {problem}: restore it from a copy, or train anew with another --out")
    return run


def run_json_problem(run) -> Optional[str]:
    """What a run.json's content lacks: its arguments, and each config's path and spec hash."""
    if not (isinstance(run, dict) and isinstance(run.get("args"), dict) and isinstance(run.get("configs"), dict)):
        return "it lacks the run's arguments and configs"
    for label, config in run["configs"].items():
        if not (isinstance(config, dict) and isinstance(config.get("path"), str) and
                isinstance(config.get("spec_sha256"), str)):
            return f"config {label!r} is not described by a path and a spec_sha256"
    return None


def describe_or_check(path: str, args, configs: List[Tuple[str, str]], specs: Dict[str, dict],
                      described: Dict[str, dict], stages: Optional[List[dict]]) -> None:
    """Under the run's lock: a new run's description written (run.json last), or an existing one checked against
    `args` and `described`; dead writers' temporary files removed."""
    for folder in ("", "configs", "certificates", "checkpoints", "videos"):
        remove_strays(os.path.join(path, folder))  # a killed writer's, or one that met a full disk
    run_json = os.path.join(path, "run.json")
    log = os.path.join(path, "metrics.jsonl")
    if os.path.exists(run_json):
        difference = run_difference(path, read_run_json(run_json), json_args(args), described, stages)
        if difference is None:
            return
        if os.path.exists(os.path.join(path, "checkpoints", "latest.pt")):
            raise SystemExit(difference)
        # Stopped before its first checkpoint (an augmentation that failed on real frames, say): nothing to resume,
        # so a rerun with corrected arguments starts the run over rather than being refused.
        print(f"kage.ppo.train: {path} stopped before its first checkpoint, so nothing is lost: starting it over "
              "with these arguments, not those it was started with", file=sys.stderr, flush=True)
        for folder in ("configs", "certificates"):
            shutil.rmtree(os.path.join(path, folder), ignore_errors=True)
        for stale in (run_json, log):
            if os.path.exists(stale):
                os.remove(stale)
    if os.path.exists(os.path.join(path, "checkpoints", "latest.pt")) or (os.path.exists(log) and os.path.getsize(log)):
        raise SystemExit(f"kage.ppo.train: {path} has a checkpoint or log rows but no run.json, so nothing shows which "
                         "arguments and configs they belong to: restore run.json, or train anew with another --out")
    os.makedirs(os.path.join(path, "configs"), exist_ok=True)
    os.makedirs(os.path.join(path, "certificates"), exist_ok=True)
    os.makedirs(os.path.join(path, "checkpoints"), exist_ok=True)
    training = schedule.distinct_configs(stages_of(args))
    for label, config in configs:
        write_json(os.path.join(path, "configs", f"{safe(label)}.json"), specs[label])
        if label not in {training_label(i) for i in range(len(training))}:
            certificate = front_end.certify(first_train_config(args), config, args.asset_root)
            write_json(os.path.join(path, "certificates", f"{safe(label)}.json"), certificate)
            if not certificate["certified"]:  # a pair that is no visual shift: its scores would read as one
                print(f"kage.ppo.train: warning: eval config {label} ({config}) is not certified against the train "
                      f"config: {'; '.join(certificate['problems'])}; its scores do not measure a visual shift "
                      f"(certificates/{safe(label)}.json)", file=sys.stderr)
    write_json(run_json, {
        "kage_run": 1, "args": json_args(args), "argv": sys.argv, "configs": described, "stages": stages,
        "code_version": code_version(), "python": sys.version.split()[0], "torch": torch.__version__,
        "device_name": torch.cuda.get_device_name() if args.device == "cuda" and torch.cuda.is_available()
        else "cpu", "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "derived": {"batch_size": args.batch_size, "minibatch_size": args.minibatch_size,
                    "num_iterations": args.num_iterations}})


def optimizer_run_state(optimizer: torch.optim.Adam, agent, run: int) -> dict:
    """Run `run`'s Adam moments (in its parameters' shapes) and the shared step count."""
    state = {}
    for name, p in agent.named_parameters():
        s = optimizer.state.get(p, {})
        state[name] = {k: (agent.run_view(v)[run].cpu().clone() if k != "step" else
                           v.cpu().clone() if torch.is_tensor(v) else v) for k, v in s.items()}
    return state


def load_optimizer(optimizer: torch.optim.Adam, agent, runs: List[dict]) -> None:
    """Rebuilds the pack's Adam state from each run's saved part."""
    for name, p in agent.named_parameters():
        if not runs[0][name]:
            continue
        state = {}
        for key, value in runs[0][name].items():
            if key == "step":  # on the host, except under fused Adam, whose kernel reads it on the device
                state[key] = (value.to(p.device) if optimizer.defaults.get("fused") else value.clone()) \
                    if torch.is_tensor(value) else value
            else:
                state[key] = torch.empty_like(p).copy_(torch.cat([r[name][key] for r in runs]).to(p.device))
        optimizer.state[p] = state


def summarize(history: List[dict]) -> dict:
    series: Dict[str, List[Optional[float]]] = {}
    for point in history:
        for key, value in flatten_evaluation(point).items():
            series.setdefault(key, []).append(value)
    return {"kage_summary": 1, "evaluations": len(history),
            "iterations": [p["iteration"] for p in history], "global_steps": [p["global_step"] for p in history],
            "stats": {key: statistics_of(values) for key, values in sorted(series.items())}}


def flatten_evaluation(point: dict) -> Dict[str, Optional[float]]:
    """An evaluation row as flat keys: train/<metric>, eval/<label>/<metric>, diff/<label>/<metric>."""
    flat = {f"train/{m}": v for m, v in point["train"].items() if m != "episodes"}
    for label, result in point["evals"].items():
        flat.update({f"eval/{label}/{m}": v for m, v in result.items() if m != "episodes"})
    for label, diff in point["diffs"].items():
        flat.update({f"diff/{label}/{m}": v for m, v in diff.items()})
    return flat


def statistics_of(values: List[Optional[float]]) -> Optional[dict]:
    present = [v for v in values if v is not None]
    if not present:
        return None
    return {"min": min(present), "mean": statistics.fmean(present), "median": statistics.median(present),
            "max": max(present), "n": len(present)}


def log_problem(path: str, data: bytes, keep: int, iteration: int) -> str:
    """Why the log's first `keep` bytes are not those the checkpoint of `iteration` recorded."""
    for number, line in enumerate(data[:keep].splitlines(), 1):
        try:
            json.loads(line)
        except ValueError:
            return f"{path} line {number} is damaged (not a JSON row), before the checkpoint of iteration {iteration}"
    if len(data) < keep:
        return (f"{path} has {len(data)} bytes, but {keep} were written up to the checkpoint of iteration {iteration}: "
                "rows are missing")
    return f"{path}: its rows up to the checkpoint of iteration {iteration} differ from those written then (edited?)"


def dropped_text(dropped: bytes) -> str:
    """'2 log rows (iterations 3-4)', with a partly written last line where there is one."""
    iterations, torn = [], False
    for line in dropped.splitlines():
        try:
            iterations.append(json.loads(line)["iteration"])
        except (ValueError, KeyError, TypeError):
            torn = True
    text = f"{len(iterations)} log row{'s' if len(iterations) != 1 else ''}"
    if iterations:
        span = f"{min(iterations)}-{max(iterations)}" if min(iterations) != max(iterations) else str(iterations[0])
        text += f" (iteration{'s' if min(iterations) != max(iterations) else ''} {span})"
    return text + (" and a partly written line" if torn else "")


def changed_arguments(before: dict, now: dict) -> List[Tuple[str, object]]:
    """(name, value before) of each argument in `now` that differs from `before` (arguments added since count
    with their earlier meaning; moved module paths name the same code), those a resume may change left out."""
    before = dict(_ADDED_ARGUMENTS, **before)
    before.setdefault("augment_mode", recorded_mode(before))
    for key in ("agent", "augment"):
        before[key] = plugins.current_reference(before.get(key))
    return [(k, before.get(k)) for k in sorted(now) if k not in _RESUMABLE_CHANGES and before.get(k) != now[k]]


def recorded_mode(recorded_args: dict) -> Optional[str]:
    """The --augment-mode a run's recorded arguments mean: the one recorded, or, for a run started before the flag
    existed, update (the only mode then) where it had an --augment."""
    if "augment_mode" in recorded_args:
        return recorded_args["augment_mode"]
    return "update" if recorded_args.get("augment") else None


def with_augment_mode(args):
    """`args` with --augment-mode's default made explicit: the mode its run directory was started in, where it
    has a run.json that records an --augment, else drac whenever --augment is given."""
    if args.augment_mode or not args.augment:
        return args
    mode = DEFAULT_AUGMENT_MODE
    path = os.path.join(args.out or default_dir(args), "run.json")
    if os.path.isfile(path):
        recorded, problem = read_json_record(path, run_json_problem)
        if not problem and recorded["args"].get("augment"):
            mode = recorded_mode(recorded["args"]) or DEFAULT_AUGMENT_MODE
    return dataclasses.replace(args, augment_mode=mode)


def check_same_run(path: str, previous: dict, args: dict, configs: dict, stages: Optional[List[dict]]) -> None:
    """Refuses to resume `path` with other arguments, with configs whose Spec changed, or with other stages."""
    difference = run_difference(path, previous, args, configs, stages)
    if difference:
        raise SystemExit(difference)


def run_difference(path: str, previous: dict, args: dict, configs: dict, stages: Optional[List[dict]]) -> Optional[str]:
    """Why `args`, `configs` and `stages` are not the run recorded in `previous` (the message and its fix), or None."""
    for label, now in configs.items():
        before = previous["configs"].get(label)
        if before is None or before["path"] != now["path"]:
            then = "no such config" if before is None else before["path"]
            return (f"kage.ppo.train: {path} was started with other configs ({label}: {then} then, {now['path']} "
                    "now): rerun with the original configs to resume, or use another --out")
        if before["spec_sha256"] != now["spec_sha256"]:
            return (f"kage.ppo.train: config '{now['path']}' ({label}) changed since {path} started (spec "
                    f"{before['spec_sha256'][:12]} then, {now['spec_sha256'][:12]} now): restore it, or start a new "
                    "run with another --out")
    if previous.get("stages") != stages:
        return (f"kage.ppo.train: {path} was started with other training stages ({previous.get('stages')} then, "
                f"{stages} now): restore the schedule or weights, or use another --out")
    changed = changed_arguments(previous["args"], args)
    if changed:
        details = ", ".join(f"{k}: {before!r} then, {args[k]!r} now" for k, before in changed)
        return (f"kage.ppo.train: {path} was started with other arguments ({details}); rerun with the original ones "
                "to resume, or use another --out")
    return None


class Progress:
    """One line on stderr every 10 s and at each evaluation: iteration, steps, steps/s and the ETA, which counts the
    evaluation points still to come at the mean time of those so far; and a line as each evaluation point starts."""

    def __init__(self, iterations: int, batch: int, eval_every: int):
        self.iterations, self.batch, self.eval_every = iterations, batch, eval_every
        self.start = time.time()
        self.first_iteration = None
        self.last_print = 0.0
        self.eval_seconds, self.eval_points, self.eval_start = 0.0, 0, None

    def evaluating(self, iteration: int, configs: int, episodes: int) -> None:
        """Says that the evaluation point of `iteration` starts (it can take minutes, silently)."""
        self.eval_start = time.time()
        print(f"iteration {iteration}: evaluating {episodes} episodes on each of {configs} configs",
              file=sys.stderr, flush=True)

    def evaluated(self) -> None:
        self.eval_seconds += time.time() - self.eval_start
        self.eval_points += 1

    def points_after(self, iteration: int) -> int:
        """The evaluation points after `iteration`: every eval_every-th iteration, and the last."""
        if self.eval_every <= 0:
            return 0
        every = self.iterations // self.eval_every - iteration // self.eval_every
        return every + (1 if self.iterations % self.eval_every and iteration < self.iterations else 0)

    def update(self, iteration: int, global_step: int, row: dict, evaluation: Optional[dict]) -> None:
        if self.first_iteration is None:
            self.first_iteration = iteration
        now = time.time()
        if evaluation is None and now - self.last_print < 10 and iteration != self.iterations:
            return
        self.last_print = now
        done = iteration - self.first_iteration + 1
        training = (now - self.start - self.eval_seconds) / done * (self.iterations - iteration)
        points = self.points_after(iteration)
        if self.eval_points:
            eta = f"ETA {(training + self.eval_seconds / self.eval_points * points) / 60:.1f} min"
        else:
            eta = f"ETA {training / 60:.1f} min" + (f" and {points} evaluation points" if points else "")
        line = (f"iteration {iteration}/{self.iterations}  step {global_step:,}  "
                f"{row['charts/SPS']:,.0f} steps/s  {eta}")
        if evaluation is not None:
            train = evaluation["train"]
            line += f"  | eval return {fmt(train['return'])} {SUCCESS_SHOWN} {train[SUCCESS_SHOWN]:.2f}"
            for label, result in evaluation["evals"].items():
                line += f"  {label}: {fmt(result['return'])} / {result[SUCCESS_SHOWN]:.2f}"
        print(line, file=sys.stderr, flush=True)


def fmt(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.1f}"
