"""Headless rigging: load a mesh file, rig it, save .blend / .glb / .png.

    blender -b --factory-startup --python addon/dcg_rig/cli.py -- MESH \\
        [-o OUT.blend] [--glb OUT.glb] [--fbx OUT.fbx] [--png OUT.png] [--up auto|y|z] \\
        [--weights DCG|BLENDER|ENVELOPE|NONE] [--bone-detail 0.5] [--tau 0.85 ...] \\
        [--off OUT.off]

Every engine option is a flag (`--target-faces 20000`); `--help` lists them. `make rig`
runs this on the bundled Spot. It goes through the add-on's own operators (dcg.load_mesh,
object.dcg_auto_rig), so it checks the same path a user clicks. Exit status 0 on success, 1 with an
"error: ..." line when anything fails, 2 for bad arguments.

This is also the add-on's side of `dcg batch --glb` (the engine package launches Blender with
this script and runs no Blender code of its own): `--glb` for the rigged model, and `--off`,
which writes the imported mesh (one mesh, world space, triangles: what the rig operator sees)
as OFF for the engine, and rigs nothing unless an output is asked for too.
"""

import argparse
import importlib
import os
import sys
import time

import bpy


def _script_args():
    """Return the arguments after Blender's `--`."""
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def _installed_extension_name(here):
    """`bl_ext.<repo>.<id>` when `here` is an extension installed in one of Blender's
    extension repositories (4.2+), else None."""
    extensions = getattr(bpy.context.preferences, "extensions", None)
    for repo in getattr(extensions, "repos", ()):
        if os.path.normpath(repo.directory) == os.path.dirname(here):
            return f"bl_ext.{repo.module}.{os.path.basename(here)}"
    return None


def _load_addon():
    """Import and register the add-on this file belongs to (once); return its package.

    An installed extension is enabled by its module name, the way Preferences enables it (its
    wheels then come with it); a legacy add-on folder or the source tree is imported as the
    package `dcg_rig`, from the folder above this file."""
    import addon_utils

    here = os.path.dirname(os.path.abspath(__file__))
    name = _installed_extension_name(here)
    if name is not None:
        module = addon_utils.enable(name, default_set=True, handle_error=None)
        if module is None:
            _fail(f"the extension {name} could not be enabled")
        return module
    parent = os.path.dirname(here)
    if parent not in sys.path:
        sys.path.insert(0, parent)
    import dcg_rig  # noqa: E402  (needs the path above)

    if not hasattr(bpy.types.Scene, "dcg_rig"):
        dcg_rig.register()
    return dcg_rig


def _parser(engine_specs, addon_options):
    parser = argparse.ArgumentParser(
        prog="blender -b --python addon/dcg_rig/cli.py --",
        description="Rig a mesh file with the DCG skeleton and save the result.")
    parser.add_argument("mesh", help="OBJ, OFF, PLY, STL, FBX, glTF (.glb/.gltf) file")
    parser.add_argument("-o", "--output", help="write the rigged scene to this .blend file")
    parser.add_argument("--glb", help="export the rigged mesh and armature as glTF binary")
    parser.add_argument("--fbx", help="export the rigged mesh and armature as FBX")
    parser.add_argument("--off", help="write the imported mesh (joined, world space, "
                                      "triangulated) as OFF; alone, nothing is rigged")
    parser.add_argument("--png", help="render a picture of the rig (mesh in x-ray, bones "
                                      "colored by kind: end red, joint purple, connection "
                                      "blue, root yellow)")
    parser.add_argument("--up", choices=("auto", "y", "z"), default="auto",
                        help="the file's up axis (auto: y for OBJ, z for OFF/PLY/STL; "
                             "FBX and glTF carry their own)")
    parser.add_argument("--resolution", type=int, nargs=2, default=(960, 720),
                        metavar=("W", "H"), help="picture size in pixels")
    parser.add_argument("--weights", choices=[m[0] for m in addon_options.WEIGHT_METHODS],
                        default=addon_options.ADDON_DEFAULTS["weights"])
    parser.add_argument("--bone-detail", type=float,
                        default=addon_options.ADDON_DEFAULTS["bone_detail"])
    parser.add_argument("--bone-names", type=str.upper,
                        choices=[item[0] for item in addon_options.BONE_NAME_ITEMS],
                        default=addon_options.ADDON_DEFAULTS["bone_names"],
                        help="dcg (descriptive) or mixamo (a humanoid's bones after Mixamo's "
                             "rig, for retargeting)")
    parser.add_argument("--root-bone", action=argparse.BooleanOptionalAction,
                        default=addon_options.ADDON_DEFAULTS["root_bone"],
                        help="start the rig with a root bone on the floor that deforms nothing")
    for spec in engine_specs:
        flag = "--" + spec.name.replace("_", "-")
        if spec.kind == "enum":
            parser.add_argument(flag, dest=spec.name, choices=[c[0] for c in spec.choices],
                                help=spec.description)
        else:
            parser.add_argument(flag, dest=spec.name,
                                type=int if spec.kind == "int" else float,
                                help=f"{spec.description} (default {spec.default})")
    return parser


def _fail(message):
    print(f"error: {message}", file=sys.stderr, flush=True)
    sys.exit(1)


def _rig_mesh_object():
    """Return the armature and mesh objects the rig operator made."""
    arm = next((o for o in bpy.data.objects if o.type == "ARMATURE"), None)
    mesh = next((o for o in bpy.data.objects if o.type == "MESH" and o.parent == arm), None)
    return arm, mesh


def _write_off(path, V, F):
    """Write the triangles (V #V by 3, F #F by 3) as an OFF file, coordinates exact."""
    os.makedirs(os.path.dirname(os.path.abspath(path)) or ".", exist_ok=True)
    with open(path, "w", encoding="utf-8") as out:
        out.write(f"OFF\n{len(V)} {len(F)} 0\n")
        out.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())
        out.writelines(f"3 {a} {b} {c}\n" for a, b, c in F.tolist())


def _write_outputs(args, picture, arm_obj, mesh_obj):
    """Save the scene, export glTF and FBX, render the picture: those that `args` asks for."""
    for path in (args.output, args.glb, args.fbx, args.png):
        if path:
            os.makedirs(os.path.dirname(os.path.abspath(path)) or ".", exist_ok=True)
    if args.output:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.output), check_existing=False)
        print(f"dcg: wrote {args.output}")
    if args.glb:
        bpy.ops.export_scene.gltf(filepath=os.path.abspath(args.glb), export_format="GLB",
                                  export_skins=True, export_animations=False)
        print(f"dcg: wrote {args.glb}")
    if args.fbx:
        bpy.ops.export_scene.fbx(filepath=os.path.abspath(args.fbx), add_leaf_bones=False,
                                 bake_anim=False, object_types={"ARMATURE", "MESH"})
        print(f"dcg: wrote {args.fbx}")
    if args.png:
        picture.render_rig_picture(bpy.context, args.png, arm_obj, mesh_obj,
                                   tuple(args.resolution))
        print(f"dcg: wrote {args.png}")


def main():
    # Start from an empty scene (the factory one has a cube, a camera and a light).
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon = _load_addon().__name__
    _engine, importing, mesh_io, options, picture, properties, rigging = (
        importlib.import_module(f"{addon}.{name}") for name in (
            "_engine", "importing", "mesh_io", "options", "picture", "properties", "rigging"))
    RigError = rigging.RigError

    if _engine.error() is not None:
        _fail(_engine.error())
    args = _parser(properties.ENGINE_SPECS, options).parse_args(_script_args())
    started = time.perf_counter()
    mesh_path = os.path.abspath(args.mesh)
    try:
        mesh_obj = importing.import_mesh_file(bpy.context, mesh_path, args.up.upper())
    except (RigError, OSError, ValueError) as error:
        _fail(str(error).strip())
    if args.off:
        _write_off(args.off, *mesh_io.evaluated_world_mesh(bpy.context, mesh_obj))
        print(f"dcg: wrote {args.off}")
        if not (args.output or args.glb or args.fbx or args.png):
            return
    engine_kwargs = {s.name: getattr(args, s.name) for s in properties.ENGINE_SPECS
                     if getattr(args, s.name) is not None}
    try:
        bpy.ops.object.dcg_auto_rig(weights=args.weights, bone_detail=args.bone_detail,
                                    bone_names=args.bone_names, root_bone=args.root_bone,
                                    **engine_kwargs)
    except RuntimeError as error:
        _fail(str(error).strip())
    arm_obj, mesh_obj = _rig_mesh_object()
    if arm_obj is None or mesh_obj is None:
        _fail("the rig operator finished without an armature bound to the mesh")
    print(f"dcg: {mesh_obj.name}: {len(arm_obj.data.bones)} bones "
          f"({', '.join(f'{k} {v:.3f} s' for k, v in arm_obj['dcg_timings'].items())})")
    _write_outputs(args, picture, arm_obj, mesh_obj)
    print(f"dcg: done in {time.perf_counter() - started:.2f} s")


def _end(status):
    """Exit with `status`. Inside PyPI's `bpy` module (no Blender binary) the interpreter's
    teardown is skipped: bpy 4.2.23 dies there with SIGSEGV after any glTF export, when every
    file has long been written and closed."""
    sys.stdout.flush()
    sys.stderr.flush()
    if not bpy.app.binary_path:
        os._exit(status)
    sys.exit(status)


if __name__ == "__main__":
    try:
        main()
        _end(0)
    except SystemExit as done:  # _fail(), argparse
        _end(done.code if isinstance(done.code, int) else 1)
    except Exception as error:  # anything unexpected still ends with status 1
        import traceback

        traceback.print_exc()
        print(f"error: {type(error).__name__}: {error}", file=sys.stderr)
        _end(1)
