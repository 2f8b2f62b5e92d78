#!/usr/bin/python3
"""Writes the skeleton of every mesh under ../shared/meshes (default options) as JSON, or
compares such a folder with another: the check that a refactoring changed no result.

    PYTHONPATH=build/python /usr/bin/python3 scripts/skeleton_snapshot.py write DIR [MESH ...]
    /usr/bin/python3 scripts/skeleton_snapshot.py compare BEFORE_DIR AFTER_DIR

Each DIR/<mesh>.json is the skeleton's document (dcg-skeleton/1) without its timings, plus a
digest of the face labels (not part of the document). `compare` prints every file that differs
and exits 1 when any does (or when one side lacks a file).
"""
import hashlib
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MESHES = ROOT.parent / "shared" / "meshes"
SUFFIXES = {".obj", ".off", ".ply", ".stl"}


def mesh_paths():
    return sorted(p for p in MESHES.rglob("*") if p.suffix.lower() in SUFFIXES)


def snapshot(path):
    import dcg

    V, F = dcg.load_mesh(str(path))
    try:
        skeleton = dcg.extract_skeleton(V, F)
    except Exception as error:  # an input error is a result too
        return {"error": f"{type(error).__name__}: {error}"}
    doc = skeleton.to_dict()
    doc.pop("timings", None)
    labels = getattr(skeleton, "face_labels", None)
    if labels is not None:
        doc["face_labels_sha1"] = hashlib.sha1(bytes(memoryview(labels.astype("<i8")))).hexdigest()
    return doc


def write(folder, paths):
    folder.mkdir(parents=True, exist_ok=True)
    for path in paths:
        name = str(path.relative_to(MESHES)).replace("/", "__") + ".json"
        (folder / name).write_text(json.dumps(snapshot(path), indent=1, sort_keys=True))
        print(name, flush=True)


def compare(before, after):
    names = sorted({p.name for p in before.glob("*.json")} | {p.name for p in after.glob("*.json")})
    differing = [n for n in names
                 if not (before / n).exists() or not (after / n).exists()
                 or (before / n).read_text() != (after / n).read_text()]
    for name in differing:
        print("differs:", name)
    print(f"{len(names) - len(differing)} of {len(names)} skeletons identical")
    return 1 if differing or not names else 0


def main(argv):
    if len(argv) >= 2 and argv[0] == "write":
        paths = [Path(p).resolve() for p in argv[2:]] or mesh_paths()
        write(Path(argv[1]), paths)
        return 0
    if len(argv) == 3 and argv[0] == "compare":
        return compare(Path(argv[1]), Path(argv[2]))
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
