"""dcg batch, the bookkeeping of OUT_DIR: files written atomically, index.jsonl (one record per
model) and whether a model is finished (see dcg.batch)."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any, Dict, Optional

from .batch_jobs import outputs_of

INDEX_NAME = "index.jsonl"


def _file_mode() -> int:
    umask = os.umask(0o022)
    os.umask(umask)
    return 0o666 & ~umask


_FILE_MODE = _file_mode()


def write_atomic(path: Path, data: bytes) -> None:
    """Write `data` to `path` through a temporary file in the same folder and os.replace."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, _FILE_MODE)  # mkstemp's 0600 -> what open() would have given
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def read_index(out_dir: Path) -> Dict[str, Dict[str, Any]]:
    """path -> its latest record in OUT_DIR/index.jsonl (unreadable lines are ignored)."""
    records: Dict[str, Dict[str, Any]] = {}
    try:
        lines = (out_dir / INDEX_NAME).read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        return records
    for line in lines:
        try:
            record = json.loads(line)
        except ValueError:
            continue  # a line cut short by a killed run
        if isinstance(record, dict) and isinstance(record.get("path"), str):
            records[record["path"]] = record
    return records


def write_index(out_dir: Path, records: Dict[str, Dict[str, Any]]) -> None:
    """Rewrite index.jsonl atomically (when it changes): one line per model, sorted by path."""
    data = "".join(json.dumps(records[p], sort_keys=True) + "\n" for p in sorted(records))
    data = data.encode("utf-8")
    path = out_dir / INDEX_NAME
    if not records and not path.exists():
        return
    try:
        if path.read_bytes() == data:
            return  # a run with nothing to do writes nothing
    except FileNotFoundError:
        pass
    write_atomic(path, data)


def fingerprint(source: Path) -> Dict[str, int]:
    """The input's stamp in its record: size and modification time."""
    stat = source.stat()
    return {"size": stat.st_size, "mtime_ns": stat.st_mtime_ns}


def is_finished(record: Optional[Dict[str, Any]], input_stamp: Dict[str, int], key: str,
                out_dir: Path, glb: bool, retry_failed: bool) -> bool:
    """Whether a model's record says it needs no new run (see dcg.batch's documentation)."""
    if not record or record.get("input") != input_stamp or record.get("options") != key:
        return False
    if record.get("status") != "ok":
        return not retry_failed
    written = record.get("outputs") or {}
    wanted = outputs_of(record["path"], glb)
    return all(written.get(kind) == rel and (out_dir / rel).is_file()
               for kind, rel in wanted.items())
