"""dcg batch, what a worker does for one model: the engine's skeleton, the bones and weights
(.weights.npz) and, with --glb, the add-on's rig through Blender (see dcg.batch)."""

from __future__ import annotations

import importlib
import io
import os
import tempfile
import time
from pathlib import Path
from typing import Any, Dict, Optional

import numpy as np

from .batch_blender import read_with_blender, rig_with_blender
from .batch_jobs import BLENDER_FORMATS, BatchError, Job, file_up
from .bones import BONE_DETAIL, BONE_NAMES, ROOT_BONE, bone_arrays, deforms, plan_bones
from .rig_warnings import plan_warnings


class _Deadline:
    """A progress callback that cancels the engine once `timeout` seconds have passed."""

    def __init__(self, timeout: Optional[float]):
        self.end = None if not timeout else time.monotonic() + timeout

    def __call__(self, stage: str, fraction: float) -> bool:
        return self.end is None or time.monotonic() < self.end

    def left(self) -> Optional[float]:
        return None if self.end is None else max(1.0, self.end - time.monotonic())


def _package():
    """The dcg package this module belongs to (also when it is vendored in the add-on)."""
    return importlib.import_module(__package__)


def weights_npz(V, F, skeleton, prepared=None, progress=None,
                bone_detail: float = BONE_DETAIL, options=None,
                bone_names: str = BONE_NAMES, root_bone: bool = ROOT_BONE, up=None,
                plan=None) -> tuple:
    """The .weights.npz bytes and the weights status: "ok", or "unavailable: why".

    The file holds the bones the add-on makes of `skeleton` (dcg.bones.plan_bones at
    `bone_detail`, named by `bone_names`' convention, with a root bone on the floor across `up`
    when `root_bone` (None: not known, as plan_bones takes it), as arrays by
    dcg.bones.bone_arrays):
    bone_names, bone_heads, bone_tails, bone_parents (-1 at a root), bone_links, bone_kinds,
    bone_z_axes (#B x 3, each bone's local Z axis) and bone_rolls (#B, Blender's roll for it,
    radians, in the model's coordinates); then status (the same text), vertices (#V) and, when
    the status is "ok", weights: #V x #B float32, the weights of the input's vertices (in
    load_mesh order) per bone, from dcg.skin_weights (rows sum to 1; the root bone's column is
    zero: it deforms nothing). No weights are made up when it is missing.
    `options`: dcg.OPTIONS values (the weights' own used). `plan`: those bones when the caller
    planned them already (then bone_detail, bone_names, root_bone and up are not read).
    """
    if plan is None:
        plan = plan_bones(skeleton, bone_detail, bone_names, root_bone=root_bone, up=up)
    bones = bone_arrays(plan)
    skin_weights = getattr(_package(), "skin_weights", None)
    W = None
    if skin_weights is None:
        status = "unavailable: this build of dcg has no skin_weights"
    elif len(bones["names"]) == 0:
        status = "unavailable: the skeleton has no bones"
    else:
        result = skin_weights(V, F, bones["heads"], bones["tails"], parents=bones["parents"],
                              deform=deforms(bones["kinds"]), prepared=prepared,
                              progress=progress, **(options or {}))
        W = np.asarray(result.dense(), dtype=np.float32)
        status = "ok"
    arrays = {f"bone_{key}": value for key, value in bones.items()}
    arrays.update(status=np.array(status), vertices=np.array(len(V), dtype=np.int64))
    if W is not None:
        arrays["weights"] = W
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    return buffer.getvalue(), status


def _rig_files(job: Job, record: Dict[str, Any], deadline: _Deadline, tmp: str):
    """The output files of `job` (json, weights, glb: bytes); fills `record` in."""
    dcg = _package()
    files: Dict[str, bytes] = {}
    mesh_path = job.source
    if os.path.splitext(job.path)[1].lower() in BLENDER_FORMATS:
        mesh_path = os.path.join(tmp, "mesh.off")
        read_with_blender(job, mesh_path, deadline.left())
    V, F = dcg.load_mesh(mesh_path)
    record.update(vertices=int(len(V)), faces=int(len(F)))
    extractor = dcg.Extractor(V, F, deadline, **job.options)
    skeleton = extractor.skeleton()
    files["json"] = skeleton.to_json().encode("utf-8")
    up = file_up(job.path)
    plan = plan_bones(skeleton, job.bone_detail, job.bone_names, root_bone=job.root_bone, up=up)
    record["warnings"] = plan_warnings(skeleton, plan, job.bone_names, job.root_bone, up)
    files["weights"], record["weights"] = weights_npz(
        V, F, skeleton, extractor.prepare(), deadline, options=job.options, plan=plan)
    record.update(nodes=skeleton.node_count, links=int(len(skeleton.links)),
                  genus=skeleton.genus, repaired=skeleton.repaired, method=skeleton.method,
                  engine_seconds=round(skeleton.timings.get("total", 0.0), 4))
    if job.glb:
        glb_path = os.path.join(tmp, "rig.glb")
        rig_with_blender(job, glb_path, deadline.left())
        files["glb"] = Path(glb_path).read_bytes()
    return files


def rig_model(job: Job) -> Dict[str, Any]:
    """Rig one model (on a worker). Never raises for a bad model.

    Returns {"record": the index record, "files": {"json" | "weights" | "glb": bytes}}.
    """
    started = time.perf_counter()
    _threads_of_the_worker()
    record: Dict[str, Any] = {"path": job.path, "status": "ok", "message": ""}
    files: Dict[str, bytes] = {}
    try:
        with tempfile.TemporaryDirectory(prefix="dcg-batch-") as tmp:
            files = _rig_files(job, record, _Deadline(job.timeout), tmp)
    except _package().Cancelled:
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


#: The thread limit this worker process set (None: none yet).
_limited_to = None


def _threads_of_the_worker() -> None:
    """On a Dask worker, the engine uses the worker's threads (a LocalCluster's: one, a core
    each), not every core of the machine in every worker: 2 local workers rig 1.83x the models
    of one, not ~1.45x (each engine's parallel stages otherwise compete for the cores). Set
    once per worker process."""
    global _limited_to
    try:
        from distributed import get_worker

        threads = int(getattr(get_worker(), "nthreads", 0) or 0)
    except (ImportError, ValueError):
        return
    if threads > 0 and threads != _limited_to:
        _limited_to = _package().limit_threads(threads)


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return f"pid {os.getpid()}"
