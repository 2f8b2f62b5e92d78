"""dcg batch, what a run is made of: the job of one model, the inputs found under the input
folder, the outputs of a model and the key of the options that made them (see dcg.batch)."""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, List, Optional

from .bones import BONE_DETAIL, BONE_NAMES, ROOT_BONE

ENGINE_FORMATS = (".obj", ".off", ".ply", ".stl")
#: Read only through Blender's importers, so only with --glb.
BLENDER_FORMATS = (".fbx", ".glb", ".gltf")
#: Output suffixes appended to the input's relative path.
SUFFIXES = {"json": ".json", "weights": ".weights.npz", "glb": ".glb"}


class BatchError(Exception):
    """A run cannot start (missing folder, unreachable scheduler, missing Blender)."""


@dataclass(frozen=True)
class Job:
    """One model for a worker (small and picklable).

    path      the input, relative to the input folder (POSIX separators)
    source    the input's absolute path, as the workers see it
    options   engine options set on the command line (the rest take the defaults)
    glb       also make the rigged .glb with Blender
    blender / blender_cli  explicit Blender executable and the add-on's CLI script; None = found
              on the worker (see dcg.batch_blender)
    timeout   seconds per model (engine: checked at its progress reports; Blender: killed)
    bone_detail  the bone plan's detail (dcg.bones), for the .weights.npz and the .glb alike
    bone_names   the bone plan's naming convention ("dcg", or "mixamo" for humanoids), likewise
    root_bone    whether the plan starts with a root bone on the floor (dcg.bones.add_root)
    """

    path: str
    source: str
    options: Dict[str, Any]
    glb: bool = False
    blender: Optional[str] = None
    blender_cli: Optional[str] = None
    timeout: Optional[float] = None
    bone_detail: float = BONE_DETAIL
    bone_names: str = BONE_NAMES
    root_bone: bool = ROOT_BONE


def file_up(path: str) -> tuple:
    """The up direction of the mesh the engine reads for `path`: +Y for OBJ (its usual axes),
    else +Z (OFF, PLY and STL, and what Blender writes out of FBX and glTF), as the add-on's
    CLI (--up auto) imports it; the root bone's floor lies across it."""
    return (0.0, 1.0, 0.0) if path.lower().endswith(".obj") else (0.0, 0.0, 1.0)


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
    """A short hash of the complete (normalized) options that make a model's outputs."""
    text = json.dumps(options, sort_keys=True, default=str)
    return hashlib.sha1(text.encode("utf-8")).hexdigest()[:12]
