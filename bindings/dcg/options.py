"""The engine's options: names, defaults, ranges and descriptions, read from the C++ table.

One table (cpp/src/options.cpp) is behind the keyword arguments of `extract_skeleton`, the CLI
flags and the Blender add-on's properties, so they cannot drift apart.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Dict, Optional, Tuple

from . import _core



@dataclass(frozen=True)
class OptionInfo:
    """One engine option.

    kind is "int", "float" or "choice"; minimum / maximum are None for choices; unit is "" or
    "normalized length" (a fraction of the mesh's bounding-box diagonal); stage is the stage
    that uses it ("prepare", "voronoi_balls", ..., "weights"; "all" for seed).
    """

    name: str
    default: Any
    description: str
    kind: str
    minimum: Optional[float] = None
    maximum: Optional[float] = None
    unit: str = ""
    choices: Tuple[str, ...] = ()
    stage: str = ""


def _build_table() -> Dict[str, OptionInfo]:
    defaults = _core.default_options()
    table = {}
    for spec in _core.option_specs():
        name, kind = spec["name"], spec["kind"]
        numeric = kind != "choice"
        table[name] = OptionInfo(
            name, defaults[name], spec["description"], kind,
            spec["minimum"] if numeric else None, spec["maximum"] if numeric else None,
            spec["unit"], tuple(spec["choices"]), spec["stage"])
    return table


#: name -> OptionInfo, in pipeline order (the skeleton's stages 0-8, then the weights').
OPTIONS: Dict[str, OptionInfo] = _build_table()
#: The options that make a skeleton (stages 0-8: all but the weights' own).
SKELETON_OPTIONS = tuple(n for n, info in OPTIONS.items() if info.stage != "weights")


def normalize_options(options: Dict[str, Any]) -> Dict[str, Any]:
    """Checks `options` and returns every option with defaults filled in.

    Raises ValueError for an unknown name or a value out of range.
    """
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ValueError(f"unknown option(s) {', '.join(unknown)}; known: {', '.join(OPTIONS)}")
    clean = {}
    for name, value in options.items():
        if OPTIONS[name].kind == "choice":
            # Only strings: str(None) would silently read as the choice "none".
            if not isinstance(value, str):
                raise ValueError(f"option {name} must be one of "
                                 f"{', '.join(OPTIONS[name].choices)}, got {value!r}")
            value = value.lower()
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"option {name} must be a number, got {value!r}") from None
        clean[name] = value
    return _core.normalize_options(clean)
