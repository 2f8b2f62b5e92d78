"""The engine's wheels (make wheel: out/wheels/) and the extension zip (make extension): what
auditwheel says of each wheel, what the compiled module loads at run time, and a clean venv of
another Python (with numpy 2 where it has it) importing and running the installed wheel."""

import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
WHEELS = sorted((REPO / "out" / "wheels").glob("dcg-*.whl"))
# make wheel's build tools (.venv/wheel-3.11 on Debian 12, wheel-3.13 on Debian 13).
AUDITWHEEL = next(iter(sorted((REPO / ".venv").glob("wheel-*/bin/auditwheel"))),
                  REPO / ".venv" / "wheel-3.11" / "bin" / "auditwheel")
# What the wheel must carry rather than take from the system.
BUNDLED = ("libembree", "libtbb", "libgmp", "libmpfr")

pytestmark = pytest.mark.skipif(not WHEELS, reason="no wheel in out/wheels (make wheel)")

sys.path.insert(0, str(REPO / "scripts"))
import make_extension  # noqa: E402


def wheel_for_this_python():
    tag = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    return next((w for w in WHEELS if f"-{tag}-" in w.name), None)


def _python_tag(wheel):
    """cp311 of dcg-0.1.0-cp311-...whl (with no wheel, pytest passes a placeholder)."""
    parts = getattr(wheel, "name", str(wheel)).split("-")
    return parts[2] if len(parts) > 2 else str(wheel)


@pytest.mark.parametrize("wheel", WHEELS, ids=_python_tag)
def test_auditwheel_finds_a_manylinux_tag_and_nothing_outside_the_policy(wheel):
    assert re.search(r"-manylinux_2_\d+_x86_64\.whl$", wheel.name), wheel.name
    if not AUDITWHEEL.is_file():
        pytest.skip(f"{AUDITWHEEL} missing (make wheel makes it)")
    shown = subprocess.run([str(AUDITWHEEL), "show", str(wheel)], capture_output=True,
                           text=True, timeout=120)
    text = " ".join((shown.stdout + shown.stderr).split())
    assert shown.returncode == 0, text
    assert re.search(r'is consistent with the following platform tag: "manylinux_2_\d+_x86_64"',
                     text), text
    # A repaired wheel depends only on libraries in the policy's whitelist (auditwheel says
    # "The wheel references external versioned symbols in these system-provided shared
    # libraries" for those); anything else would be listed as needing to be bundled.
    assert "need to be" not in text and "not in the policy" not in text, text
    names = zipfile.ZipFile(wheel).namelist()
    for lib in BUNDLED:
        assert any(n.startswith("dcg.libs/" + lib) for n in names), (lib, names)


def test_the_module_loads_its_libraries_from_the_wheel_not_the_system(tmp_path):
    wheel = WHEELS[0]
    zipfile.ZipFile(wheel).extractall(tmp_path)
    (module,) = (tmp_path / "dcg").glob("_core*.so")
    ldd = subprocess.run(["ldd", str(module)], capture_output=True, text=True, check=True).stdout
    resolved = {}  # library name -> the file the loader picks
    for line in ldd.splitlines():
        if "=>" in line and "/" in line.split("=>")[1]:
            name, target = line.split("=>")
            resolved[name.strip()] = os.path.realpath(target.split("(")[0].strip())
    assert "not found" not in ldd, ldd
    for lib in BUNDLED:
        picked = [t for n, t in resolved.items() if n.startswith(lib)]
        assert picked and all(t.startswith(str(tmp_path / "dcg.libs")) for t in picked), ldd


def interpreter_for(wheel):
    """(A Python of the wheel's version, whether it has numpy) (scripts/find-python.sh:
    pyenv's first, numpy 2 there, else Debian's, else the one scripts/build-python.sh built),
    or (None, False)."""
    tag = wheel.name.split("-")[2][2:]
    found = subprocess.run(["bash", str(REPO / "scripts" / "find-python.sh"),
                            f"{tag[0]}.{tag[1:]}"], capture_output=True, text=True)
    path = found.stdout.strip()
    if found.returncode != 0:
        return None, False
    has_numpy = subprocess.run([path, "-c", "import numpy"], capture_output=True).returncode == 0
    return path, has_numpy


def install_numpy(py, version):
    """numpy into the venv of `py` from the wheel cache (~/.cache/dcg-rig/wheels/numpy-cpXY,
    filled from PyPI the first time, as bpy-venv.sh does for bpy): a Python that
    scripts/build-python.sh built has none of its own. False when it cannot be had."""
    cache = Path(os.environ.get("DCG_WHEEL_CACHE", Path.home() / ".cache" / "dcg-rig" /
                                "wheels")) / f"numpy-{version}"
    pip = [py, "-m", "pip", "-q", "--disable-pip-version-check"]
    if not list(cache.glob("numpy-*.whl")):
        part = cache.with_name(cache.name + ".part")
        if subprocess.run(pip + ["download", "-d", str(part), "--only-binary=:all:", "numpy"],
                          capture_output=True, timeout=300).returncode != 0:
            return False
        part.rename(cache)
    return subprocess.run(pip + ["install", "--no-index", "--find-links", str(cache), "numpy"],
                          capture_output=True, timeout=300).returncode == 0


@pytest.mark.parametrize("wheel", WHEELS, ids=_python_tag)
def test_a_clean_venv_imports_and_runs_the_installed_wheel(wheel, tmp_path):
    """In a venv of its own (numpy from the interpreter's site-packages, or from the wheel cache
    where the interpreter has none; nothing else), the installed wheel loads and rigs spot, away
    from the source tree and the build folder."""
    python, has_numpy = interpreter_for(wheel)
    if python is None:
        pytest.skip(f"no Python for {wheel.name}")
    target = tmp_path / "venv"
    subprocess.run([python, "-m", "venv", "--system-site-packages", str(target)],
                   check=True, timeout=120)
    py = str(target / "bin" / "python")
    if not has_numpy and not install_numpy(py, _python_tag(wheel)):
        pytest.skip(f"no numpy for {wheel.name} (none here, PyPI out of reach)")
    subprocess.run([py, "-m", "pip", "install", "-q", "--no-deps", "--no-index", str(wheel)],
                   check=True, timeout=300)
    script = ("import dcg, numpy; V, F = dcg.load_mesh(%r); s = dcg.extract_skeleton(V, F); "
              "print(dcg.__file__, numpy.__version__, len(s.links))"
              % str(REPO / "data" / "spot.obj"))
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "DCG_PYTHONPATH")}
    run = subprocess.run([py, "-c", script], capture_output=True, text=True, timeout=300,
                         env=env, cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    location, numpy_version, links = run.stdout.split()[-3:]
    assert str(target) in location and int(links) > 0


def test_the_extension_manifest_follows_the_wheels(tmp_path):
    text = make_extension.manifest_text(
        (REPO / "addon" / "dcg_rig" / "blender_manifest.toml").read_text(),
        [str(w) for w in WHEELS])
    assert 'platforms = ["linux-x64"]' in text
    for wheel in WHEELS:
        assert f'"./wheels/{wheel.name}"' in text
    assert make_extension.wheel_platforms("dcg-0.1.0-cp311-cp311-win_amd64.whl") == {"windows-x64"}
    assert make_extension.wheel_platforms(
        "dcg-0.1.0-cp311-cp311-macosx_11_0_universal2.whl") == {"macos-x64", "macos-arm64"}
