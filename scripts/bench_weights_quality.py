"""Our skinning weights and Blender's bone heat against the artists' weights, on the artists'
skeletons (make bench). Runs inside Blender:

    blender -b --factory-startup --python scripts/bench_weights_quality.py -- \\
        --pythonpath build/python [--rigged ../shared/meshes/rigged] \\
        [--out out/bench/weights-quality.md]

Per character (NAME.obj + NAME.rig.txt): the artist's skeleton as one bone per joint
(dcg.metrics.joint_bones: head at the joint, tail at its children's mean, leaves half their
parent bone on), as a Blender armature; then, in the same run,
  ours:    dcg.skin_weights(V, F, heads, tails, parents=rig.parents)
  blender: bpy.ops.object.parent_set(type='ARMATURE_AUTO') (bone heat), its vertex groups
each compared with the artist's weights (column j = joint j: a bone's weight belongs to the
joint at its head) by dcg.metrics.weight_metrics: L1, precision and recall of influences above
1e-4, deformation error (5 seeded random poses, linear blend skinning, % of the bounding-box
diagonal), unweighted vertices; and seconds. Writes the Markdown table to --out (and prints it)
and one JSON line per character to the same path with .jsonl.
"""

import argparse
import os
import sys
import time
import types

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import bench_weights  # noqa: E402  (its scene helpers; Blender runs this file as __main__)
import quality_tables  # noqa: E402

#: Published figures (MagicArticulate's paper, their test set): L1, precision, recall.
REFERENCES = [
    {"name": "MagicArticulate (published)", "l1": 0.398, "precision": 0.821, "recall": 0.816},
    {"name": "RigNet (published)", "l1": 0.464, "precision": 0.771, "recall": 0.835},
    {"name": "geodesic voxel binding (published)", "l1": 0.687, "precision": 0.693,
     "recall": 0.792},
    {"name": "ours, earlier figures on this set (issue)", "l1": 0.58, "precision": 0.62,
     "recall": 0.91},
    {"name": "bone heat, earlier figures on this set (issue)", "l1": 0.40, "precision": 0.83,
     "recall": 0.83},
]
MEASURES = [("L1", "l1", ".3f"), ("precision", "precision", "%"), ("recall", "recall", "%"),
            ("deform. err. %", "deformation_error", ".3f"), ("unweighted", "unweighted", "d"),
            ("s", "seconds", ".3f")]
COLUMNS = [("character", "name", ""), ("vertices", "vertices", "d"), ("joints", "joints", "d")]
COLUMNS += [(f"{who} {title}", f"{key}_{name}", spec) for key, who in (("ours", "ours"),
            ("blender", "bone heat")) for title, name, spec in MEASURES]


def parse():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="bench_weights_quality.py")
    parser.add_argument("--pythonpath", default=os.path.join(HERE, "..", "build", "python"))
    parser.add_argument("--rigged", default=str(quality_tables.default_rigged()))
    parser.add_argument("--out", default=str(quality_tables.ROOT / "out" / "bench" /
                                             "weights-quality.md"))
    parser.add_argument("--seed", type=int, default=0, help="of the deformation poses")
    return parser.parse_args(argv)


def group_weights(mesh_obj, names) -> np.ndarray:
    """The #V x #J matrix of mesh_obj's vertex groups named after the joints."""
    column = {group.index: names.index(group.name) for group in mesh_obj.vertex_groups
              if group.name in names}
    W = np.zeros((len(mesh_obj.data.vertices), len(names)))
    for vertex in mesh_obj.data.vertices:
        for element in vertex.groups:
            if element.group in column:
                W[vertex.index, column[element.group]] += element.weight
    return W


def bone_heat(V, F, rig, heads, tails):
    """Blender's bone heat weights (#V x #J) of the artist's bones, and its seconds."""
    bench_weights.clear_scene()
    plan = [types.SimpleNamespace(name=name, head=heads[j], tail=tails[j], use_connect=False,
                                  parent=rig.names[rig.parents[j]] if rig.parents[j] >= 0
                                  else None) for j, name in enumerate(rig.names)]
    mesh_obj = bench_weights.make_mesh_object("mesh", V, F)
    arm_obj = bench_weights.make_armature(plan)
    seconds, _ = bench_weights.blender_bone_heat(mesh_obj, arm_obj)
    return group_weights(mesh_obj, rig.names), seconds


def measure(name, obj, rig_path, seed) -> dict:
    """One character's row: ours_* and blender_* measures."""
    import dcg
    from dcg import metrics

    V, F = dcg.load_mesh(obj)
    rig = metrics.read_rig_info(rig_path, len(V))
    heads, tails = metrics.joint_bones(rig.joints, rig.parents)
    start = time.perf_counter()
    ours = dcg.skin_weights(V, F, heads, tails, parents=rig.parents).dense()
    weights = {"ours": (ours, time.perf_counter() - start),
               "blender": bone_heat(V, F, rig, heads, tails)}
    row = {"name": name, "vertices": len(V), "joints": len(rig.joints)}
    for who, (W, seconds) in weights.items():
        measured = metrics.weight_metrics(V, W, rig.weights, rig.joints, rig.parents, seed)
        measured["seconds"] = seconds
        row.update({f"{who}_{key}": value for key, value in measured.items()})
    return row


def summary(rows) -> list:
    """Lines on where bone heat fails and, elsewhere, which method deforms closer."""
    failed = [r["name"] for r in rows if r["blender_unweighted"] > 0]
    others = [r for r in rows if r["blender_unweighted"] == 0]
    better = [r["name"] for r in others
              if r["blender_deformation_error"] < r["ours_deformation_error"]]
    ours_none = sum(r["ours_unweighted"] for r in rows)
    return [f"- Bone heat leaves vertices unweighted on {len(failed)} of {len(rows)}: "
            + (", ".join(f"{r['name']} ({r['blender_unweighted']})" for r in rows
                         if r["name"] in failed) or "none") + ".",
            f"- On the other {len(others)}, bone heat deforms closer to the artist's weights "
            f"on {len(better)}" + (f" ({', '.join(better)})" if better else "") + ".",
            f"- Ours leaves {ours_none} vertices unweighted in all."]


def report(args, rows):
    keys = [key for _, key, spec in COLUMNS[1:]]
    mean = quality_tables.mean_row(rows, keys)
    mean["name"] = f"**mean of {len(rows)}**"
    lines = quality_tables.header("Skinning weights against the artists' weights")
    lines += [f"Blender {bpy.app.version_string}. Characters of `{args.rigged}`, each on its "
              "artist's skeleton (one bone per joint: head at the joint, tail at its children's "
              "mean, a leaf half its parent bone on; the weight of a bone is its head joint's). "
              "Ours: `dcg.skin_weights(V, F, heads, tails, parents)`; bone heat: Blender's "
              "`parent_set(type='ARMATURE_AUTO')` on the same armature, same run. L1: mean over "
              "vertices of the summed absolute difference (0..2); precision / recall: of the "
              "influences above 1e-4, per vertex, averaged; deformation error: mean vertex gap "
              "between the mesh posed with each weights and with the artist's (linear blend "
              f"skinning, 5 random poses of up to 35 degrees a joint, seed {args.seed}) in % of "
              "the bounding-box diagonal; unweighted vertices stay at rest (Blender's armature "
              "modifier). The mean row averages every column, unweighted included.", ""]
    lines += quality_tables.table(COLUMNS, rows + [mean]) + [""] + summary(rows)
    lines += ["", "Reference rows (L1, precision, recall; published on other sets, or measured "
              "earlier on this one, not in this run):", ""]
    lines += quality_tables.table([("method", "name", "")] + MEASURES[:3], REFERENCES)
    quality_tables.write(args.out, lines, rows)


def main():
    args = parse()
    sys.path.insert(0, os.path.abspath(args.pythonpath))
    from dcg import metrics

    characters = metrics.rigged_characters(args.rigged)
    if not characters:
        print(f"bench_weights_quality: no rigged characters in {args.rigged}; skipped")
        return
    rows = []
    for name, obj, rig_path in characters:
        rows.append(measure(name, obj, rig_path, args.seed))
        print(f"bench_weights_quality: {rows[-1]}", flush=True)
    report(args, rows)


if __name__ == "__main__":
    main()
