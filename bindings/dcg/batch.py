"""Batch rigging: every mesh under a folder, on this machine or on a Dask cluster.

    /usr/bin/python3 -m dcg batch IN_DIR OUT_DIR [--scheduler tcp://HOST:8786] [--workers N]
                                  [--glb] [--force] [--retry-failed] [--tau 0.85 ...]

For each mesh file under IN_DIR (OBJ, OFF, PLY, STL; with --glb also FBX and glTF) it writes,
under OUT_DIR at the input's relative path plus a suffix:

    <rel>.json          the skeleton (dcg-skeleton/1)
    <rel>.weights.npz   the skeleton's bones and, when the engine has them, vertex weights
    <rel>.glb           with --glb: the rigged mesh made by the add-on's headless Blender CLI
    index.jsonl         one record per model: path, status ok/error, message, seconds, faces...

Division of work: the Dask workers read the inputs (IN_DIR must be readable at the same path on
every worker), run the engine (and Blender) and send the output files back as bytes; the process
that runs `dcg batch` is the only writer of OUT_DIR. So every file is written once, atomically
(temporary file in the same folder, then os.replace), even when a task runs twice because its
worker died, and OUT_DIR only needs to exist on the machine that starts the run.

A model is finished when index.jsonl holds a record for it with the same input (size and
modification time) and the same engine options, and its outputs exist; finished models are
skipped unless `force` (failed ones too, unless `retry_failed`). A bad model becomes an error
record and never stops the others; a worker that dies has its tasks run again elsewhere by the
scheduler (up to its `allowed-failures`), and exceptions escaping a task are retried `retries`
times.

Python API: `run(in_dir, out_dir, ...) -> Summary` does what the command does.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import uuid
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, TextIO

import numpy as np

ENGINE_FORMATS = (".obj", ".off", ".ply", ".stl")
#: Read only through Blender's importers, so only with --glb.
BLENDER_FORMATS = (".fbx", ".glb", ".gltf")
INDEX_NAME = "index.jsonl"
#: Output suffixes appended to the input's relative path.
SUFFIXES = {"json": ".json", "weights": ".weights.npz", "glb": ".glb"}
BLENDER_CLI_ENV = "DCG_BLENDER_CLI"
BLENDER_ENV = "BLENDER"


class BatchError(Exception):
    """A run cannot start (missing folder, unreachable scheduler, missing Blender)."""


# --- what a worker does ------------------------------------------------------------------------


@dataclass(frozen=True)
class Job:
    """One model for a worker (small and picklable).

    path      the input, relative to the input folder (POSIX separators)
    source    the input's absolute path, as the workers see it
    options   engine options set on the command line (the rest take the defaults)
    glb       also make the rigged .glb with Blender
    blender / blender_cli  explicit Blender executable and add-on CLI script; None = search on
              the worker (see find_blender_cli)
    timeout   seconds per model (engine: checked at its progress reports; Blender: killed)
    """

    path: str
    source: str
    options: Dict[str, Any]
    glb: bool = False
    blender: Optional[str] = None
    blender_cli: Optional[str] = None
    timeout: Optional[float] = None


def find_blender_cli(explicit: Optional[str] = None) -> Path:
    """The add-on's headless CLI script (dcg_rig/cli.py), searched in this order:

    1. `explicit` (the --blender-cli option), then the environment variable DCG_BLENDER_CLI;
    2. the add-on this package is vendored in (dcg_rig/_vendor/dcg -> dcg_rig/cli.py);
    3. the build output beside the package (build/python/dcg ->
       build/blender_scripts/addons/dcg_rig/cli.py);
    4. the source tree (build/python/dcg or bindings/dcg -> addon/dcg_rig/cli.py).
    Raises BatchError naming the places it looked.
    """
    given = explicit or os.environ.get(BLENDER_CLI_ENV)
    if given:
        path = Path(given).expanduser().resolve()
        if path.is_file():
            return path
        raise BatchError(f"Blender CLI script {path} does not exist")
    package = Path(__file__).resolve().parent
    candidates = [
        package.parent.parent / "cli.py",
        package.parent.parent / "blender_scripts" / "addons" / "dcg_rig" / "cli.py",
        package.parent.parent / "addon" / "dcg_rig" / "cli.py",
        package.parent.parent.parent / "addon" / "dcg_rig" / "cli.py",
    ]
    for path in candidates:
        if path.is_file() and path.parent.name == "dcg_rig":
            return path
    raise BatchError("the add-on's cli.py was not found; give --blender-cli or set "
                     f"{BLENDER_CLI_ENV} (looked at {', '.join(map(str, candidates))})")


def find_blender(explicit: Optional[str] = None) -> str:
    """The Blender executable: `explicit`, $BLENDER, or `blender` on PATH (BatchError)."""
    name = explicit or os.environ.get(BLENDER_ENV) or "blender"
    found = shutil.which(name)
    if found is None:
        raise BatchError(f"Blender executable {name!r} not found (give --blender or set "
                         f"{BLENDER_ENV})")
    return found


def check_glb_tools(blender: Optional[str], blender_cli: Optional[str]) -> str:
    """'' when Blender and the add-on CLI are found here (run on each worker), else why not."""
    try:
        find_blender(blender)
        find_blender_cli(blender_cli)
    except BatchError as error:
        return str(error)
    return ""


class _Deadline:
    """A progress callback that cancels the engine once `timeout` seconds have passed."""

    def __init__(self, timeout: Optional[float]):
        self.end = None if not timeout else time.monotonic() + timeout

    def __call__(self, stage: str, fraction: float) -> bool:
        return self.end is None or time.monotonic() < self.end

    def left(self) -> Optional[float]:
        return None if self.end is None else max(1.0, self.end - time.monotonic())


def _run_blender(job: Job, args: List[str], what: str, timeout: Optional[float]) -> None:
    """Run Blender in the background with `args`; raise RuntimeError with its error line."""
    command = [find_blender(job.blender), "-b", "--factory-startup", *args]
    env = dict(os.environ)
    # The add-on finds the engine through DCG_PYTHONPATH: use the worker's own package.
    env.setdefault("DCG_PYTHONPATH", str(Path(__file__).resolve().parent.parent))
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env,
                              stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise TimeoutError(f"{what}: Blender still running after {timeout:.0f} s") from None
    if done.returncode != 0:
        lines = [line for line in (done.stderr + done.stdout).splitlines() if line.strip()]
        errors = [line for line in lines if line.startswith("error:")]
        reason = errors[-1][len("error:"):].strip() if errors else " / ".join(lines[-3:])
        raise RuntimeError(f"{what} failed (Blender exit status {done.returncode}): {reason}")


# Runs inside Blender: import a file through the add-on's importer (one joined mesh, any rig
# dropped) and write its triangles in world coordinates as OFF, for the engine to read.
_BLENDER_TO_OFF = r"""
import sys, bpy
addon_parent, source, target = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, addon_parent)
bpy.ops.wm.read_factory_settings(use_empty=True)
import dcg_rig
if not hasattr(bpy.types.Scene, "dcg_rig"):
    dcg_rig.register()
from dcg_rig import importing
try:
    obj = importing.import_mesh_file(bpy.context, source)
except Exception as error:
    print("error:", str(error).strip(), file=sys.stderr)
    sys.exit(1)
mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
mesh.transform(obj.matrix_world)
mesh.calc_loop_triangles()
with open(target, "w") as out:
    out.write(f"OFF\n{len(mesh.vertices)} {len(mesh.loop_triangles)} 0\n")
    out.writelines(f"{v.co.x!r} {v.co.y!r} {v.co.z!r}\n" for v in mesh.vertices)
    out.writelines("3 %d %d %d\n" % tuple(t.vertices) for t in mesh.loop_triangles)
"""


def _option_flags(options: Dict[str, Any]) -> List[str]:
    """Engine options as the add-on CLI's flags (--target-faces 20000 ...)."""
    flags = []
    for name, value in sorted(options.items()):
        flags += [f"--{name.replace('_', '-')}", str(value)]
    return flags


def bones_of(skeleton) -> Dict[str, np.ndarray]:
    """One bone per segment of every link polyline, chained away from the root.

    Links are oriented breadth-first from the root (a link that closes a loop points away from
    the node reached first); each link's polyline, so oriented, becomes a chain of bones, and
    the chain's first bone has as parent the last bone of the link that reached its first node
    (-1 at the root, or at a part not joined to it). Parents come before their children.
    Segments of zero length are left out.

    Returns names (#B str, "<kind of the link's far node>.<link number>.<segment>"),
    heads / tails (#B x 3, in the mesh's coordinates), parents (#B int64) and links (#B int64,
    the skeleton link each bone belongs to).
    """
    links = np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)
    n = skeleton.node_count
    adjacency: List[List[int]] = [[] for _ in range(n)]
    for index, (a, b) in enumerate(links.tolist()):
        adjacency[a].append(index)
        adjacency[b].append(index)
    order = np.full(n, -1, dtype=np.int64)     # breadth-first discovery order of each node
    arriving = np.full(n, -1, dtype=np.int64)  # the link through which a node was reached
    seen = 0
    for start in ([skeleton.root] if 0 <= skeleton.root < n else []) + list(range(n)):
        if order[start] >= 0:
            continue
        order[start], seen = seen, seen + 1
        queue = deque([start])
        while queue:
            u = queue.popleft()
            for index in adjacency[u]:
                a, b = links[index]
                v = b if a == u else a
                if order[v] < 0:
                    order[v], seen = seen, seen + 1
                    arriving[v] = index
                    queue.append(v)
    oriented = sorted((int(order[b]), a, b, i) if order[a] <= order[b] else
                      (int(order[a]), b, a, i) for i, (a, b) in enumerate(links.tolist()))
    positions = np.asarray(skeleton.positions, dtype=np.float64).reshape(-1, 3)
    names, heads, tails, parents, owners = [], [], [], [], []
    last_bone: Dict[int, int] = {}  # link -> its last bone
    counters: Dict[str, int] = {}
    for _, head, tail, index in oriented:
        points = np.asarray(skeleton.polylines[index], dtype=np.float64).reshape(-1, 3)
        if len(points) < 2:
            points = positions[[links[index, 0], links[index, 1]]]
        if head != links[index, 0]:
            points = points[::-1]
        kind = str(skeleton.kinds[tail])
        counters[kind] = counters.get(kind, 0) + 1
        parent = last_bone.get(int(arriving[head]), -1) if arriving[head] >= 0 else -1
        segment = 0
        for p, q in zip(points[:-1], points[1:]):
            if not np.any(p != q):
                continue
            names.append(f"{kind}.{counters[kind]:03d}.{segment:02d}")
            heads.append(p)
            tails.append(q)
            parents.append(parent)
            owners.append(index)
            parent = len(names) - 1
            segment += 1
        if segment:
            last_bone[index] = parent
        elif arriving[head] >= 0 and int(arriving[head]) in last_bone:
            last_bone[index] = last_bone[int(arriving[head])]
    return {
        "names": np.array(names, dtype=str),
        "heads": np.array(heads, dtype=np.float64).reshape(-1, 3),
        "tails": np.array(tails, dtype=np.float64).reshape(-1, 3),
        "parents": np.array(parents, dtype=np.int64),
        "links": np.array(owners, dtype=np.int64),
    }


def weights_npz(V, F, skeleton, prepared=None, progress=None) -> tuple:
    """The .weights.npz bytes and the weights status: "ok", or "unavailable: why".

    The file holds bone_names, bone_heads, bone_tails, bone_parents, bone_links (bones_of),
    status (the same text), vertices (#V) and, when the status is "ok", weights: #V x #B
    float32, the weights of the input's vertices (in load_mesh order) per bone, from
    dcg.skin_weights (rows sum to 1). No weights are made up when it is missing.
    """
    import dcg

    bones = bones_of(skeleton)
    skin_weights = getattr(dcg, "skin_weights", None)
    W = None
    if skin_weights is None:
        status = "unavailable: this build of dcg has no skin_weights"
    elif len(bones["names"]) == 0:
        status = "unavailable: the skeleton has no bones"
    else:
        result = skin_weights(V, F, bones["heads"], bones["tails"], prepared=prepared,
                              progress=progress)
        W = np.asarray(result.dense(), dtype=np.float32)
        status = "ok"
    arrays = {f"bone_{key}": value for key, value in bones.items()}
    arrays.update(status=np.array(status), vertices=np.array(len(V), dtype=np.int64))
    if W is not None:
        arrays["weights"] = W
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    return buffer.getvalue(), status


def rig_model(job: Job) -> Dict[str, Any]:
    """Rig one model (on a worker). Never raises for a bad model.

    Returns {"record": the index record, "files": {"json" | "weights" | "glb": bytes}}.
    """
    import dcg

    started = time.perf_counter()
    record: Dict[str, Any] = {"path": job.path, "status": "ok", "message": ""}
    files: Dict[str, bytes] = {}
    deadline = _Deadline(job.timeout)
    extension = os.path.splitext(job.path)[1].lower()
    try:
        with tempfile.TemporaryDirectory(prefix="dcg-batch-") as tmp:
            mesh_path = job.source
            if extension in BLENDER_FORMATS:
                mesh_path = os.path.join(tmp, "mesh.off")
                cli = find_blender_cli(job.blender_cli)
                _run_blender(job, ["--python-expr", _BLENDER_TO_OFF, "--",
                                   str(cli.parent.parent), job.source, mesh_path],
                             "reading it with Blender", deadline.left())
            V, F = dcg.load_mesh(mesh_path)
            record.update(vertices=int(len(V)), faces=int(len(F)))
            extractor = dcg.Extractor(V, F, deadline, **job.options)
            skeleton = extractor.skeleton()
            files["json"] = skeleton.to_json().encode("utf-8")
            files["weights"], record["weights"] = weights_npz(
                V, F, skeleton, extractor.prepare(), deadline)
            record.update(nodes=skeleton.node_count, links=int(len(skeleton.links)),
                          genus=skeleton.genus, repaired=skeleton.repaired,
                          method=skeleton.method,
                          engine_seconds=round(skeleton.timings.get("total", 0.0), 4))
            if job.glb:
                glb_path = os.path.join(tmp, "rig.glb")
                cli = find_blender_cli(job.blender_cli)
                _run_blender(job, ["--python", str(cli), "--", job.source, "--glb", glb_path,
                                   *_option_flags(job.options)], "rigging it in Blender",
                             deadline.left())
                files["glb"] = Path(glb_path).read_bytes()
    except dcg.Cancelled:
        record.update(status="error", message=f"timed out after {job.timeout:g} s")
    except (OSError, ValueError, RuntimeError, BatchError) as error:
        record.update(status="error", message=str(error).strip() or type(error).__name__)
    except Exception as error:  # noqa: BLE001 - a bad model must never stop the run
        record.update(status="error", message=f"{type(error).__name__}: {error}")
    if record["status"] != "ok":
        files = {}
    record["seconds"] = round(time.perf_counter() - started, 4)
    record["worker"] = _worker_name()
    return {"record": record, "files": files}


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return f"pid {os.getpid()}"


# --- the client: what to do, writing, progress -------------------------------------------------


def find_models(in_dir: Path, glb: bool = False, exclude: Optional[Path] = None) -> List[str]:
    """Mesh files under in_dir (relative POSIX paths, sorted); hidden files and folders and
    the `exclude` folder (the output, when it lies inside) are left out."""
    formats = ENGINE_FORMATS + (BLENDER_FORMATS if glb else ())
    exclude = exclude.resolve() if exclude else None
    found = []
    for root, dirs, names in os.walk(in_dir):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".")
                         and (exclude is None or (Path(root) / d).resolve() != exclude))
        for name in names:
            if not name.startswith(".") and os.path.splitext(name)[1].lower() in formats:
                found.append((Path(root) / name).relative_to(in_dir).as_posix())
    return sorted(found)


def outputs_of(path: str, glb: bool) -> Dict[str, str]:
    """Output kind -> path relative to the output folder."""
    kinds = ("json", "weights", "glb") if glb else ("json", "weights")
    return {kind: path + SUFFIXES[kind] for kind in kinds}


def options_key(options: Dict[str, Any]) -> str:
    """A short hash of the complete (normalized) engine options."""
    text = json.dumps(options, sort_keys=True, default=str)
    return hashlib.sha1(text.encode("utf-8")).hexdigest()[:12]


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


def _fingerprint(source: Path) -> Dict[str, int]:
    stat = source.stat()
    return {"size": stat.st_size, "mtime_ns": stat.st_mtime_ns}


def is_finished(record: Optional[Dict[str, Any]], input_stamp: Dict[str, int], key: str,
                out_dir: Path, glb: bool, retry_failed: bool) -> bool:
    """Whether a model's record says it needs no new run (see the module's documentation)."""
    if not record or record.get("input") != input_stamp or record.get("options") != key:
        return False
    if record.get("status") != "ok":
        return not retry_failed
    written = record.get("outputs") or {}
    wanted = outputs_of(record["path"], glb)
    return all(written.get(kind) == rel and (out_dir / rel).is_file()
               for kind, rel in wanted.items())


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

    @property
    def rate(self) -> float:
        done = self.ok + self.failed
        return 60.0 * done / self.rig_seconds if self.rig_seconds > 0 else 0.0

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
        return "\n".join(lines)


def _start_client(scheduler: Optional[str], workers: Optional[int]):
    """(client, cluster or None): connect to `scheduler`, or start a LocalCluster with one
    single-threaded worker process per core."""
    try:
        from distributed import Client, LocalCluster
    except ImportError as error:
        raise BatchError(f"Dask is not installed ({error}); on Debian: apt-get install "
                         "python3-distributed") from None
    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError) as error:
            raise BatchError(f"cannot reach the Dask scheduler at {scheduler}: {error}") from None
    count = workers or (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                        else os.cpu_count() or 1)
    cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    return Client(cluster), cluster


def run(in_dir, out_dir, *, options: Optional[Dict[str, Any]] = None,
        scheduler: Optional[str] = None, workers: Optional[int] = None, glb: bool = False,
        force: bool = False, retry_failed: bool = False, blender: Optional[str] = None,
        blender_cli: Optional[str] = None, timeout: Optional[float] = None, retries: int = 2,
        client=None, progress: Optional[TextIO] = sys.stderr,
        on_result: Optional[Callable[[Dict[str, Any]], None]] = None) -> Summary:
    """Rig every model under in_dir into out_dir (see the module's documentation).

    options: engine options (dcg.OPTIONS names; ValueError when bad). client: an existing
    distributed.Client to use instead of `scheduler` / a LocalCluster of `workers`. progress:
    where the progress bar goes (None: nowhere). on_result(record) is called after each
    model's files and record are written. Raises BatchError when the run cannot start.
    """
    from .options import normalize_options

    started = time.perf_counter()
    in_dir, out_dir = Path(in_dir).resolve(), Path(out_dir).resolve()
    if not in_dir.is_dir():
        raise BatchError(f"input folder {in_dir} does not exist")
    options = dict(options or {})
    key = options_key(normalize_options(options))
    out_dir.mkdir(parents=True, exist_ok=True)
    records = read_index(out_dir)
    write_index(out_dir, records)  # a clean file to append to, whatever a killed run left

    models = find_models(in_dir, glb, exclude=out_dir)
    summary = Summary(found=len(models))
    jobs, stamps = [], {}
    for path in models:
        stamps[path] = _fingerprint(in_dir / path)
        if not force and is_finished(records.get(path), stamps[path], key, out_dir, glb,
                                     retry_failed):
            summary.skipped += 1
            continue
        jobs.append(Job(path, str(in_dir / path), options, glb, blender, blender_cli, timeout))
    if not jobs:
        summary.seconds = time.perf_counter() - started
        return summary

    own_client = client is None
    cluster = None
    if own_client:
        client, cluster = _start_client(scheduler, workers)
    try:
        summary.workers = len(client.scheduler_info().get("workers", {}))
        if glb:
            problems = {w: why for w, why in client.run(check_glb_tools, blender,
                                                        blender_cli).items() if why}
            if problems:
                worker, why = next(iter(problems.items()))
                raise BatchError(f"--glb cannot run on {len(problems)} worker(s), "
                                 f"e.g. {worker}: {why}")
        summary.rig_seconds = _rig(client, jobs, out_dir, key, stamps, records, summary,
                                   retries, progress, on_result)
    finally:
        write_index(out_dir, records)
        if own_client:
            client.close()
            if cluster is not None:
                cluster.close()
    summary.seconds = time.perf_counter() - started
    return summary


def _rig(client, jobs: List[Job], out_dir: Path, key: str, stamps, records, summary: Summary,
         retries: int, progress_stream, on_result) -> float:
    """Submit the jobs, write each result as it arrives; return the seconds it took."""
    from distributed import as_completed

    started = time.perf_counter()
    bar = Progress(len(jobs), progress_stream)
    run_id = uuid.uuid4().hex[:8]
    pending = {}
    for job in jobs:
        future = client.submit(rig_model, job, key=f"dcg-rig-{run_id}-{job.path}",
                               retries=retries, pure=False)
        pending[future] = job
    with open(out_dir / INDEX_NAME, "a", encoding="utf-8") as index:
        for future, result in as_completed(list(pending), with_results=True,
                                           raise_errors=False):
            job = pending.pop(future)
            del future  # the scheduler may forget the result now
            record, files = _record_of(job, result)
            for kind, data in files.items():
                write_atomic(out_dir / outputs_of(job.path, job.glb)[kind], data)
            record["outputs"] = {k: outputs_of(job.path, job.glb)[k] for k in files}
            record.update(input=stamps[job.path], options=key,
                          finished=time.strftime("%Y-%m-%dT%H:%M:%S%z"))
            records[job.path] = record
            index.write(json.dumps(record, sort_keys=True) + "\n")
            index.flush()
            if record["status"] == "ok":
                summary.ok += 1
            else:
                summary.failed += 1
                summary.failures.append((job.path, record["message"]))
            bar.update(record)
            if on_result is not None:
                on_result(record)
    return time.perf_counter() - started


def _record_of(job: Job, result) -> tuple:
    """(record, files) from a task's result, or an error record when the task itself failed
    (its worker died too often, or an exception escaped rig_model after the retries)."""
    if isinstance(result, dict) and "record" in result:
        return dict(result["record"]), result["files"]
    if isinstance(result, tuple) and len(result) == 3:  # as_completed's (type, error, trace)
        result = result[1]
    name = type(result).__name__
    if name == "KilledWorker":
        message = ("the worker running it died each time it was tried (a crash, or out of "
                   "memory)")
    else:
        message = f"{name}: {result}"
    return {"path": job.path, "status": "error", "message": message}, {}
