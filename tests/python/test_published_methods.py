"""The published methods (results/methods/METHOD/packs) unpack with their checksums, and the tables of
results/methods/README.md are those that lab/tools/methods_tables.py computes from the packs now, as
test_published_table.py checks the baseline's table. The tool itself runs here on a stand-in method made of two of
the baseline's own packs, and its marker replacement (lab/tools/generated_block.py) on small pages."""
import json
import re
import shutil
import subprocess
import sys

import pytest

from support import ROOT

METHODS = ROOT / "results/methods"
BASELINE_PACKS = ROOT / "results/kage-bench-table/packs"
TOOLS = ROOT / "lab/tools"
UNPACK = TOOLS / "table_unpack.py"
TOOL = TOOLS / "methods_tables.py"
sys.path.insert(0, str(TOOLS))
import generated_block  # noqa: E402 (lab/tools is no package)
import methods_tables  # noqa: E402


def tool(*args):
    return subprocess.run([sys.executable, str(TOOL), *map(str, args)], capture_output=True, text=True)


def block_of(readme) -> str:
    return generated_block.generated(readme.read_text(), methods_tables.TOOL, str(readme))


def section(block: str, heading: str) -> str:
    """The part of `block` from its `### heading` to the next heading."""
    return block.split(f"### {heading}", 1)[1].split("\n### ", 1)[0]


def row(block: str, *first_cells: str) -> list:
    """The cells of the one table row of `block` that begins with `first_cells`."""
    found = [line for line in block.splitlines() if line.startswith("| " + " | ".join(first_cells) + " |")]
    assert len(found) == 1, f"no single row {first_cells} in:\n{block}"
    return [cell.strip() for cell in found[0].strip("|").split("|")]


# ---- the published methods ----

def test_every_published_method_unpacks_with_its_checksums(tmp_path):
    methods = methods_tables.published(str(METHODS))
    if not methods:
        pytest.skip("results/methods publishes no method yet (no METHOD/packs/task_I.tar.gz): this test checks "
                    "each method's checksums once its packs are in")
    for method in methods:
        unpack = subprocess.run([sys.executable, str(UNPACK), str(METHODS / method / "packs"), str(tmp_path / method)],
                                capture_output=True, text=True)
        assert unpack.returncode == 0, f"{method}: {unpack.stderr}"
        runs = list((tmp_path / method / "runs").glob("**/summary.json"))
        assert runs, f"{method}: its packs hold no finished run (summary.json)"


def test_the_readme_tables_are_those_of_the_packs_now():
    check = tool("--check")
    assert check.returncode == 0, check.stdout + check.stderr
    block = block_of(METHODS / "README.md")
    methods = methods_tables.published(str(METHODS))
    if not methods:
        assert block == methods_tables.NOTHING_PUBLISHED
        return
    assert row(block, "all pairs", "baseline")[2:4] == ["34", "170"]  # every pair, seeds 1-5
    for method in methods:
        cells = row(section(block, "Eval success per axis"), "all pairs", method)
        assert int(cells[3]) > 0 and re.fullmatch(r"\d\.\d\d \[\d\.\d\d, \d\.\d\d\]", cells[6]), cells
        assert row(section(block, "Training runs"), method)[3] != "0", f"{method} has no training run in the tables"
        assert float(row(section(block, "GPU time"), method)[2]) > 0, f"{method} has no training time in the tables"
    for i, a in enumerate(methods):  # every two methods head to head
        for b in methods[i + 1:]:
            cells = row(section(block, "Methods head to head"), "all pairs", a, b)
            assert int(cells[3]) > 0 and re.fullmatch(r"\d\.\d\d \[\d\.\d\d, \d\.\d\d\]", cells[4]), cells


INTERVAL = re.compile(r"\d+\.\d+(?: %)? \[\d+\.\d+, \d+\.\d+\]")  # "0.54 [0.49, 0.58]", "47.7 % [40.1, 55.2]"


def test_every_interval_the_prose_quotes_is_one_of_the_tables():
    # The answers per axis and their detail are written by hand around the generated tables: a pack added or
    # changed moves the tables, and prose quoting the old intervals must then fail here until it is rewritten.
    text = (METHODS / "README.md").read_text()
    block = block_of(METHODS / "README.md")
    if not methods_tables.published(str(METHODS)):
        pytest.skip("results/methods publishes no method yet: no prose quotes its intervals")
    prose = text.replace(block, "")
    quoted = INTERVAL.findall(prose)
    assert quoted, "the methods README's answers quote no interval of the tables"
    stale = [q for q in quoted if q not in block]
    assert not stale, f"intervals quoted in results/methods/README.md that no table gives (rewrite them): {stale}"


# ---- the tool, on a stand-in method ----

STAND_IN_TASKS = (0, 4)  # SHAPE_BLACK's shared runs (part 1) and background/4's, seeds 1 to 6


def stand_in(tmp_path):
    """A methods folder with one method, "copy", whose packs are two of the baseline's, and the README."""
    root = tmp_path / "methods"
    (root / "copy/packs").mkdir(parents=True)
    for task in STAND_IN_TASKS:
        for suffix in (".tar.gz", ".sha256"):
            shutil.copy(BASELINE_PACKS / f"task_{task}{suffix}", root / "copy/packs")
    shutil.copy(METHODS / "README.md", root)
    return root


def expected_pairs(baseline) -> list:
    """The pairs the stand-in's runs are scored for: those whose run unit is one of its packs'."""
    units = {re.match(r"runs/(.+)/seed_\d+/summary.json$", line.split("  ")[1].strip()).group(1)
             for task in STAND_IN_TASKS for line in open(BASELINE_PACKS / f"task_{task}.sha256")
             if line.rstrip().endswith("/summary.json")}
    bench = json.loads((baseline / "bench.json").read_text())
    suite = json.loads((baseline / "suite.json").read_text())
    return [p["pair"] for p in suite["pairs"] if bench["shared"].get(p["pair"], [p["pair"]])[0] in units]


def test_the_tables_of_a_stand_in_method(tmp_path):
    """The stand-in's runs are the baseline's own, so on every axis it has, its row is the baseline's on the same
    results and P(copy > baseline) is one half; the prose around the markers is kept, and a second run in another
    folder gives the same tables (--check)."""
    root = stand_in(tmp_path)
    written = tool("--methods-root", root, "--work", tmp_path / "work")
    assert written.returncode == 0, written.stderr
    pairs = expected_pairs(tmp_path / "work/baseline")
    assert len(pairs) == 11  # 10 pairs trained on SHAPE_BLACK, and background/4

    page, skeleton = (root / "README.md").read_text(), (METHODS / "README.md").read_text()
    block = block_of(root / "README.md")
    assert page.replace(block, "") == skeleton.replace(block_of(METHODS / "README.md"), "")
    assert row(block, "all pairs", "baseline")[2:4] == ["34", "170"]
    copy = row(block, "all pairs", "copy")
    assert copy[2:4] == [str(len(pairs)), str(5 * len(pairs))] and copy[6].startswith("0.50 [")
    for axis in ("background", "agent", "distractors", "all pairs"):
        assert row(block, axis, "copy")[2:6] == row(block, axis, "baseline, on copy's results")[2:6]
    for axis in ("filters", "effects", "layout"):  # no stand-in run is scored there
        assert row(block, axis, "copy")[2:] == ["0", "0", "-", "-", "-"]
    assert "### Methods head to head" not in block  # one method: no other to match it against
    # 2 run units x seeds 1-5; the baseline's 45 runs of seeds 1-5 include them
    training = section(block, "Training runs")
    assert row(training, "copy")[1:4] == [f"{len(pairs)} of 34", f"{5 * len(pairs)} of 170", "10"]
    assert row(training, "baseline")[1:4] == ["34 of 34", "170 of 170", "45"]
    # GPU time: one row per pack the two tasks hold, a part of the baseline's, on the devices their lists name
    lists = [(BASELINE_PACKS / f"task_{task}.sha256").read_text().splitlines() for task in STAND_IN_TASKS]
    packs = sum(1 for lines in lists for line in lines if re.search(r"  packs/task_\d+_pack_\d+\.json$", line))
    named = sorted({line[len("# device: "):] for lines in lists for line in lines if line.startswith("# device: ")})
    cost, baseline_cost = row(section(block, "GPU time"), "copy"), row(section(block, "GPU time"), "baseline")
    assert cost[1] == str(packs) and cost[6] == "; ".join(named)
    assert 0 < float(cost[2]) < float(baseline_cost[2]) and 0 < float(cost[3]) < float(baseline_cost[3])
    # A pack's logged training and evaluation happen between its first run's run.json and summary.json.
    assert float(cost[4]) <= float(cost[5]) < float(baseline_cost[5])

    again = tool("--methods-root", root, "--check")
    assert again.returncode == 0, again.stdout + again.stderr


def test_two_methods_head_to_head(tmp_path):
    """Two stand-ins with the same runs: where the one has a result, the other ties it, so P(one > other) is one
    half on every axis they cover."""
    root = stand_in(tmp_path)
    shutil.copytree(root / "copy", root / "twin")
    written = tool("--methods-root", root, "--work", tmp_path / "work")
    assert written.returncode == 0, written.stderr
    matches = section(block_of(root / "README.md"), "Methods head to head")
    pairs = expected_pairs(tmp_path / "work/baseline")
    assert row(matches, "all pairs", "copy", "twin")[3] == str(len(pairs))
    for axis in ("background", "agent", "distractors", "all pairs"):
        assert row(matches, axis, "copy", "twin")[4].startswith("0.50 ["), axis
    for axis in ("filters", "effects", "layout"):  # neither has a result there
        assert f"| {axis} |" not in matches


def test_a_method_named_but_not_published_is_refused(tmp_path):
    root = stand_in(tmp_path)
    refused = tool("--methods-root", root, "cope")
    assert refused.returncode != 0
    assert f"{root}/cope/packs has no task_I.tar.gz: publish the method's packs there, or name one of: copy" \
        in refused.stderr


def test_a_readme_without_markers_is_refused_before_any_work(tmp_path):
    root = stand_in(tmp_path)
    (root / "README.md").write_text("# Methods\n\nNo tables here.\n")
    refused = tool("--methods-root", root, "--work", tmp_path / "work")
    assert refused.returncode != 0
    assert f"{root}/README.md has no line '{generated_block.begin_marker(methods_tables.TOOL)}'" in refused.stderr
    assert not (tmp_path / "work").exists()


# ---- the marker replacement ----

BEGIN, END = generated_block.begin_marker("t.py"), generated_block.end_marker("t.py")


def test_the_generated_part_is_replaced_and_the_prose_kept():
    page = f"# Title\n\nProse above.\n{BEGIN}\nold table\n{END}\nProse below.\n"
    assert generated_block.generated(page, "t.py", "P.md") == "old table\n"
    assert generated_block.replaced(page, "\nnew\ntable\n", "t.py", "P.md") == \
        f"# Title\n\nProse above.\n{BEGIN}\n\nnew\ntable\n{END}\nProse below.\n"
    empty = f"{BEGIN}\n{END}\n"
    assert generated_block.replaced(empty, "x\n", "t.py", "P.md") == f"{BEGIN}\nx\n{END}\n"


@pytest.mark.parametrize("page, message", [
    (f"prose\n{END}\n", f"t.py: P.md has no line '{BEGIN}': give it exactly one begin and one end marker line"),
    (f"{BEGIN}\nprose\n", f"t.py: P.md has no line '{END}'"),
    (f"{BEGIN}\n{BEGIN}\n{END}\n", f"t.py: P.md has 2 lines (at lines 1, 2) '{BEGIN}'"),
    (f"{END}\nx\n{BEGIN}\n", "t.py: P.md:1: the end marker comes before the begin marker (line 3)"),
    (f"text {BEGIN}\n{END}\n", f"t.py: P.md has no line '{BEGIN}'"),  # a marker is a line of its own
])
def test_a_missing_or_misplaced_marker_names_the_page_and_the_fix(page, message):
    with pytest.raises(SystemExit) as refused:
        generated_block.replaced(page, "new\n", "t.py", "P.md")
    assert message in str(refused.value) and "run t.py again" in str(refused.value)
