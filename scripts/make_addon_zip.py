#!/usr/bin/python3
"""Zip the assembled add-on (build/blender_scripts/addons/dcg_rig, with the engine vendored
in _vendor/) into an installable archive whose top folder is dcg_rig/.

    /usr/bin/python3 scripts/make_addon_zip.py build/blender_scripts/addons/dcg_rig out/dcg_rig.zip

Used by `make addon` and by the Blender test that installs the zip in a clean Blender.
"""

import os
import sys
import zipfile


def addon_files(addon_dir, skipped_dirs=("__pycache__",)):
    """(path, path relative to `addon_dir`) of the add-on's files, sorted, without caches,
    the folders `skipped_dirs` and the extension's manifest template (blender_manifest.toml:
    the legacy zip must not carry it, Blender 4.2+ would take the zip for an extension without
    its wheels; make_extension.py writes the completed one itself)."""
    for folder, subfolders, files in os.walk(addon_dir):
        subfolders[:] = sorted(d for d in subfolders if d not in skipped_dirs)
        for name in sorted(files):
            if not name.endswith(".pyc") and name != "blender_manifest.toml":
                path = os.path.join(folder, name)
                yield path, os.path.relpath(path, addon_dir)


def make_zip(addon_dir, zip_path):
    """Write `zip_path` from `addon_dir` (skipping caches); return the number of files."""
    addon_dir = os.path.abspath(addon_dir)
    if not os.path.isfile(os.path.join(addon_dir, "__init__.py")):
        raise SystemExit(f"error: {addon_dir} holds no add-on (__init__.py); run make build")
    os.makedirs(os.path.dirname(os.path.abspath(zip_path)) or ".", exist_ok=True)
    count = 0
    top = os.path.basename(addon_dir)
    with zipfile.ZipFile(zip_path, "w", zipfile.ZIP_DEFLATED) as archive:
        for path, relative in addon_files(addon_dir):
            archive.write(path, os.path.join(top, relative))
            count += 1
    return count


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    files = make_zip(sys.argv[1], sys.argv[2])
    print(f"wrote {sys.argv[2]} ({files} files)")
