"""The exceptions kage raises beside the built-in ones."""
import re
from typing import List, NamedTuple


class Diagnostic(NamedTuple):
    """One located message of kagec's front end: ``file:line:col: severity: message [rule]``."""

    file: str
    line: int
    col: int
    severity: str
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}: {self.severity}: {self.message}"


_DIAGNOSTIC = re.compile(r"^(?P<file>.+?):(?P<line>\d+):(?P<col>\d+): (?P<severity>error|warning|note): (?P<message>.*)$")


class ConfigError(ValueError):
    """A config that kagec rejects. ``str(e)`` is kagec's full report (source lines and carets);
    ``e.diagnostics`` lists its located messages, errors and warnings alike."""

    def __init__(self, text: str):
        super().__init__(text)
        self.diagnostics: List[Diagnostic] = [
            Diagnostic(m["file"], int(m["line"]), int(m["col"]), m["severity"], m["message"])
            for m in map(_DIAGNOSTIC.match, text.splitlines())
            if m
        ]

    @property
    def errors(self) -> List[Diagnostic]:
        return [d for d in self.diagnostics if d.severity == "error"]


class ConfigWarning(UserWarning):
    """A config's warning from kagec's front end (an inert setting, a value outside the documented range, a
    reproduced quirk of the original, ...), given by ``make_vec`` as ``kagec lint`` prints it, once per message
    as Python's warning filters show warnings. Silence one rule in the config with a ``# kagec: disable=RULE``
    comment on its line, or all of them with ``warnings.filterwarnings("ignore", category=kage.ConfigWarning)``."""


class DeviceUnavailableError(RuntimeError):
    """``device="cuda"`` without a usable GPU (no driver, no device, or a build without CUDA)."""

    def __init__(self, text: str):
        super().__init__(f"{text.rstrip()}\nkage: no usable GPU for device='cuda'; use device='cpu'")
