"""The engine's options: names, defaults, ranges and descriptions, read from the C++ table.

One table (cpp/src/pipeline.cpp) is behind the keyword arguments of `extract_skeleton`, the CLI
flags and the Blender add-on's properties, so they cannot drift apart.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Dict, Optional, Tuple

from . import _core

REPAIR_CHOICES = ("auto", "none")


@dataclass(frozen=True)
class OptionInfo:
    """One engine option.

    kind is "int", "float" or "choice"; minimum / maximum are None for choices; unit is "" or
    "normalized length" (a fraction of the mesh's bounding-box diagonal).
    """

    name: str
    default: Any
    description: str
    kind: str
    minimum: Optional[float] = None
    maximum: Optional[float] = None
    unit: str = ""
    choices: Tuple[str, ...] = ()


def _build_table() -> Dict[str, OptionInfo]:
    defaults = _core.default_options()
    table = {
        "repair": OptionInfo(
            "repair", defaults["repair"],
            "What to do with input that is not one closed manifold: 'auto' wraps it into a "
            "closed proxy (CGAL alpha wrapping), 'none' raises an error naming the problem",
            "choice", choices=REPAIR_CHOICES),
    }
    for spec in _core.option_specs():
        table[spec["name"]] = OptionInfo(
            spec["name"], defaults[spec["name"]], spec["description"],
            "int" if spec["integer"] else "float", spec["minimum"], spec["maximum"], spec["unit"])
    return table


#: name -> OptionInfo, in pipeline order.
OPTIONS: Dict[str, OptionInfo] = _build_table()


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
                raise ValueError(f"option {name} must be one of {', '.join(REPAIR_CHOICES)}, "
                                 f"got {value!r}")
            value = value.lower()
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"option {name} must be a number, got {value!r}") from None
        clean[name] = value
    return _core.normalize_options(clean)
