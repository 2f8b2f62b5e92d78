"""The add-on registers where users look for it and mirrors the engine's options."""

import os

import bpy
import pytest
from conftest import AS_EXTENSION


@pytest.mark.skipif(AS_EXTENSION, reason="the extension is enabled from the user folder "
                    "(test_extension.py checks where)")
def test_enabled_from_the_build_output():
    import dcg_rig

    scripts = os.path.realpath(os.environ["BLENDER_USER_SCRIPTS"])
    assert os.path.realpath(dcg_rig.__file__).startswith(scripts)


def test_engine_imports_inside_blender(dcg):
    assert callable(dcg.extract_skeleton)
    from dcg_rig import _engine

    assert _engine.error() is None


@pytest.mark.parametrize("name", ["OBJECT_OT_dcg_auto_rig", "OBJECT_OT_dcg_preview",
                                  "OBJECT_OT_dcg_clear", "DCG_OT_preset", "DCG_OT_load_mesh"])
def test_operators_are_registered(name):
    assert hasattr(bpy.types, name)


def test_rig_is_in_the_object_animation_menu():
    from dcg_rig import ui

    draw_functions = bpy.types.VIEW3D_MT_object_animation._dyn_ui_initialize()
    assert ui.menu_entry in draw_functions


def test_panel_is_in_the_dcg_sidebar_tab():
    panel = bpy.types.VIEW3D_PT_dcg_rig
    assert panel.is_registered
    assert (panel.bl_space_type, panel.bl_region_type, panel.bl_category) == (
        "VIEW_3D", "UI", "DCG")


def test_rig_and_preview_are_undoable():
    for operator in (bpy.types.OBJECT_OT_dcg_auto_rig, bpy.types.OBJECT_OT_dcg_preview, bpy.types.OBJECT_OT_dcg_clear):
        assert "UNDO" in operator.bl_options


def test_settings_mirror_the_engine_defaults(dcg, scene):
    settings = scene.dcg_rig
    for name, info in dcg.OPTIONS.items():
        value = getattr(settings, name)
        if isinstance(info.default, str):
            assert value == info.default
        else:
            assert value == pytest.approx(info.default, rel=1e-6), name


def test_presets_change_the_settings_and_default_restores_them(dcg, scene):
    settings = scene.dcg_rig
    bpy.ops.dcg.preset(preset="COARSE")
    assert settings.tau != pytest.approx(dcg.OPTIONS["tau"].default)
    bpy.ops.dcg.preset(preset="DEFAULT")
    assert settings.tau == pytest.approx(dcg.OPTIONS["tau"].default)


def test_unregister_and_register_again():
    import addon_utils

    addon_utils.disable("dcg_rig", default_set=True)
    assert not hasattr(bpy.types, "OBJECT_OT_dcg_auto_rig")
    assert not hasattr(bpy.types.Scene, "dcg_rig")
    addon_utils.enable("dcg_rig", default_set=True, handle_error=None)
    assert hasattr(bpy.types, "OBJECT_OT_dcg_auto_rig")
    assert hasattr(bpy.types.Scene, "dcg_rig")
