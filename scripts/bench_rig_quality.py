#!/usr/bin/python3
"""Our skeleton against the artists' on the rigged characters (make bench):

    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_rig_quality.py \\
        [--rigged ../shared/meshes/rigged] [--out out/bench/rig-quality.md]

Per character (NAME.obj + NAME.rig.txt): dcg.extract_skeleton with the default options, its
bones as the add-on plans them (dcg.bones.plan_bones, default bone_detail, the root bone's
floor across the file's up axis, `floor_up`; our joints are the bones' heads and tails)
against the artist's joints and parent-child bones: CD-J2J, CD-J2B and CD-B2B
(dcg.metrics.skeleton_metrics) in % of the mesh's longest bounding-box side, how far
our paired bones (`.L` / `.R`) are from mirroring each other across the plan's mirror plane
(dcg.metrics.mirror_error, same unit; dcg.bones.plan_plane), the bone counts and the engine's
method. A second set of CD columns ("inside") leaves out the artist's joints outside the mesh
(winding number, scripts/mesh_parts.py: a root on the floor, a hub above the body, IK targets),
each kept joint's parent its nearest kept ancestor (dcg.metrics.kept_joints), and our root bone
on the floor: how much of the distance is joints no skeleton inside the shape can reach (a
diagnostic; issue 17's targets are on the plain columns). A second table sets each CD beside
the character's before issue 17's bone planner (scripts/rig_quality_before.json: measured at
that commit, the command in the file), the issue's "no character worse than today". Writes the
Markdown tables to --out (and prints them) and one JSON line per character to the same path
with .jsonl.
"""
import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

import mesh_parts
import quality_tables

#: Published figures (MagicArticulate and Puppeteer papers; Pinocchio as they report it).
REFERENCES = [
    {"name": "Puppeteer (published)", "cd_j2j": 3.785, "cd_j2b": 2.847, "cd_b2b": 2.430},
    {"name": "MagicArticulate (published)", "cd_j2j": 4.003, "cd_j2b": 3.026, "cd_b2b": 2.586},
    {"name": "RigNet (published)", "cd_j2j": 4.143, "cd_j2b": 2.961, "cd_b2b": 2.675},
    {"name": "Pinocchio (published)", "cd_j2j": 8.36},
    {"name": "ours, earlier figures on this set (issue)", "cd_j2j": 4.69, "cd_j2b": 3.35,
     "cd_b2b": 3.67},
]
METRICS = ["cd_j2j", "cd_j2b", "cd_b2b"]
#: Each character's CDs before issue 17's bone planner, measured at the commit the file names.
BEFORE = quality_tables.ROOT / "scripts" / "rig_quality_before.json"
#: A CD is worse than before when it grew by more than this (% of the longest side).
WORSE_BY = 0.005
PARTS = ["j2j_ours", "j2j_ours_far", "j2j_theirs", "j2j_theirs_far"]
INSIDE_METRICS = ["inside_" + m for m in METRICS]
COLUMNS = [("character", "name", ""), ("CD-J2J %", "cd_j2j", ".3f"),
           ("CD-J2B %", "cd_j2b", ".3f"), ("CD-B2B %", "cd_b2b", ".3f"),
           ("J2J ours->theirs %", "j2j_ours", ".3f"), ("of it unrigged %", "j2j_ours_far", ".3f"),
           ("J2J theirs->ours %", "j2j_theirs", ".3f"),
           ("of it unreached %", "j2j_theirs_far", ".3f"),
           ("inside CD-J2J %", "inside_cd_j2j", ".3f"),
           ("inside CD-J2B %", "inside_cd_j2b", ".3f"),
           ("inside CD-B2B %", "inside_cd_b2b", ".3f"), ("their joints outside", "outside", "d"),
           ("mirror mean %", "mirror_mean", ".3f"), ("mirror max %", "mirror_max", ".3f"),
           ("pairs", "pairs", "d"), ("unpaired limbs", "unpaired_limbs", "d"),
           ("our bones", "bones", "d"),
           ("their bones", "their_bones", "d"),
           ("up", "up", ""), ("method", "method", ""), ("seconds", "seconds", ".2f")]


def floor_up(V) -> np.ndarray:
    """The up axis of a character's file: the coordinate axis whose plane through the origin
    its lowest point is nearest (in longest sides; Z first on ties), the floor its exporter stood
    it on. The game characters' conversions stand on z = 0 (the flying Q_Dragon and Q_Wasp a
    little above it), glTF-Blender-IO's cylinder on y = 0 (glTF's up, which Blender's importer
    turns to +Z). The root bone's floor lies across it, as it lies across Blender's +Z for a
    model standing in the viewport."""
    V = np.asarray(V, dtype=float)
    lowest = np.abs(V.min(axis=0)) / max(float(np.ptp(V, axis=0).max()), 1e-300)
    axis = min((2, 1, 0), key=lambda a: lowest[a])  # stable: Z, then Y, then X on ties
    return np.eye(3)[axis]


def measure(name, obj, rig_path, bone_detail) -> dict:
    """One character's row."""
    import dcg
    from dcg import bones, metrics

    V, F = dcg.load_mesh(obj)
    rig = metrics.read_rig_info(rig_path, len(V))
    start = time.perf_counter()
    skeleton = dcg.extract_skeleton(V, F)
    seconds = time.perf_counter() - start
    up = floor_up(V)
    plan = bones.bone_arrays(bones.plan_bones(skeleton, bone_detail, up=up))
    row = {"name": name, "vertices": len(V), "bones": len(plan["heads"]), "up": "XYZ"[up.argmax()],
           "their_bones": len(rig.joints), "method": skeleton.method, "seconds": seconds}
    row.update(metrics.skeleton_metrics(V, plan["heads"], plan["tails"], rig.joints,
                                        rig.parents))
    row.update(metrics.j2j_parts(V, plan["heads"], plan["tails"], rig.joints, rig.parents))
    inside = mesh_parts.inside_any_part(rig.joints, V, F)
    joints, parents = metrics.kept_joints(rig.joints, rig.parents, inside)
    ours = bones.deforms(plan["kinds"])  # our root bone on the floor is left out likewise
    kept = metrics.skeleton_metrics(V, plan["heads"][ours], plan["tails"][ours], joints, parents)
    row.update({"inside_" + key: value for key, value in kept.items()})
    row["outside"] = int((~inside).sum())
    plane = bones.plan_plane(skeleton, up)
    row.update(pairs=0, mirror_mean=None, mirror_max=None,
               unpaired_limbs=bones.unpaired_limbs(skeleton, up))
    if plane is not None:
        row.update(metrics.mirror_error(V, plan["names"], plan["heads"], plan["tails"],
                                        plane.normal, plane.offset))
    return row


def against_before(row, before) -> dict:
    """`row`'s CDs beside `before` (the character's entry of BEFORE; None: not measured then):
    "before_<metric>" and "change_<metric>" (now - then) of each, and "worse", the names of
    those that grew by more than WORSE_BY ("" when none; "-" without a before)."""
    if before is None:
        return {"worse": "-"}
    out, worse = {}, []
    for key in METRICS:
        out["before_" + key] = before[key]
        out["change_" + key] = row[key] - before[key]
        if out["change_" + key] > WORSE_BY:
            worse.append(key[3:].upper())
    out["worse"] = ", ".join(worse)
    return out


def before_table(rows, path=BEFORE) -> list:
    """The Markdown lines comparing `rows` (and their mean) with the CDs in `path`."""
    if not path.exists():
        return []
    before = json.loads(path.read_text())
    for row in rows:
        row.update(against_before(row, before["characters"].get(row["name"])))
    compared = [row for row in rows if row["worse"] != "-"]
    worse = [row["name"] for row in compared if row["worse"]]
    columns = [("character", "name", "")]
    for key in METRICS:
        label = key[3:].upper()
        columns += [(f"{label} before %", "before_" + key, ".3f"),
                    (f"{label} now %", key, ".3f"), (f"{label} change", "change_" + key, "+.3f")]
    summary = quality_tables.mean_row(compared, [key for _, key, _ in columns[1:]],
                                      name=f"**mean of {len(compared)}**")
    summary["worse"] = f"{len(worse)} of {len(compared)}"
    return ["", f"Against the skeleton before issue 17 (commit {before['commit']}; "
            f"`{path.name}`): each CD then and now, the change (negative: closer to the "
            f"artist's), and which grew by more than {WORSE_BY:g}. Worse in at least one: "
            f"{', '.join(worse) or 'none'}.", ""] + quality_tables.table(
                columns + [("worse", "worse", "")], compared + [summary])


def main():
    from dcg import bones, metrics

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rigged", type=Path, default=quality_tables.default_rigged())
    parser.add_argument("--out", type=Path,
                        default=quality_tables.ROOT / "out" / "bench" / "rig-quality.md")
    parser.add_argument("--bone-detail", type=float, default=bones.BONE_DETAIL)
    args = parser.parse_args()
    characters = metrics.rigged_characters(args.rigged)
    if not characters:
        print(f"bench_rig_quality: no rigged characters in {args.rigged}; skipped",
              file=sys.stderr)
        return 0
    rows = []
    for name, obj, rig_path in characters:
        rows.append(measure(name, obj, rig_path, args.bone_detail))
        print(f"bench_rig_quality: {rows[-1]}", file=sys.stderr, flush=True)
    mean = quality_tables.mean_row(rows, METRICS + PARTS + INSIDE_METRICS + [
        "outside", "mirror_mean", "mirror_max", "pairs", "unpaired_limbs", "bones", "their_bones",
        "seconds"])
    mean["name"] = f"**mean of {len(rows)}**"
    lines = quality_tables.header("Skeleton quality: our bones against the artists' skeletons")
    lines += [f"Characters of `{args.rigged}`. Ours: `dcg.extract_skeleton` (defaults), bones of "
              f"`dcg.bones.plan_bones` (bone_detail {args.bone_detail:g}); our joints are the "
              "bones' distinct heads and tails; the root bone's floor lies across the file's up "
              "axis ('up': `floor_up`, the coordinate plane the model stands on). Theirs: the "
              "rig's joints, bones from each parent to each child. Chamfer distances "
              "(`dcg.metrics`) in % of the mesh's longest "
              "bounding-box side; CD-B2B samples both bone sets 0.5% of that side apart. "
              "Mirror: the distance from each `.L` bone's head and tail mirrored across the "
              "plan's mirror plane (`dcg.bones.plan_plane`) to its `.R` partner's, mean and "
              "largest, same unit ('-' without a mirror plane; the mean row over the "
              "characters that have one); pairs: the pairs of bones; unpaired limbs: limbs "
              "of a shape that mirrors itself whose ends mirror each other yet did not pair "
              "(`dcg.bones.unpaired_limbs`, what the add-on warns of). "
              "'their bones': one per joint (the weights protocol). The 'inside' CD columns "
              "leave out the artist's joints outside the mesh ('their joints outside': a root "
              "on the floor, a hub above the body, IK targets; winding number), each kept "
              "joint's parent its nearest kept ancestor, and our root bone on the floor: a "
              "diagnostic of how much of the distance no skeleton inside the shape can remove "
              "(the targets are on the first three columns). CD-J2J is the mean of its two "
              "directions: 'J2J ours->theirs' "
              "(our joints to the artist's nearest) and 'J2J theirs->ours'; 'of it unrigged' is "
              "the part of the first from our joints farther than "
              f"{metrics.FAR_JOINT:g}% from every artist bone (limbs the artist did not rig), "
              "'of it unreached' the part of the second from the artist's joints as far from "
              "all our bones (`dcg.metrics.j2j_parts`): what is left is how densely and where "
              "along the limbs the joints fall.", ""]
    lines += quality_tables.table(COLUMNS, rows + [mean])
    lines += before_table(rows)
    lines += ["", "Reference rows (other sets: MagicArticulate's Articulation-XL / ModelsResource "
              "figures as the papers give them; not measured here):", ""]
    lines += quality_tables.table([("method", "name", "")] + COLUMNS[1:4], REFERENCES)
    quality_tables.write(args.out, lines, rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
