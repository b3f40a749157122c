"""Where the FMUs are (the order is in scfmu.fmu's docstring) and a component's model name or path → its
FMU file, with the closest name when a name is unknown."""

from __future__ import annotations

import functools
import os
from importlib import resources
from pathlib import Path

_FMU_DIR_OVERRIDE: Path | None = None


def set_fmu_dir(path: str | Path | None) -> None:
    """Uses ``path`` as the FMU folder (unless ``SCFMU_FMU_DIR`` is set); None restores the default."""
    global _FMU_DIR_OVERRIDE
    _FMU_DIR_OVERRIDE = None if path is None else Path(path).resolve()


@functools.cache  # where the installed package lies does not change while it runs
def _package_fmus() -> Path | None:
    d = resources.files("scfmu") / "fmus"
    if d.is_dir() and any(p.name.endswith(".fmu") for p in d.iterdir()):
        return Path(str(d))
    return None


@functools.cache
def _checkout_fmus() -> Path | None:
    """``fmus/`` of the source checkout that holds this package (editable install), if it is one."""
    pkg = Path(str(resources.files("scfmu")))
    root = pkg.parent
    if (root / "Cargo.toml").is_file() and (root / "fmus").is_dir():
        return root / "fmus"
    return None


def fmu_dir() -> Path:
    """The folder holding ``<Model>.fmu`` (see the module docstring for the order)."""
    env = os.environ.get("SCFMU_FMU_DIR")
    if env:
        return Path(env)
    if _FMU_DIR_OVERRIDE is not None:
        return _FMU_DIR_OVERRIDE
    for d in (_package_fmus(), _checkout_fmus()):
        if d is not None:
            return d
    raise FileNotFoundError("no FMU folder: set SCFMU_FMU_DIR or pass --fmus DIR (this installation ships no "
                            "FMUs and is not a source checkout with fmus/)")


def is_path(model: str) -> bool:
    """True when a component's model is given as a path to an FMU file rather than a model name."""
    return str(model).endswith(".fmu") or "/" in str(model) or os.sep in str(model)


class UnknownModel(FileNotFoundError):
    """A model name that names no FMU of the FMU folder (the message suggests the closest names)."""


def models() -> list[str]:
    """The model names of the FMU folder (``<name>.fmu``), sorted."""
    try:
        return sorted(p.stem for p in fmu_dir().glob("*.fmu"))
    except OSError:
        return []


def fmu_path(model: str) -> Path:
    """The FMU file of ``model``: a path to an ``.fmu`` file as given, else ``<fmu_dir()>/<model>.fmu``."""
    if is_path(model):
        p = Path(model).expanduser()
        if p.is_dir():
            raise FileNotFoundError(f"FMU {p} is a directory, not an FMU file (give the .fmu archive)")
        if not p.is_file():
            raise FileNotFoundError(f"FMU {p} not found")
        return p.resolve()
    p = fmu_dir() / f"{model}.fmu"
    if not p.is_file():
        import difflib
        close = difflib.get_close_matches(str(model), models(), n=1)
        if close:
            raise UnknownModel(f"unknown model {model!r}; did you mean {close[0]!r}? (the models are the .fmu files "
                               f"of {fmu_dir()})")
        raise UnknownModel(f"{p} not found: build the FMUs (scripts/build_fmus.sh in a checkout), set "
                           f"SCFMU_FMU_DIR or pass --fmus DIR")
    return p
