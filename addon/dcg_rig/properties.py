"""The add-on's settings: one PropertyGroup behind `Scene.dcg_rig`.

The engine options mirror `dcg.OPTIONS` (defaults, limits, descriptions), so they follow
the engine as it grows. When `dcg` cannot be imported there are no engine options; the
panel then shows the reason and the operators report it.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty

from . import _engine, options

INT_MIN, INT_MAX = -(2 ** 31), 2 ** 31 - 1


def _engine_specs():
    """Return the OptionSpec list of the engine, empty when it cannot be imported."""
    engine = _engine.load()
    return options.option_specs(engine.OPTIONS) if engine is not None else []


ENGINE_SPECS = _engine_specs()


def _property(spec, flags, update=None):
    """Return the bpy property for one engine OptionSpec (`update`: Blender's callback when
    it changes, or None)."""
    common = {"name": options.label(spec.name), "description": spec.description,
              "default": spec.default, "options": flags}
    if update is not None:
        common["update"] = update
    if spec.kind == "enum":
        return EnumProperty(items=spec.choices, **common)
    limits = {}
    if spec.minimum is not None:
        limits["min"] = spec.minimum
    if spec.maximum is not None:
        limits["max"] = spec.maximum
    if spec.kind == "int":
        limits = {k: min(max(int(v), INT_MIN), INT_MAX) for k, v in limits.items()}
        return IntProperty(**limits, **common)
    return FloatProperty(precision=4, step=1, **{k: float(v) for k, v in limits.items()},
                         **common)


def engine_annotations(flags=frozenset(), updates=None):
    """Return name -> bpy property for every engine option (`updates`: name -> callback)."""
    updates = updates or {}
    return {spec.name: _property(spec, set(flags), updates.get(spec.name))
            for spec in ENGINE_SPECS}


def _tau_changed(settings, context):
    """The panel's Tau moved: a shown preview follows it (operators.retune_live_preview)."""
    from . import operators  # imported here: operators imports this module
    operators.retune_live_preview(context)


def addon_annotations(flags=frozenset(), with_weights=True):
    """Return name -> bpy property for the add-on's own settings."""
    result = {"bone_detail": FloatProperty(
        name="Bone Detail", subtype="FACTOR", min=0.0, max=1.0,
        default=options.ADDON_DEFAULTS["bone_detail"], options=set(flags),
        description="How many bones each limb gets, its joints where it bends and "
                    "narrows: 0 gives one bone per limb, 1 one bone per polyline segment; "
                    "below 0.5 long limbs lose bones first")}
    result["bone_names"] = EnumProperty(
        name="Bone Names", items=options.BONE_NAME_ITEMS,
        default=options.ADDON_DEFAULTS["bone_names"], options=set(flags),
        description="How the bones are named: descriptive, or after Mixamo's rig for a "
                    "humanoid (then its chains get Mixamo's bone counts, not Bone Detail's)")
    result["root_bone"] = BoolProperty(
        name="Root Bone", default=options.ADDON_DEFAULTS["root_bone"], options=set(flags),
        description="Start the rig with a root bone on the floor under the body, parent of "
                    "all the others and deforming nothing: what moves the whole character "
                    "(game engines' root motion, Rigify's root)")
    if with_weights:
        result["weights"] = EnumProperty(
            name="Weights", items=options.WEIGHT_METHODS,
            default=options.ADDON_DEFAULTS["weights"], options=set(flags),
            description="How the mesh's vertices are weighted to the bones")
    return result


def setting_names(with_weights=True):
    """Return the names of every setting the rig operator reads."""
    return [s.name for s in ENGINE_SPECS] + list(addon_annotations(
        with_weights=with_weights))


class DCGRigSettings(bpy.types.PropertyGroup):
    """Settings of the DCG panel, the defaults of the DCG operators."""

    __annotations__ = {**engine_annotations(updates={"tau": _tau_changed}),
                       **addon_annotations()}


def settings(context):
    """Return the scene's DCGRigSettings."""
    return context.scene.dcg_rig


def apply_preset(context, preset):
    """Set the scene's settings to `preset` ("DEFAULT", "COARSE", "DETAILED")."""
    values = options.preset_values(ENGINE_SPECS, preset)
    target = settings(context)
    for name, value in values.items():
        setattr(target, name, value)
