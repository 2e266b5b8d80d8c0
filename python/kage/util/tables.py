"""Numbers as CSV and Markdown tables, written alike by the checkpoint scorer (kage.ppo.evaluate) and the
benchmark report (kage.bench.tables): 3 significant digits (at most 2 decimals) in Markdown, "-" where a value
is missing."""
import csv
import io
import math
from typing import List, Optional, Sequence


def csv_text(header: Sequence[str], rows: List[list]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([["" if cell is None else cell for cell in row] for row in rows])
    return out.getvalue()


def decimals(value: float) -> int:
    """Three significant digits, at most two decimals (0.83, 12.3, 480, -3456)."""
    if value == 0:
        return 2
    return min(2, max(0, 2 - math.floor(math.log10(abs(value)))))


def fmt_value(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.{decimals(value)}f}"


def md_table(header: Sequence[str], rows: List[Sequence[str]], text_columns: int) -> str:
    """A Markdown table, its first `text_columns` columns left-aligned and the numbers right-aligned."""
    def line(cells):
        return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"
    rule = ["---"] * text_columns + ["---:"] * (len(header) - text_columns)
    return "\n".join([line(header), line(rule)] + [line(r) for r in rows]) + "\n"
