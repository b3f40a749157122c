"""Data of paper 000 shipped with the package (read with importlib.resources, never by path counting)."""

from importlib import resources
from pathlib import Path


def data_file(name: str) -> Path:
    """The path of a data file of this folder (a real file: the package is installed unzipped)."""
    return Path(str(resources.files(__name__) / name))
