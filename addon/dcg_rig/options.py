"""The engine's options as the add-on sees them (no `bpy`: plain pytest can test this).

Every option comes from `dcg.OPTIONS`, so defaults, limits and descriptions stay the
engine's. The add-on's own settings (weights, bone detail) live in `ADDON_DEFAULTS`.
"""

from dataclasses import dataclass

# The add-on's own settings, shared by the panel, the operators and the CLI.
ADDON_DEFAULTS = {"weights": "DCG", "bone_detail": 0.5, "bone_names": "DCG", "root_bone": True}

WEIGHT_METHODS = (
    ("DCG", "DCG", "The engine's own bone heat weights: every vertex weighted, open and "
                   "multi-part meshes and any scale included"),
    ("BLENDER", "Automatic", "Blender's Automatic Weights (bone heat), checked and repaired"),
    ("ENVELOPE", "Envelope", "By distance to the bones, scaled by the skeleton radii "
                             "(never fails)"),
    ("NONE", "None", "Armature modifier and empty vertex groups, for painting by hand"),
)

# How bones are named (dcg.bones.plan_bones' names, lower-cased).
BONE_NAME_ITEMS = (
    ("DCG", "Descriptive", "By what each limb is and its side: spine.001, head.002, "
                           "front_leg.003.L, arm.002.R, tail.004 (X-Axis Mirror, Symmetrize "
                           "and Paste Pose Flipped pair the sides)"),
    ("MIXAMO", "Mixamo", "A humanoid's bones named and counted after Mixamo's rig (Hips, "
                         "Spine, LeftArm, LeftForeArm, LeftUpLeg, ...), so that animations "
                         "made for it retarget; other shapes keep the descriptive names"),
)

# Presets: option values that differ from the defaults (the rest are reset to defaults).
PRESETS = {
    "DEFAULT": {},
    "COARSE": {"target_faces": 8000, "samples": 2000, "tau": 0.75, "min_gap": 0.01,
               "min_radius": 0.004, "bone_detail": 0.0},
    # upsample: a small input is remeshed up to target_faces and sampled in full; without it
    # the engine keeps a small input as it is and caps its samples (README, Options).
    "DETAILED": {"target_faces": 40000, "samples": 8000, "upsample": 1, "tau": 0.92,
                 "min_gap": 0.0025, "min_radius": 0.001, "bone_detail": 1.0},
}
PRESET_ITEMS = (
    ("DEFAULT", "Default", "The engine's defaults"),
    ("COARSE", "Coarse", "Fewer prongs and bones, faster"),
    ("DETAILED", "Detailed", "More prongs and bones, slower"),
)


@dataclass(frozen=True)
class OptionSpec:
    """One engine option: `kind` is "int", "float" or "enum" (then `choices` is set)."""

    name: str
    kind: str
    default: object
    minimum: object
    maximum: object
    description: str
    choices: tuple = ()
    stage: str = ""  # the engine stage that uses it: "weights" for the weights' own


def label(name):
    """Return the UI label of an option name: "min_gap" -> "Min Gap"."""
    return name.replace("_", " ").title()


UNIT_NOTES = {
    "normalized length": "in normalized units: a fraction of the mesh's bounding-box diagonal",
}


def _tooltip(info):
    """Return the option's description with its unit spelled out (Blender shows it as the
    tooltip)."""
    unit = getattr(info, "unit", "")
    return f"{info.description} ({UNIT_NOTES.get(unit, unit)})" if unit else info.description


def option_specs(engine_options):
    """Return a list of OptionSpec from `dcg.OPTIONS` (a dict name -> OptionInfo), in order."""
    specs = []
    for name, info in engine_options.items():
        default = info.default
        stage = getattr(info, "stage", "")
        if isinstance(default, str):
            choices = tuple((c, label(c), c) for c in (info.choices or (default,)))
            specs.append(OptionSpec(name, "enum", default, None, None, info.description,
                                    choices, stage))
        elif isinstance(default, bool):
            raise TypeError(f"engine option {name} is a bool, which the add-on does not know")
        elif isinstance(default, int):
            specs.append(OptionSpec(name, "int", default, info.minimum, info.maximum,
                                    _tooltip(info), stage=stage))
        else:
            specs.append(OptionSpec(name, "float", float(default), info.minimum, info.maximum,
                                    _tooltip(info), stage=stage))
    return specs


def engine_kwargs(specs, values):
    """Return the keyword arguments of `dcg.extract_skeleton` from `values` (name -> value).

    Floats are rounded to 7 significant digits: Blender stores them as 32-bit floats, and
    0.85 should reach the engine as 0.85, not 0.8500000238.
    """
    kwargs = {}
    for spec in specs:
        if spec.name not in values:
            continue
        value = values[spec.name]
        if spec.kind == "int":
            value = int(value)
        elif spec.kind == "float":
            value = float(f"{float(value):.7g}")
        kwargs[spec.name] = value
    return kwargs


def preset_values(specs, preset):
    """Return name -> value for every engine option and add-on setting under `preset`."""
    values = {spec.name: spec.default for spec in specs}
    values.update(ADDON_DEFAULTS)
    values.update({k: v for k, v in PRESETS[preset].items() if k in values})
    return values
