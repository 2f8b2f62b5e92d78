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
import sys
import zipfile

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

# A wheel's platform tag -> Blender's platform name.
PLATFORMS = (
    (re.compile(r"(many|musl)linux.*_x86_64$"), "linux-x64"),
    (re.compile(r"(many|musl)linux.*_aarch64$"), "linux-arm64"),
    (re.compile(r"macosx_.*_(x86_64|universal2)$"), "macos-x64"),
    (re.compile(r"macosx_.*_(arm64|universal2)$"), "macos-arm64"),
    (re.compile(r"win_amd64$"), "windows-x64"),
    (re.compile(r"win_arm64$"), "windows-arm64"),
)
SKIPPED_DIRS = {"__pycache__", "_vendor"}


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
    text = "\n".join(lines[:first_table] + added + lines[first_table:]) + "\n"
    if tomllib is not None:
        tomllib.loads(text)  # a broken template fails here, not inside Blender
    return text


def add_tree(archive, addon_dir):
    """Add the add-on's files at the zip's root, without caches, _vendor/ and the template."""
    count = 0
    for folder, subfolders, files in os.walk(addon_dir):
        subfolders[:] = sorted(d for d in subfolders if d not in SKIPPED_DIRS)
        for name in sorted(files):
            if name.endswith(".pyc") or name == "blender_manifest.toml":
                continue
            path = os.path.join(folder, name)
            archive.write(path, os.path.relpath(path, addon_dir))
            count += 1
    return count


def stage_extension(addon_dir, wheels, folder, license_file=None):
    """Write the extension's tree into `folder` instead of a zip: the input of
    `blender --command extension build --split-platforms` (one zip per platform, on a CI that
    has the wheels of every platform)."""
    import shutil

    with open(os.path.join(addon_dir, "blender_manifest.toml"), encoding="utf-8") as f:
        text = manifest_text(f.read(), wheels)
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(addon_dir, folder, ignore=shutil.ignore_patterns(*SKIPPED_DIRS, "*.pyc"))
    with open(os.path.join(folder, "blender_manifest.toml"), "w", encoding="utf-8") as f:
        f.write(text)
    if license_file:
        shutil.copy(license_file, os.path.join(folder, "LICENSE"))
    os.makedirs(os.path.join(folder, "wheels"))
    for wheel in wheels:
        shutil.copy(wheel, os.path.join(folder, "wheels"))
    return folder


def make_extension(addon_dir, wheels, out_dir, license_file=None):
    """Write <out_dir>/<id>-<version>.zip; return its path."""
    with open(os.path.join(addon_dir, "blender_manifest.toml"), encoding="utf-8") as f:
        template = f.read()
    if not wheels:
        raise SystemExit("error: no engine wheel given (build them with `make wheel`)")
    text = manifest_text(template, wheels)
    ident = re.search(r'^id\s*=\s*"([^"]+)"', text, re.M).group(1)
    version = re.search(r'^version\s*=\s*"([^"]+)"', text, re.M).group(1)
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, f"{ident}-{version}.zip")
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("blender_manifest.toml", text)
        add_tree(archive, addon_dir)
        if license_file:
            archive.write(license_file, "LICENSE")
        for wheel in sorted(wheels):
            archive.write(wheel, "wheels/" + os.path.basename(wheel), zipfile.ZIP_STORED)
    return path


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
