"""dcg batch, the seam to Blender: the library launches `blender` with the add-on's own
headless entry point (dcg_rig/cli.py) and runs no Blender code of its own.

The entry point is, in this order:

1. the script given (--blender-cli, `blender_cli=`), else $DCG_BLENDER_CLI;
2. the installed add-on of the Blender that runs it: `dcg_rig/cli.py` in one of that Blender's
   add-on folders (legacy add-ons, BLENDER_USER_SCRIPTS included) or extension repositories,
   as Blender itself lists them (asked once per worker process).

Blender is --blender (`blender=`), $BLENDER, or `blender` on PATH. What the add-on's CLI is
asked for: `cli.py -- IN --off OUT.off` (FBX and glTF inputs, read by Blender's importers into
one world-space mesh for the engine) and `cli.py -- IN --glb OUT.glb --bone-detail D [options]`
(the rigged model). The add-on finds the engine through DCG_PYTHONPATH, set to this package's
folder unless already set.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

from .batch_jobs import BatchError, Job
from .bones import BONE_NAMES, ROOT_BONE

BLENDER_CLI_ENV = "DCG_BLENDER_CLI"
BLENDER_ENV = "BLENDER"
ADDON = "dcg_rig"

# Asks a Blender for the folders it loads add-ons and extensions from (nothing of the add-on).
_LIST_ADDON_FOLDERS = (
    "import addon_utils, bpy\n"
    "repos = getattr(getattr(bpy.context.preferences, 'extensions', None), 'repos', ())\n"
    "folders = [*addon_utils.paths(),"
    " *(r.directory for r in repos if getattr(r, 'enabled', True))]\n"
    "print(*('DCG-ADDON-FOLDER ' + f for f in folders), sep='\\n', flush=True)\n")


def find_blender(explicit: Optional[str] = None) -> str:
    """The Blender executable: `explicit`, $BLENDER, or `blender` on PATH (BatchError)."""
    name = explicit or os.environ.get(BLENDER_ENV) or "blender"
    found = shutil.which(name)
    if found is None:
        raise BatchError(f"Blender executable {name!r} not found (give --blender or set "
                         f"{BLENDER_ENV})")
    return found


def addon_folders(blender: str) -> Tuple[str, ...]:
    """The add-on and extension folders of the Blender `blender`, as it lists them."""
    variables = tuple(sorted((k, v) for k, v in os.environ.items() if k.startswith("BLENDER")))
    return _addon_folders(blender, variables)


@functools.lru_cache(maxsize=8)
def _addon_folders(blender: str, variables: Tuple[Tuple[str, str], ...]) -> Tuple[str, ...]:
    try:
        done = subprocess.run([blender, "-b", "--factory-startup", "--python-expr",
                               _LIST_ADDON_FOLDERS], capture_output=True, text=True,
                              timeout=120, stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise BatchError(f"cannot ask {blender} for its add-on folders: {error}") from None
    prefix = "DCG-ADDON-FOLDER "
    return tuple(line[len(prefix):] for line in done.stdout.splitlines()
                 if line.startswith(prefix))


def find_addon_cli(explicit: Optional[str] = None, blender: Optional[str] = None) -> Path:
    """The add-on's headless entry point, dcg_rig/cli.py (see the module's documentation).
    Raises BatchError saying where it looked."""
    given = explicit or os.environ.get(BLENDER_CLI_ENV)
    if given:
        path = Path(given).expanduser().resolve()
        if path.is_file():
            return path
        raise BatchError(f"the add-on's CLI script {path} does not exist")
    executable = find_blender(blender)
    folders = addon_folders(executable)
    for folder in folders:
        path = Path(folder) / ADDON / "cli.py"
        if path.is_file():
            return path.resolve()
    raise BatchError(f"the {ADDON} add-on is not installed in {executable} (looked in "
                     f"{', '.join(folders) or 'no add-on folder'}): install it (make addon, "
                     f"make extension), or give its cli.py with --blender-cli or "
                     f"{BLENDER_CLI_ENV}")


def check_glb_tools(blender: Optional[str], blender_cli: Optional[str]) -> str:
    """'' when Blender and the add-on's CLI are found here (run on each worker), else why."""
    try:
        find_blender(blender)
        find_addon_cli(blender_cli, blender)
    except BatchError as error:
        return str(error)
    return ""


def cli_flags(options: Dict[str, Any], bone_detail: float,
              bone_names: str = BONE_NAMES, root_bone: bool = ROOT_BONE) -> List[str]:
    """Engine options, the bone detail, the bone names' convention and the root bone as the
    add-on CLI's flags (--target-faces 20000 ...)."""
    flags = ["--bone-detail", repr(float(bone_detail)), "--bone-names", bone_names,
             "--root-bone" if root_bone else "--no-root-bone"]
    for name, value in sorted(options.items()):
        flags += [f"--{name.replace('_', '-')}", str(value)]
    return flags


def run_addon_cli(job: Job, args: List[str], what: str, timeout: Optional[float]) -> None:
    """Run the add-on's CLI in a background Blender with `args` (after its `--`); raise
    RuntimeError with its `error:` line, TimeoutError after `timeout` seconds."""
    cli = find_addon_cli(job.blender_cli, job.blender)
    command = [find_blender(job.blender), "-b", "--factory-startup", "--python", str(cli),
               "--", *args]
    env = dict(os.environ)
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


def read_with_blender(job: Job, off_path: str, timeout: Optional[float]) -> None:
    """Write the model read by Blender's importers (one mesh, world space) to `off_path`."""
    run_addon_cli(job, [job.source, "--off", off_path], "reading it with Blender", timeout)


def rig_with_blender(job: Job, glb_path: str, timeout: Optional[float]) -> None:
    """Write the model rigged by the add-on (its bone plan at job.bone_detail) to `glb_path`."""
    run_addon_cli(job, [job.source, "--glb", glb_path, *cli_flags(job.options, job.bone_detail,
                                                              job.bone_names, job.root_bone)],
                  "rigging it in Blender", timeout)
