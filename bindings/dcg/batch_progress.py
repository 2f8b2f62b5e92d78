"""dcg batch, what the user sees: the progress of a run and its summary (see dcg.batch)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, TextIO

from .batch_index import INDEX_NAME


class Progress:
    """Models done / total with the rate, on a stream (stderr).

    On a terminal: one bar redrawn in place. Otherwise (logs, pipes): one line per model.
    """

    def __init__(self, total: int, stream: Optional[TextIO]):
        self.total, self.stream = total, stream
        self.done = self.failed = 0
        self.started = time.perf_counter()
        self.tty = bool(stream is not None and getattr(stream, "isatty", lambda: False)())

    def rate(self) -> float:
        """Models per minute so far."""
        elapsed = time.perf_counter() - self.started
        return 60.0 * self.done / elapsed if elapsed > 0 else 0.0

    def update(self, record: Dict[str, Any]) -> None:
        self.done += 1
        self.failed += record.get("status") != "ok"
        if self.stream is None:
            return
        rate = self.rate()
        left = (self.total - self.done) / rate * 60.0 if rate > 0 else 0.0
        counts = f"{self.done}/{self.total}"
        tail = f"{rate:.1f} models/min, {self.failed} failed, eta {_clock(left)}"
        if self.tty:
            width = 30
            full = int(width * self.done / max(self.total, 1))
            line = f"\r[{'#' * full}{'.' * (width - full)}] {counts} {tail} "
            self.stream.write(line + ("\n" if self.done == self.total else ""))
        else:
            status = "ok" if record.get("status") == "ok" else "FAILED"
            detail = f" ({record['message']})" if record.get("message") else ""
            warned = len(record.get("warnings", []))
            detail += f" ({warned} warning{'s' if warned != 1 else ''})" if warned else ""
            self.stream.write(f"[{counts}] {status} {record['path']} "
                              f"{record.get('seconds', 0):.2f} s{detail}; {tail}\n")
        self.stream.flush()


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


@dataclass
class Summary:
    """The outcome of a run. `seconds`: the whole run (cluster start included); `rate`: models
    per minute over the rigging itself (first task submitted to last result)."""

    found: int = 0
    ok: int = 0
    failed: int = 0
    skipped: int = 0
    seconds: float = 0.0
    rig_seconds: float = 0.0
    workers: int = 0
    failures: List[tuple] = field(default_factory=list)
    warned: List[tuple] = field(default_factory=list)  # (path, [warnings]) of ok models

    @property
    def rate(self) -> float:
        done = self.ok + self.failed
        return 60.0 * done / self.rig_seconds if self.rig_seconds > 0 else 0.0

    def count(self, record: Dict[str, Any]) -> None:
        """Count a model's record as ok or failed."""
        if record.get("status") == "ok":
            self.ok += 1
            if record.get("warnings"):
                self.warned.append((record["path"], record["warnings"]))
        else:
            self.failed += 1
            self.failures.append((record["path"], record.get("message", "")))

    def text(self) -> str:
        if self.ok + self.failed == 0:
            return (f"nothing to do: all {self.found} models are finished "
                    f"(--force redoes them, --retry-failed the failed ones)")
        lines = [f"{self.ok} ok, {self.failed} failed, {self.skipped} skipped as finished, of "
                 f"{self.found} models; {self.seconds:.1f} s in all, {self.rate:.1f} models/min "
                 f"on {self.workers} worker{'s' if self.workers != 1 else ''}"]
        lines += [f"  failed: {path}: {message}" for path, message in self.failures[:20]]
        if len(self.failures) > 20:
            lines.append(f"  ... and {len(self.failures) - 20} more (see {INDEX_NAME})")
        if self.warned:
            lines.append(f"{len(self.warned)} of the ok models have warnings (index.jsonl's "
                         f"\"warnings\"):")
            lines += [f"  warning: {path}: {text}" for path, texts in self.warned[:20]
                      for text in texts]
            if len(self.warned) > 20:
                lines.append(f"  ... and {len(self.warned) - 20} more models (see {INDEX_NAME})")
        return "\n".join(lines)
