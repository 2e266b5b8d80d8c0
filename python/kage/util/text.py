"""Small pieces of the messages the package prints."""
from typing import Optional


def plural(count: int, noun: str, nouns: Optional[str] = None) -> str:
    """'1 run', '2 runs', '2 batches': a count with its noun (`nouns` the plural, else the noun and an s)."""
    return f"{count} {noun if count == 1 else nouns or noun + 's'}"
