"""Bone names in Blender (dcg.naming): public meshes loaded the way a user loads them come out
with their limbs' names (legs, arms, head, tail), read the way the model stands in the viewport,
and Blender's own mirror naming pairs the sides."""

import os
import re
from pathlib import Path

import bpy
import numpy as np
import pytest

MESHES = Path(os.environ.get("DCG_MESHES", ""))
#: The limbs each public mesh's rig names (the spine aside).
LIMBS = {
    "spot.obj": {"front_leg.L", "front_leg.R", "hind_leg.L", "hind_leg.R", "head", "tail"},
    "cow.off": {"front_leg.L", "front_leg.R", "hind_leg.L", "hind_leg.R", "head", "tail"},
    "knight.off": {"arm.L", "arm.R", "leg.L", "leg.R", "head"},
}
#: Each file's up axis (the loader's Up Axis): these OFF files are Y up, as the OBJ convention.
UP = {"spot.obj": "AUTO", "cow.off": "Y", "knight.off": "Y"}


def rigged(name, **options):
    """(mesh, armature) of the public mesh `name` loaded (UP's axis, else the loader's Auto)
    and rigged without weights, with the operator's `options`."""
    path = MESHES / name
    if not path.is_file():
        pytest.skip(f"{path} not found (set DCG_MESHES)")
    bpy.ops.dcg.load_mesh(filepath=str(path), up_axis=UP.get(name, "AUTO"))
    mesh = bpy.context.active_object
    assert bpy.ops.object.dcg_auto_rig(weights="NONE", **options) == {"FINISHED"}
    (arm,) = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    return mesh, arm


@pytest.mark.parametrize("name", sorted(LIMBS))
def test_limbs_are_named_after_what_they_are(name, dcg):
    mesh, arm = rigged(name)
    chains = {re.sub(r"\.\d{3}", "", bone.name) for bone in arm.data.bones}
    assert chains - {"spine", "root"} == LIMBS[name]
    for bone in arm.data.bones:  # Blender's mirror naming pairs the sides
        flipped = bpy.utils.flip_name(bone.name)
        assert (flipped != bone.name) == bone.name.endswith((".L", ".R"))
        assert flipped in arm.data.bones


@pytest.mark.parametrize("name", sorted(LIMBS))
def test_legs_stand_on_the_ground_and_the_head_is_highest(name, dcg):
    # Loaded standing (Blender's Z up), the legs are the limbs that reach the floor.
    mesh, arm = rigged(name)
    heights = np.array([(mesh.matrix_world @ v.co).z for v in mesh.data.vertices])
    ground = heights.min() + 0.2 * np.ptp(heights)

    def tip_height(chain):
        tips = [b for b in arm.data.bones if re.sub(r"\.\d{3}", "", b.name) == chain
                and not b.children]
        return max((arm.matrix_world @ b.tail_local).z for b in tips)

    legs = [c for c in LIMBS[name] if "leg" in c]
    assert legs and all(tip_height(chain) <= ground for chain in legs)
    assert tip_height("head") == max(tip_height(chain) for chain in LIMBS[name])


def test_a_characters_fingers_get_bones_in_blender(dcg):
    # Mannequiny's hands have fingers (the engine finds a thumb and two fingers on each). Blender
    # hands the engine float32 coordinates, where its 59 parts' union needs exact constructions
    # (a wrap instead smoothed the fingers away: 5 ends, no finger bones).
    _, arm = rigged("rigged/Mannequiny.obj")
    chains = {re.sub(r"\.\d{3}", "", bone.name) for bone in arm.data.bones}
    fingers = {chain for chain in chains if chain.startswith("finger")}
    assert fingers == {f"finger{i}.{side}" for i in range(1, 5) for side in "LR"}
    assert sum(bone.get("dcg_kind") == "end" for bone in arm.data.bones) == 11


def test_a_humanoids_fingers_get_mixamos_names(dcg):
    # Loaded upright in Blender, Mannequiny's skeleton closes a loop at a knee (its surface has
    # three handles): the loop gets no bone, and with Bone Names = Mixamo its fingers hang from
    # LeftHand / RightHand as Mixamo's do.
    _, arm = rigged("rigged/Mannequiny.obj", bone_names="MIXAMO")
    bones = arm.data.bones
    for side in ("Left", "Right"):
        for finger in ("Thumb", "Index", "Middle"):
            assert bones[f"{side}Hand{finger}1"].parent.name == f"{side}Hand"
    assert bones["LeftUpLeg"].parent.name == "Hips"
    assert bones["LeftHand"].tail_local.x > 0.5 and bones["RightHand"].tail_local.x < -0.5
