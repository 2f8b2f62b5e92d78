#!/usr/bin/env python3
"""Write the Blender 4.2+ extension: the add-on's files, its manifest completed with the engine's
wheels, and the wheels themselves, in one zip that Blender installs from disk.

    python3 scripts/make_extension.py --addon addon/dcg_rig --wheels out/wheels --out-dir out

writes out/dcg_rig-<version>.zip (the version from addon/dcg_rig/blender_manifest.toml). The
manifest's `platforms` list follows from the wheels' tags (a manylinux x86_64 wheel: linux-x64),
and `wheels` lists them as ./wheels/<file>. Used by `make extension` and by `make test`, which
installs the zip into each Blender 4.2+ it runs.
"""

import argparse
import os
import re
import shutil
import sys
import tomllib
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_addon_zip import addon_files  # noqa: E402  (the legacy zip's file list)

# A wheel's platform tag -> Blender's platform name.
PLATFORMS = (
    (re.compile(r"(many|musl)linux.*_x86_64$"), "linux-x64"),
    (re.compile(r"(many|musl)linux.*_aarch64$"), "linux-arm64"),
    (re.compile(r"macosx_.*_(x86_64|universal2)$"), "macos-x64"),
    (re.compile(r"macosx_.*_(arm64|universal2)$"), "macos-arm64"),
    (re.compile(r"win_amd64$"), "windows-x64"),
    (re.compile(r"win_arm64$"), "windows-arm64"),
)
SKIPPED_DIRS = ("__pycache__", "_vendor")


def wheel_platforms(wheel):
    """Blender's platform names for the wheel file name `wheel` (tags after the last '-')."""
    tags = os.path.basename(wheel)[:-len(".whl")].split("-")[-1].split(".")
    names = {name for tag in tags for pattern, name in PLATFORMS if pattern.search(tag)}
    if not names:
        raise SystemExit(f"error: {wheel}: no Blender platform for its tag {tags}")
    return names


def manifest_text(template, wheels):
    """The manifest `template` with `platforms` and `wheels` added before its first table."""
    platforms = sorted(set().union(*(wheel_platforms(w) for w in wheels)))
    lines = template.splitlines()
    first_table = next((i for i, line in enumerate(lines) if line.startswith("[")), len(lines))
    quoted = lambda items: "[" + ", ".join(f'"{item}"' for item in items) + "]"  # noqa: E731
    added = [f"platforms = {quoted(platforms)}",
             f"wheels = {quoted('./wheels/' + os.path.basename(w) for w in sorted(wheels))}", ""]
    return "\n".join(lines[:first_table] + added + lines[first_table:]) + "\n"


def extension_files(addon_dir, wheels, license_file=None):
    """The extension's contents: (name in the extension, source file or None, text or None),
    the completed manifest first. Its `id` and `version` are returned too, for the zip's name.
    A broken manifest template fails here (tomllib), not inside Blender."""
    with open(os.path.join(addon_dir, "blender_manifest.toml"), encoding="utf-8") as f:
        text = manifest_text(f.read(), wheels)
    manifest = tomllib.loads(text)
    files = [("blender_manifest.toml", None, text)]
    files += [(relative, path, None) for path, relative in addon_files(addon_dir, SKIPPED_DIRS)]
    if license_file:
        files.append(("LICENSE", license_file, None))
    files += [("wheels/" + os.path.basename(w), w, None) for w in sorted(wheels)]
    return manifest["id"], manifest["version"], files


def make_extension(addon_dir, wheels, out_dir, license_file=None):
    """Write <out_dir>/<id>-<version>.zip; return its path."""
    if not wheels:
        raise SystemExit("error: no engine wheel given (build them with `make wheel`)")
    ident, version, files = extension_files(addon_dir, wheels, license_file)
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, f"{ident}-{version}.zip")
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, source, text in files:
            if text is not None:
                archive.writestr(name, text)
            else:  # wheels are zips already
                archive.write(source, name, zipfile.ZIP_STORED if name.endswith(".whl") else None)
    return path


def stage_extension(addon_dir, wheels, folder, license_file=None):
    """Write the same contents into `folder` instead of a zip: the input of
    `blender --command extension build --split-platforms` (one zip per platform, on a CI that
    has the wheels of every platform)."""
    shutil.rmtree(folder, ignore_errors=True)
    for name, source, text in extension_files(addon_dir, wheels, license_file)[2]:
        target = os.path.join(folder, name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        if text is not None:
            with open(target, "w", encoding="utf-8") as f:
                f.write(text)
        else:
            shutil.copy(source, target)
    return folder


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--addon", required=True, help="the add-on folder (addon/dcg_rig)")
    parser.add_argument("--wheels", required=True, help="folder of the engine's wheels")
    parser.add_argument("--out-dir", required=True)
    parser.add_argument("--license", help="the LICENSE file to include")
    parser.add_argument("--stage", metavar="FOLDER",
                        help="write the extension's tree into FOLDER, not a zip")
    args = parser.parse_args(argv)
    wheels = sorted(os.path.join(args.wheels, w) for w in os.listdir(args.wheels)
                    if w.startswith("dcg-") and w.endswith(".whl"))
    if args.stage:
        stage_extension(args.addon, wheels, args.stage, args.license)
        print(f"staged {args.stage} ({len(wheels)} wheel(s))")
        return
    path = make_extension(args.addon, wheels, args.out_dir, args.license)
    print(f"wrote {path} ({len(wheels)} wheel(s): {', '.join(map(os.path.basename, wheels))})")


if __name__ == "__main__":
    sys.exit(main())
