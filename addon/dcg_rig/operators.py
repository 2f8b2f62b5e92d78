"""The add-on's operators: object.dcg_auto_rig, object.dcg_preview, object.dcg_clear,
dcg.mirror_skeleton, dcg.preset and dcg.load_mesh.

Rig and Preview run the engine. Invoked from the UI they run it on a worker thread
(`worker.SkeletonJob`) and stay modal: progress in the status bar and on the cursor, Esc
cancels, Blender keeps drawing. Executed from a script, from the redo panel or in
background mode (`blender -b`) they block. Either way the scene is only changed once the
skeleton exists, and `rigging.apply_rig` undoes its own changes when binding fails, so a
failed or cancelled run leaves the scene as it was and reports why.

Every engine option and add-on setting is also an operator property (`bpy.ops.object.dcg_auto_rig(
tau=0.9)`); a property that is not set takes the value of the DCG panel (`Scene.dcg_rig`).
"""

import time
import traceback

import bpy
from bpy.props import EnumProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from . import (_engine, armature, editing, live, mesh_io, options, preview, properties, rigging,
               worker)


def _kind_counts(kinds):
    """Return "2 end, 1 joint, 5 connection" for a sequence of kinds."""
    names = [str(k) for k in kinds]
    return ", ".join(f"{names.count(k)} {k}" for k in ("end", "joint", "connection"))


def _mirror_summary(bone_names):
    """"; 10 mirrored pairs" for an armature whose bones pair by side (X.L / X.R, or Mixamo's
    LeftX / RightX: what X-Axis Mirror and Symmetrize pair), "; no mirror plane" without."""
    names = set(bone_names)
    pairs = sum(1 for n in names if (n.endswith(".L") and n[:-1] + "R" in names)
                or (n.startswith("Left") and "Right" + n[4:] in names))
    return f"; {pairs} mirrored pairs" if pairs else "; no mirror plane"


class _EngineOperator:
    """Shared by Rig and Preview: settings, the blocking and the modal engine runs.

    Subclasses implement `finish(context, mesh_obj, skeleton, settings) -> set`.
    """

    _running = False  #: one engine job at a time (class attribute, shared by subclasses)

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        if _EngineOperator._running:
            cls.poll_message_set("a DCG computation is already running")
            return False
        if obj is None or obj.type != "MESH":
            cls.poll_message_set("select a mesh object")
            return False
        if context.mode != "OBJECT":
            cls.poll_message_set("switch to Object Mode")
            return False
        return True

    def settings_values(self, context):
        """Return name -> value of every setting: the operator's where set, else the panel's."""
        scene_settings = properties.settings(context)
        own = self.properties.bl_rna.properties
        values = {}
        for name in properties.setting_names():
            is_set = name in own and self.properties.is_property_set(name)
            source = self if is_set else scene_settings
            values[name] = getattr(source, name)
        return values

    def engine_options(self, values):
        """Return the keyword arguments of `dcg.extract_skeleton` from the settings."""
        return options.engine_kwargs(properties.ENGINE_SPECS, values)

    def execute(self, context):
        """Blocking run (scripts, redo panel, background mode)."""
        values = self.settings_values(context)
        mesh_obj = context.active_object
        started = time.perf_counter()
        try:
            engine = _engine.require()
            self.check(mesh_obj)
            V, F = rigging.object_mesh(context, mesh_obj)
            kwargs = self.engine_options(values)
            compute = self.compute(engine, mesh_obj, V, F, kwargs)
            skeleton = compute(V, F, progress=_console_progress(context), **kwargs)
        except Exception as error:  # reported, never raised into Blender
            return self.fail(error)
        finally:
            context.window_manager.progress_end()
        self.elapsed = time.perf_counter() - started
        return self.finish_checked(context, mesh_obj, skeleton, values)

    def invoke(self, context, event):
        """Modal run on a worker thread when there is a window to report progress in."""
        if bpy.app.background or context.window is None:
            return self.execute(context)
        values = self.settings_values(context)
        mesh_obj = context.active_object
        try:
            engine = _engine.require()
            self.check(mesh_obj)
            V, F = rigging.object_mesh(context, mesh_obj)
            kwargs = self.engine_options(values)
            engine.normalize_options(kwargs)  # bad values fail here, not in the thread
        except Exception as error:
            return self.fail(error)
        self._values = values
        self._mesh_name = mesh_obj.name
        self._started = time.perf_counter()
        compute = self.compute(engine, mesh_obj, V, F, kwargs)
        self._job = worker.SkeletonJob(engine, V, F, kwargs, compute).start()
        _EngineOperator._running = True
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        self._status(context)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC" and event.value == "PRESS":
            self._job.cancel()
            return {"RUNNING_MODAL"}
        if event.type != "TIMER" or event.timer is not self._timer:
            return {"PASS_THROUGH"}
        if not self._job.done():
            context.window_manager.progress_update(int(100 * self._job.fraction))
            self._status(context)
            return {"RUNNING_MODAL"}
        self._end_modal(context)
        job = self._job
        if job.cancelled:
            self.report({"WARNING"}, "DCG: cancelled, nothing changed")
            return {"CANCELLED"}
        if job.error is not None:
            return self.fail(job.error)
        mesh_obj = bpy.data.objects.get(self._mesh_name)
        if mesh_obj is None or mesh_obj.type != "MESH":
            return self.fail(rigging.RigError(f"{self._mesh_name} was deleted or renamed "
                                              "while its skeleton was computed"))
        self.elapsed = time.perf_counter() - self._started
        return self.finish_checked(context, mesh_obj, job.skeleton, self._values)

    def cancel(self, context):
        """Called by Blender when the modal run is aborted (window closed, file loaded)."""
        self._job.cancel()
        self._end_modal(context)

    def _status(self, context):
        text = (f"DCG: {self._job.stage} {int(100 * self._job.fraction)}%  "
                "(Esc to cancel)")
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def _end_modal(self, context):
        _EngineOperator._running = False
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

    def check(self, mesh_obj):
        """Raise RigError when the operator cannot work on `mesh_obj` (before any engine
        work)."""

    def compute(self, engine, mesh_obj, V, F, kwargs):
        """Return the engine call, `f(V, F, progress=..., **options)`, whose result
        `finish` receives (each operator says which), for the triangles (V, F) of `mesh_obj`
        and the engine options `kwargs`."""
        raise NotImplementedError

    def finish_checked(self, context, mesh_obj, skeleton, values):
        """Run `finish`, turning any exception into an error report."""
        try:
            return self.finish(context, mesh_obj, skeleton, values)
        except Exception as error:
            return self.fail(error)

    def fail(self, error):
        """Report `error` to the user (and the console) and cancel."""
        if not isinstance(error, (rigging.RigError, _engine.EngineUnavailable, ValueError,
                                  OSError)):
            traceback.print_exception(type(error), error, error.__traceback__)
            message = f"{type(error).__name__}: {error}"
        else:
            message = str(error)
        self.report({"ERROR"}, f"DCG: {message}")
        return {"CANCELLED"}


def _console_progress(context):
    """Return a progress callback for blocking runs: the cursor's progress indicator in the
    UI, one line per stage on the console in background mode."""
    wm = context.window_manager
    wm.progress_begin(0, 100)
    last = [None]

    def progress(stage, fraction):
        wm.progress_update(int(100 * fraction))
        if bpy.app.background and stage != last[0]:
            print(f"dcg: {stage}", flush=True)
            last[0] = stage
        return True

    return progress


def _run_extractor(engine):
    """Return an engine call that runs every stage in a `dcg.Extractor` and returns it, so
    that the stages' results (stage 0 for the weights, balls and prongs for the preview)
    stay available."""
    def run(V, F, progress=None, **options):
        extractor = engine.Extractor(V, F, progress, **options)
        extractor.skeleton()
        return extractor
    return run


def _report_repair(operator, extractor):
    """Tell the user what stage 0 did to a mesh that is not one closed manifold: a warning when
    the skeleton is of a proxy (the alpha wrap, of the whole or of a part that crossed itself)
    or faces were left out (fins), else for information (the union of closed parts keeps the
    mesh's own surface)."""
    prepared = extractor.prepare()
    summary = _engine.require().repair_summary(prepared)
    if summary is None:
        return
    report = prepared.report
    proxy = prepared.wrap_alpha > 0 or report.get("fin_faces", 0) > 0 or \
        report.get("wrapped_parts", 0) > 0
    operator.report({"WARNING" if proxy else "INFO"}, f"DCG: {summary}")


def _skeleton_of(extractor):
    """Return `extractor` once its skeleton exists (computed here if it was retuned)."""
    extractor.skeleton()
    return extractor


def show_preview(context, mesh_obj, extractor, values):
    """Draw the preview of `extractor`'s skeleton of `mesh_obj` (its stages, nodes and links)
    with the editable armature of its bones (`editing`), planned with the settings `values`;
    return the planner's warnings."""
    skeleton = extractor.skeleton()
    collection = preview.build_preview(context, skeleton, preview.stage_geometry(extractor))
    plan, warnings = rigging.plan_bones(skeleton, values["bone_detail"], values["bone_names"],
                                        values["root_bone"], mesh_obj.matrix_world.translation)
    if plan:
        engine = _engine.require()
        mixamo = engine.humanoid.is_mixamo(plan)  # planned from the pelvis: its own plane
        plane = (engine.humanoid if mixamo else engine.bones).plan_plane(skeleton)
        editing.add_editable_skeleton(context, mesh_obj, plan, plane, collection)
    return warnings


def retune_live_preview(context):
    """The panel's Tau moved: redraw the shown preview at the new tau from its kept extractor
    (`live`), when the preview is of the active mesh as it is now, with the panel's other
    options, and its skeleton was not edited; otherwise leave it as it is (Preview Skeleton
    makes a new one)."""
    obj = context.active_object
    if _EngineOperator._running or obj is None or live.kept_for(obj.name) is None:
        return
    if bpy.data.collections.get(preview.COLLECTION_NAME) is None:  # removed by hand
        live.forget()
        return
    edited = editing.preview_skeleton(obj.name)
    if edited is not None and editing.is_edited(edited):
        print(f"DCG: the preview of {obj.name} was not redrawn: its skeleton was edited "
              "(Preview Skeleton starts again from the new tau)")
        return
    scene_settings = properties.settings(context)
    values = {name: getattr(scene_settings, name) for name in properties.setting_names()}
    try:
        V, F = rigging.object_mesh(context, obj)
        kwargs = options.engine_kwargs(properties.ENGINE_SPECS, values)
        extractor = live.matching(obj.name, V, F, kwargs)
        if extractor is None:
            return
        show_preview(context, obj, extractor, values)
    except Exception as error:  # a property update cannot report: the console says why
        print(f"DCG: the preview was not updated: {type(error).__name__}: {error}")


class OBJECT_OT_dcg_auto_rig(_EngineOperator, bpy.types.Operator):
    """Rig the active mesh: DCG skeleton, armature with end, joint and connection bones,
    and weights"""

    bl_idname = "object.dcg_auto_rig"
    bl_label = "Rig with DCG"
    bl_options = {"REGISTER", "UNDO"}
    __annotations__ = {**properties.engine_annotations({"SKIP_SAVE"}),
                       **properties.addon_annotations({"SKIP_SAVE"})}

    def check(self, mesh_obj):
        rigging.check_riggable(mesh_obj)

    def compute(self, engine, mesh_obj, V, F, kwargs):
        # The previewed skeleton when the preview was made of these triangles with these
        # options (a moved Tau slider included): what the user looked at is what gets bound.
        previewed = live.matching(mesh_obj.name, V, F, kwargs)
        self._previewed = previewed is not None
        if previewed is None:
            return _run_extractor(engine)
        return lambda V, F, progress=None, **options: _skeleton_of(previewed)

    def finish(self, context, mesh_obj, extractor, values):
        skeleton = extractor.skeleton()
        # The preview's skeleton as the user edited it, bound as it is (editing.py).
        edited = editing.edited_plan(_engine.require(), mesh_obj)
        result = rigging.apply_rig(context, mesh_obj, skeleton, values["weights"],
                                   values["bone_detail"], extractor.prepare(),
                                   self.engine_options(values), values["bone_names"], edited,
                                   values["root_bone"])
        live.forget()  # the rig replaced the preview
        arm_obj = result.armature
        arm_obj["dcg_timings"] = {k: float(v) for k, v in skeleton.timings.items()}
        arm_obj["dcg_method"] = skeleton.method
        _report_repair(self, extractor)
        for warning in result.warnings:
            self.report({"WARNING"}, f"DCG: {warning}")
        source = ("the edited preview skeleton, " if edited is not None else
                  "the previewed skeleton, " if self._previewed else "")
        self.report({"INFO"}, f"DCG: rigged {mesh_obj.name} with {result.bone_count} bones "
                              f"({source}{_kind_counts(skeleton.kinds)} nodes"
                              f"{_mirror_summary(b.name for b in arm_obj.data.bones)}) in "
                              f"{self.elapsed:.2f} s")
        return {"FINISHED"}


class OBJECT_OT_dcg_preview(_EngineOperator, bpy.types.Operator):
    """Show the stages of the active mesh's DCG skeleton without rigging it: domain balls,
    prongs, and the skeleton's nodes (colored by kind) and links"""

    bl_idname = "object.dcg_preview"
    bl_label = "Preview Skeleton"
    bl_options = {"REGISTER", "UNDO"}
    __annotations__ = {**properties.engine_annotations({"SKIP_SAVE"}),
                       **properties.addon_annotations({"SKIP_SAVE"}, with_weights=False)}

    def compute(self, engine, mesh_obj, V, F, kwargs):
        self._kept_as = (mesh_obj.name, live.fingerprint(V, F), kwargs)
        return _run_extractor(engine)

    def finish(self, context, mesh_obj, extractor, values):
        skeleton = extractor.skeleton()
        warnings = show_preview(context, mesh_obj, extractor, values)
        name, mesh_fingerprint, kwargs = self._kept_as
        live.remember(name, mesh_fingerprint, kwargs, extractor)  # for the Tau slider and Rig
        _report_repair(self, extractor)
        for warning in warnings:
            self.report({"WARNING"}, f"DCG: {warning}")
        self.report({"INFO"}, f"DCG: {len(skeleton.positions)} nodes "
                              f"({_kind_counts(skeleton.kinds)}), {len(skeleton.links)} links "
                              f"in {self.elapsed:.2f} s")
        return {"FINISHED"}


class OBJECT_OT_dcg_clear(bpy.types.Operator):
    """Remove the DCG rigs of the active mesh (armature, weights, modifier) and the preview"""

    bl_idname = "object.dcg_clear"
    bl_label = "Clear DCG Rig"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        obj = context.active_object
        removed = armature.clear_rigs(obj) if obj is not None and obj.type == "MESH" else 0
        live.forget()
        had_preview = bpy.data.collections.get(preview.COLLECTION_NAME) is not None
        preview.clear_preview()
        self.report({"INFO"}, f"DCG: removed {removed} rig(s)"
                              + (" and the preview" if had_preview else ""))
        return {"FINISHED"}


class DCG_OT_mirror_skeleton(bpy.types.Operator):
    """Mirror the preview skeleton's bones of one side onto their partners of the other,
    across the mesh's mirror plane (the selected bones in Edit Mode, else all)"""

    bl_idname = "dcg.mirror_skeleton"
    bl_label = "Mirror Skeleton Edit"
    bl_options = {"REGISTER", "UNDO"}
    source: EnumProperty(name="From", items=(
        ("L", "Left to Right", "Copy the .L / Left bones onto their .R / Right partners"),
        ("R", "Right to Left", "Copy the .R / Right bones onto their .L / Left partners")),
        default="L")

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        if obj is None or obj.type != "ARMATURE" or editing.PREVIEW_OF not in obj:
            cls.poll_message_set("make the DCG preview skeleton the active object")
            return False
        if editing.MIRROR_PLANE not in obj:
            cls.poll_message_set("the previewed shape has no mirror plane")
            return False
        return True

    def execute(self, context):
        try:
            done, missing = editing.mirror_edit(context.active_object, self.source)
        except ValueError as error:
            self.report({"ERROR"}, f"DCG: {error}")
            return {"CANCELLED"}
        note = f" ({missing} without a partner on the other side)" if missing else ""
        self.report({"INFO"}, f"DCG: mirrored {done} bones{note}")
        return {"FINISHED"}


class DCG_OT_preset(bpy.types.Operator):
    """Set the DCG panel's settings to a preset"""

    bl_idname = "dcg.preset"
    bl_label = "DCG Preset"
    bl_options = {"REGISTER", "UNDO"}
    preset: EnumProperty(name="Preset", items=options.PRESET_ITEMS, default="DEFAULT")

    def execute(self, context):
        properties.apply_preset(context, self.preset)
        return {"FINISHED"}


UP_AXES = (("AUTO", "Auto", "Y for OBJ files (their usual convention), Z otherwise"),
           ("Y", "Y Up", "The file's Y axis points up: rotate it to Blender's Z up"),
           ("Z", "Z Up", "The file is Z up already, like Blender"))


class DCG_OT_load_mesh(bpy.types.Operator, ImportHelper):
    """Load an OBJ, OFF, PLY or STL file with the engine's reader (the same triangles the
    CLI and the Python API see) as a new mesh object"""

    bl_idname = "dcg.load_mesh"
    bl_label = "Load Mesh File"
    bl_options = {"REGISTER", "UNDO"}
    filter_glob: StringProperty(default="*.obj;*.off;*.ply;*.stl", options={"HIDDEN"})
    up_axis: EnumProperty(name="Up Axis", items=UP_AXES, default="AUTO")

    def execute(self, context):
        try:
            engine = _engine.require()
            V, F = engine.load_mesh(self.filepath)
        except Exception as error:
            self.report({"ERROR"}, f"DCG: {error}")
            return {"CANCELLED"}
        name = bpy.path.display_name_from_filepath(self.filepath) or "mesh"
        obj = bpy.data.objects.new(name, mesh_io.mesh_from_arrays(name, V, F))
        up = self.up_axis
        if up == "AUTO":
            up = "Y" if self.filepath.lower().endswith(".obj") else "Z"
        if up == "Y":
            obj.rotation_euler = (1.5707963267948966, 0.0, 0.0)
        context.collection.objects.link(obj)
        for other in context.view_layer.objects:
            other.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        self.report({"INFO"}, f"DCG: loaded {name}: {len(V)} vertices, {len(F)} triangles")
        return {"FINISHED"}


CLASSES = (OBJECT_OT_dcg_auto_rig, OBJECT_OT_dcg_preview, OBJECT_OT_dcg_clear,
           DCG_OT_mirror_skeleton, DCG_OT_preset, DCG_OT_load_mesh)
