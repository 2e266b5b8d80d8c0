"""A suite's units: what one training run per seed covers. A plain pair is a unit; a sweep (one train
config, several evals) is one unit; under --share-training, the plain pairs of one train config share a
unit. kage.bench run trains units, kage.bench report reads them back, and kage.bench score evaluates a
checkpoint on them: all three take them from here.

A pair trains on one config, or on a mixture or a schedule of mixtures: its suite.json "train" then holds
"stages" ([{"start", "configs": [{"name", "spec_sha256", "weight"}]}]) and "schedule" (the schedule file, or
null for a mixture written in the manifest), and its "name" says what it is ("mixture of 9", or the schedule
file)."""
import dataclasses
import difflib
import os
from typing import Dict, List, Optional

PLAIN_LABEL = "eval"  # the eval label of a plain pair's runs


@dataclasses.dataclass
class Unit:
    """One trained thing per seed: its name (runs/<name>/seed_<s>/), declared axis, and the suite.json
    entries of the pairs it evaluates, in manifest order."""

    name: str
    axis: str
    pairs: List[dict]
    is_sweep: bool = False
    shared: bool = False  # --share-training: several plain pairs of one train config
    labels: Dict[str, str] = dataclasses.field(default_factory=dict)  # pair -> eval label, where not label_of's

    def label(self, pair: dict) -> str:
        return self.labels.get(pair["pair"], label_of(pair))

    @property
    def train(self) -> str:
        """What the unit trains on, by name: its config, "mixture of N", or its schedule file."""
        return self.pairs[0]["train"]["name"]

    @property
    def training(self) -> dict:
        """The suite.json "train" entry of the unit's pairs (one config, a mixture or a schedule)."""
        return self.pairs[0]["train"]

    @property
    def train_configs(self) -> List[str]:
        """The configs the unit trains on, distinct, in order of first appearance (kage.ppo.train labels them
        train, train.1, ...; its "train" evaluation runs the current stage's mixture)."""
        return training_configs(self.training)

    @property
    def evals(self) -> List[str]:
        return [p["eval"]["name"] for p in self.pairs]

    @property
    def eval_labels(self) -> List[str]:
        return [self.label(p) for p in self.pairs]


def training_configs(train: dict) -> List[str]:
    """The distinct configs of a suite.json "train" entry, in order of first appearance."""
    if "stages" not in train:
        return [train["name"]]
    out: List[str] = []
    for stage in train["stages"]:
        out.extend(c["name"] for c in stage["configs"] if c["name"] not in out)
    return out


def train_stem(train: dict) -> str:
    """A file-name stem for a unit's training: the config's or schedule's file stem, or "mixture-of-N"."""
    if "stages" in train and train.get("schedule") is None:
        return f"mixture-of-{len(training_configs(train))}"
    return os.path.splitext(os.path.basename(train.get("schedule") or train["name"]))[0]


def label_of(pair: dict) -> str:
    """A pair's eval label in its own run: "eval" for a plain pair, the eval's name within a sweep."""
    return PLAIN_LABEL if pair["sweep"] is None else pair["sweep_eval"]


def units_of(suite: dict, shared: Optional[Dict[str, List[str]]] = None) -> List[Unit]:
    """The suite's plain pairs and sweeps in manifest order. `shared` ({pair: [unit, label]}, bench.json's under
    --share-training) puts a pair in the shared run that trained it."""
    shared = shared or {}
    units: Dict[str, Unit] = {}
    for pair in suite["pairs"]:
        if pair["pair"] in shared:
            name, label = shared[pair["pair"]]
            unit = units.setdefault(name, Unit(name, "(shared)", [], shared=True))
            unit.pairs.append(pair)
            unit.labels[pair["pair"]] = label
        elif pair["sweep"] is None:
            units[pair["pair"]] = Unit(pair["pair"], pair["declared_axis"], [pair])
        else:
            units.setdefault(pair["sweep"], Unit(pair["sweep"], pair["declared_axis"], [], is_sweep=True)).pairs.append(pair)
    return list(units.values())


def select(units: List[Unit], wanted: Optional[List[str]], program: str) -> List[Unit]:
    """The `wanted` units (all when none are named), refusing a name the suite lacks with the near names, and
    one eval of a sweep (a sweep trains as a whole)."""
    if not wanted:
        return units
    by_name = {u.name: u for u in units}
    chosen = []
    for name in wanted:
        if name in by_name:
            chosen.append(by_name[name])
            continue
        sweep = next((u.name for u in units if u.is_sweep and name.startswith(u.name + "/")), None)
        if sweep:
            raise SystemExit(f"{program}: {name} is one eval of the sweep '{sweep}'; select the sweep as a whole")
        close = difflib.get_close_matches(name, by_name, n=3)
        hint = f"; did you mean {', '.join(close)}?" if close else f"; the suite has {', '.join(list(by_name)[:6])} ..."
        raise SystemExit(f"{program}: no pair or sweep named '{name}' in the suite{hint}")
    return chosen
