"""Our skinning weights (dcg.skin_weights) against Blender's bone heat, same mesh, same armature,
same run. Runs inside Blender:

    blender -b --factory-startup --python scripts/bench_weights.py -- \\
        --pythonpath build/python --out out/bench/weights.md ../shared/meshes/hand.obj ...

Per mesh (and per --scale, default 1): the DCG skeleton, the add-on's bone plan
(dcg.bones.plan_bones), an armature of those bones; then
  ours:    dcg.skin_weights(V, F, plan): stage 0 + bone heat + transfer (seconds, unweighted)
  blender: bpy.ops.object.parent_set(type='ARMATURE_AUTO') (seconds, vertices left with no
           weight: Blender fails silently, see ENVIRONMENT.md)
and the ratio; and ours again with the skeleton's stage 0 reused (prepared=). Writes a Markdown table to --out (and prints it) plus one JSON line per mesh to
the same path with .jsonl.
"""

import argparse
import json
import os
import sys
import time
import types

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def parse():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="bench_weights.py")
    parser.add_argument("meshes", nargs="+")
    parser.add_argument("--pythonpath", default=os.path.join(REPO, "build", "python"))
    parser.add_argument("--out", default=os.path.join(REPO, "out", "bench", "weights.md"))
    parser.add_argument("--scale", type=float, action="append",
                        help="scale the mesh (and armature) by this; repeatable (default 1)")
    parser.add_argument("--bone-detail", type=float, default=0.5)
    parser.add_argument("--repeat", type=int, default=1, help="time ours this many times (min)")
    return parser.parse_args(argv)


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for mesh in list(bpy.data.meshes):
        bpy.data.meshes.remove(mesh)
    for arm in list(bpy.data.armatures):
        bpy.data.armatures.remove(arm)


def make_mesh_object(name, V, F):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(V.tolist(), [], F.tolist())
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def make_armature(plan):
    data = bpy.data.armatures.new("rig")
    obj = bpy.data.objects.new("rig", data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    for spec in plan:
        bone = data.edit_bones.new(spec.name)
        bone.head = [float(x) for x in spec.head]
        bone.tail = [float(x) for x in spec.tail]
    for spec in plan:
        if spec.parent:
            data.edit_bones[spec.name].parent = data.edit_bones[spec.parent]
            data.edit_bones[spec.name].use_connect = bool(spec.use_connect)
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def blender_bone_heat(mesh_obj, arm_obj):
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    mesh_obj.select_set(True)
    arm_obj.select_set(True)
    bpy.context.view_layer.objects.active = arm_obj
    start = time.perf_counter()
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    seconds = time.perf_counter() - start
    sums = np.zeros(len(mesh_obj.data.vertices))
    for vertex in mesh_obj.data.vertices:
        for element in vertex.groups:
            sums[vertex.index] += element.weight
    return seconds, int(np.sum(sums <= 0))


def main():
    args = parse()
    sys.path.insert(0, os.path.abspath(args.pythonpath))
    import dcg
    from dcg.weights import skin_weights

    from dcg import bones
    rows = []
    for path in args.meshes:
        V0, F = dcg.load_mesh(path)
        start = time.perf_counter()
        extractor = dcg.Extractor(V0, F)
        skeleton = extractor.skeleton()
        skeleton_seconds = time.perf_counter() - start
        prepared0 = extractor.prepare()
        plan0 = bones.plan_bones(skeleton, args.bone_detail)
        for scale in args.scale or [1.0]:
            clear_scene()
            V = V0 * scale
            plan = plan0
            if scale != 1.0:
                plan = [type(s)(**{**s.__dict__, "head": s.head * scale, "tail": s.tail * scale})
                        for s in plan0]
            name = os.path.basename(path) + ("" if scale == 1.0 else f" x{scale:g}")
            ours = []
            for _ in range(max(1, args.repeat)):
                start = time.perf_counter()
                w = skin_weights(V, F, plan)
                ours.append(time.perf_counter() - start)
            ours_unweighted = int(np.sum(np.bincount(w.rows, minlength=len(V)) == 0))
            # The same with the skeleton's stage 0 reused (what a caller holding the Extractor
            # pays): the working mesh is the same up to the scale.
            prepared = types.SimpleNamespace(
                vertices=prepared0.vertices, faces=prepared0.faces,
                scale=prepared0.scale * scale, offset=prepared0.offset * scale,
                map_face=prepared0.map_face, map_barycentric=prepared0.map_barycentric)
            reused = []
            for _ in range(max(1, args.repeat)):
                start = time.perf_counter()
                skin_weights(V, F, plan, prepared=prepared)
                reused.append(time.perf_counter() - start)
            mesh_obj = make_mesh_object("mesh", V, F)
            arm_obj = make_armature(plan)
            blender_seconds, blender_unweighted = blender_bone_heat(mesh_obj, arm_obj)
            row = {"mesh": name, "vertices": len(V), "faces": len(F), "bones": len(plan),
                   "skeleton_s": skeleton_seconds, "ours_s": min(ours),
                   "ours_steps": w.timings, "ours_unweighted": ours_unweighted, "ours_reused_s": min(reused),
                   "blender_s": blender_seconds, "blender_unweighted": blender_unweighted,
                   "ratio": min(ours) / blender_seconds if blender_seconds > 0 else None,
                   "ratio_reused": min(reused) / blender_seconds if blender_seconds > 0 else None}
            rows.append(row)
            print(json.dumps(row), flush=True)
    lines = ["# Skinning weights: dcg.skin_weights vs Blender's bone heat", "",
             f"Blender {bpy.app.version_string}; same mesh, same armature (add-on bone plan, "
             f"bone_detail {args.bone_detail}), same run. 'ours' includes stage 0; 'ours, "
             "stage 0 reused' takes the skeleton's Extractor.prepare().", "",
             "| mesh | vertices | bones | ours (s) | unweighted | Blender (s) | unweighted |"
             " ours / Blender | ours, stage 0 reused (s) | reused / Blender |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ratio = f"{r['ratio']:.2f}" if r["ratio"] is not None else "-"
        ratio_reused = f"{r['ratio_reused']:.2f}" if r["ratio_reused"] is not None else "-"
        lines.append(f"| {r['mesh']} | {r['vertices']} | {r['bones']} | {r['ours_s']:.3f} | "
                     f"{r['ours_unweighted']} | {r['blender_s']:.3f} | "
                     f"{r['blender_unweighted']} | {ratio} | {r['ours_reused_s']:.3f} | "
                     f"{ratio_reused} |")
    text = "\n".join(lines) + "\n"
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as handle:
        handle.write(text)
    with open(os.path.splitext(args.out)[0] + ".jsonl", "w") as handle:
        for r in rows:
            handle.write(json.dumps(r) + "\n")
    print(text)


if __name__ == "__main__":
    main()
